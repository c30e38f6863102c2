-- autotune.lua -- search a technique's parameters for the lowest error
-- against the reference under a time budget (the way XeGTAO tunes its AO
-- against a ray-traced reference): a Latin-hypercube start over the
-- registry's ranges (log-spaced where a range spans decades), then a
-- coordinate search that halves its steps when no move helps. A feasible
-- point (time <= budget) beats an infeasible one; among feasible ones the
-- lower error wins, among infeasible ones the faster. Times are measured, so
-- a point close to the budget may fall either side of it on another run.
local sl = package.loaded.shadowlab or require "shadowlab"
local json = require "shadowlab.json"
local sweep = require "shadowlab.sweep"

local autotune = {}

local compare_fields = { "light", "repeats", "warmup", "samples", "pattern", "seed", "cache" }

local function find_param(desc, name)
  for _, p in ipairs(desc.params) do
    if p.name == name then return p end
  end
  error(string.format("autotune: %s has no parameter %s", desc.name, name), 3)
end

-- The tuned parameters: the named ones (enums and bools step through their
-- values), or every int and float parameter.
local function tuned(desc, names)
  local list = {}
  if names then
    for _, n in ipairs(names) do list[#list + 1] = find_param(desc, n) end
  else
    for _, p in ipairs(desc.params) do
      if p.type == "int" or p.type == "float" then list[#list + 1] = p end
    end
  end
  if #list == 0 then error("autotune: " .. desc.name .. " has no numeric parameter to tune", 3) end
  return list
end

local function is_log(p) return p.min > 0 and p.max / p.min >= 100 end

-- One coordinate move of parameter p from value v by `step`: a factor 2^step
-- on log ranges, step/8 of the width otherwise, at least 1 for ints; the
-- next or previous choice of an enum; the other value of a bool.
local function moved(p, v, step, direction)
  if p.type == "bool" then return not v end
  if p.type == "enum" then
    local i = 1
    for k, c in ipairs(p.choices) do
      if c == v then i = k end
    end
    return p.choices[(i - 1 + direction) % #p.choices + 1]
  end
  local x = is_log(p) and v * 2 ^ (direction * step) or v + direction * step * (p.max - p.min) / 8
  x = math.max(p.min, math.min(p.max, x))
  if p.type == "int" then
    local r = math.floor(x + 0.5)
    if r == v then r = v + direction end
    x = math.tointeger(math.max(p.min, math.min(p.max, r)))
  end
  return x
end

local function better(a, b)
  if not b then return true end
  if a.feasible ~= b.feasible then return a.feasible end
  if a.feasible then return a.error < b.error end
  return a.time < b.time
end

-- autotune.run{lab = LAB, technique = NAME, budget_s = S, params = {names} (default: every
-- int/float), fixed = {name = value}, evaluations = 24, initial = 8, seed = 1,
-- time = "frame" | "evaluate_median", error = "all.rmse", and lab:compare's light,
-- repeats, warmup, samples, pattern, cache, reference_seed (its `seed`)}. Returns
-- {best, history, feasible}: every evaluated point has params, error, time,
-- feasible and its record.
function autotune.run(spec)
  if type(spec) ~= "table" or not spec.lab or not spec.technique or type(spec.budget_s) ~= "number" then
    error("autotune.run needs lab, technique and budget_s (seconds)", 2)
  end
  local desc = sl.technique(spec.technique)
  local params = tuned(desc, spec.params)
  local fixed = sl.params(spec.technique, spec.fixed or {})
  local region, field = (spec.error or "all.rmse"):match("^(%w+)%.([%w_]+)$")
  local time_field = spec.time or "frame"
  local budget = spec.evaluations or 24
  local history, memo, best = {}, {}, nil

  local function evaluate(values)
    local full = {}
    for k, v in pairs(fixed) do full[k] = v end
    for k, v in pairs(values) do full[k] = v end
    full = sl.params(spec.technique, full)
    local id = json.encode(full)
    if memo[id] then return memo[id] end
    if #history >= budget then return nil end
    local opts = { technique = spec.technique, params = full }
    for _, f in ipairs(compare_fields) do opts[f] = spec[f == "seed" and "reference_seed" or f] end
    local rec = spec.lab:compare(opts):record()
    local point = { params = full, error = rec.metrics[region][field], time = rec.timings_s[time_field], record = rec }
    point.feasible = point.time <= spec.budget_s
    history[#history + 1] = point
    memo[id] = point
    if better(point, best) then best = point end
    return point
  end

  local ranges = {}
  for _, p in ipairs(params) do
    if p.type == "int" or p.type == "float" then
      ranges[p.name] = { p.min, p.max, (p.type == "int" and "int" or "") .. (is_log(p) and " log" or "") }
    end
  end
  evaluate({})
  if next(ranges) then
    for _, point in ipairs(sweep.latin(ranges, spec.initial or 8, spec.seed or 1)) do evaluate(point) end
  end
  local step = 2
  while #history < budget and step >= 1 / 16 and best do
    local improved = false
    for _, p in ipairs(params) do
      for _, dir in ipairs({ 1, -1 }) do
        local values = {}
        for _, q in ipairs(params) do values[q.name] = best.params[q.name] end
        values[p.name] = moved(p, best.params[p.name], step, dir)
        local before = best
        evaluate(values)
        improved = improved or best ~= before
      end
    end
    if not improved then step = step / 2 end
  end
  return { best = best, history = history, feasible = best ~= nil and best.feasible }
end

return autotune
