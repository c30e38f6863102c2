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
  return desc.param[name] or error(string.format("autotune: %s has no parameter %s", desc.name, name), 3)
end

-- The tuned parameters: the named ones (enums and bools step through their
-- values), else the technique's main parameter (the registry's main_param, `main` in Lua:
-- its kernel, terms, search radius) and its shadow map's resolution where it
-- has one; a technique without a main parameter tunes its numeric ones.
-- Biases, splits and warp settings are tuned only when named: their ranges
-- reach 1e6 and 1e9 and a blind search spends its budget on refused maps.
local function tuned(desc, names)
  local list = {}
  if not names then names = autotune.default_params(desc) end
  for _, n in ipairs(names) do list[#list + 1] = find_param(desc, n) end
  if #list == 0 then error("autotune: " .. desc.name .. " has no numeric parameter to tune", 3) end
  return list
end

-- The names tuned() picks when none are given (a technique description from sl.technique).
function autotune.default_params(desc)
  local names = {}
  if desc.main then names[#names + 1] = desc.main end
  if desc.param.map_size and desc.main ~= "map_size" then names[#names + 1] = "map_size" end
  if #names > 0 then return names end
  for _, p in ipairs(desc.params) do
    if p.type == "int" or p.type == "float" then names[#names + 1] = p.name end
  end
  return names
end

-- How a numeric range is searched: in log(value) when it spans a factor 100
-- or more. A range from 0 that spans decades is searched in log over
-- [floor, max], floor = 1e-3 of the default (of max when the default is 0):
-- linear steps of (max - min) / 8 would jump from 0 to 125,000 on a bias
-- range of [0, 1e6]. 0 itself is reached as the default, which is evaluated
-- first.
local function log_floor(p)
  if p.min > 0 then return p.max / p.min >= 100 and p.min or nil end
  local scale = p.default and p.default > 0 and p.default or p.max
  local floor = scale * 1e-3
  if p.type == "int" then floor = math.max(1, floor) end
  return p.max / floor >= 100 and floor or nil
end

local function is_log(p) return log_floor(p) ~= nil end

-- One coordinate move of parameter p from value v by `step`: a factor 2^step
-- on log ranges (from 0, to the log range's floor), step/8 of the width
-- otherwise, at least 1 for ints; the next or previous choice of an enum; the
-- other value of a bool.
local function moved(p, v, step, direction)
  if p.type == "bool" then return not v end
  if p.type == "enum" then
    local i = 1
    for k, c in ipairs(p.choices) do
      if c == v then i = k end
    end
    return p.choices[(i - 1 + direction) % #p.choices + 1]
  end
  local x
  if is_log(p) then
    x = v > 0 and v * 2 ^ (direction * step) or (direction > 0 and log_floor(p) or v)
  else
    x = v + direction * step * (p.max - p.min) / 8
  end
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

-- autotune.run{lab = LAB, technique = NAME, budget_s = S, params = {names} (default:
-- the main parameter and map_size, see tuned), fixed = {name = value}, evaluations = 24,
-- initial = 8, seed = 1, time = "frame" | "evaluate_median", error = "all.rmse", and
-- lab:compare's light, repeats (default 5), warmup (default 1), samples, pattern, cache,
-- reference_seed (its `seed`)}. Returns {best, history, feasible, refused}: every
-- evaluated point has params, error, time (the median of its repeats), feasible and its
-- record; a point the engine refuses (a map over its memory cap, splits that do not fit)
-- is skipped, listed in `refused` with the engine's message, and counts as an
-- evaluation. A point measured over the budget by at most 2x is measured once more
-- and keeps the faster time (noise only adds time; point.measured = 2), so one slow
-- measurement does not mark it infeasible for the rest of the search (points are
-- memoised).
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
  local history, refused, memo, best = {}, {}, {}, nil
  local timing = { repeats = spec.repeats or 5, warmup = spec.warmup or 1 }

  local function measure(full)
    local opts = { technique = spec.technique, params = full }
    for _, f in ipairs(compare_fields) do opts[f] = timing[f] or spec[f == "seed" and "reference_seed" or f] end
    local ok, run = pcall(spec.lab.compare, spec.lab, opts)
    if not ok then return nil, tostring(run) end
    return run:record()
  end

  local function evaluate(values)
    local full = {}
    for k, v in pairs(fixed) do full[k] = v end
    for k, v in pairs(values) do full[k] = v end
    full = sl.params(spec.technique, full)
    local id = json.encode(full)
    if memo[id] then return memo[id] end
    if #history + #refused >= budget then return nil end
    local rec, msg = measure(full)
    if not rec then
      local point = { params = full, refused = true, message = msg }
      refused[#refused + 1] = point
      memo[id] = point
      return point
    end
    local point = { params = full, record = rec, time = rec.timings_s[time_field] }
    if point.time > spec.budget_s and point.time <= 2 * spec.budget_s then
      local again = measure(full) -- noise only adds time: the faster of two measurements stands
      if again and again.timings_s[time_field] < point.time then point.record, point.time = again, again.timings_s[time_field] end
      point.measured = 2
    end
    point.error = point.record.metrics[region][field]
    point.feasible = point.time <= spec.budget_s
    history[#history + 1] = point
    memo[id] = point
    if better(point, best) then best = point end
    return point
  end

  local ranges = {}
  for _, p in ipairs(params) do
    if p.type == "int" or p.type == "float" then
      ranges[p.name] = { log_floor(p) or p.min, p.max, (p.type == "int" and "int" or "") .. (is_log(p) and " log" or "") }
    end
  end
  evaluate({})
  if next(ranges) then
    for _, point in ipairs(sweep.latin(ranges, spec.initial or 8, spec.seed or 1)) do evaluate(point) end
  end
  local step = 2
  while #history + #refused < budget and step >= 1 / 16 and best do
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
  return { best = best, history = history, refused = refused, feasible = best ~= nil and best.feasible }
end

return autotune
