-- sweep.lua -- the points of a parameter sweep, as lists of tables
-- {name = value, ...}: cartesian grids, zipped lists, and random or
-- Latin-hypercube samples of ranges. Deterministic: names are visited in
-- sorted order and the random streams are seeded (splitmix64), so the same
-- call gives the same configurations, and so the same keys, on every machine.
local sweep = {}

local function sorted_keys(t)
  local keys = {}
  for k in pairs(t) do
    if type(k) ~= "string" then error("sweep: parameter names must be strings, got " .. type(k), 3) end
    keys[#keys + 1] = k
  end
  table.sort(keys)
  return keys
end

local function copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = v end
  return c
end

local function check_list(name, values, level)
  if type(values) ~= "table" or #values == 0 then
    error(string.format("sweep: %s needs a non-empty list of values", name), level)
  end
end

-- Every combination: grid{K = {1, 3}, map_size = {512, 1024}} gives 4 points,
-- the last name varying fastest (names sorted).
function sweep.grid(axes)
  local keys = sorted_keys(axes)
  local points = { {} }
  for _, name in ipairs(keys) do
    check_list(name, axes[name], 3)
    local grown = {}
    for _, p in ipairs(points) do
      for _, v in ipairs(axes[name]) do
        local q = copy(p)
        q[name] = v
        grown[#grown + 1] = q
      end
    end
    points = grown
  end
  return points
end

-- Element-wise: zip{K = {1, 3, 5}, map_size = {256, 512, 1024}} gives 3 points.
function sweep.zip(axes)
  local keys, n = sorted_keys(axes), nil
  for _, name in ipairs(keys) do
    check_list(name, axes[name], 3)
    if n and #axes[name] ~= n then
      error(string.format("sweep.zip: %s has %d values, the others %d", name, #axes[name], n), 2)
    end
    n = #axes[name]
  end
  local points = {}
  for i = 1, n or 0 do
    local p = {}
    for _, name in ipairs(keys) do p[name] = axes[name][i] end
    points[i] = p
  end
  return points
end

-- A seeded stream of uniform numbers in [0, 1) (splitmix64, 53 bits).
function sweep.rng(seed)
  local state = math.tointeger(seed) or error("sweep.rng: seed must be an integer", 2)
  return function()
    state = state + 0x9E3779B97F4A7C15
    local z = state
    z = (z ~ (z >> 30)) * 0xBF58476D1CE4E5B9
    z = (z ~ (z >> 27)) * 0x94D049BB133111EB
    z = z ~ (z >> 31)
    return (z >> 11) * (1.0 / 9007199254740992.0)
  end
end

-- A range is {min, max [, "int" | "log" | "int log"]}: ints are drawn from the
-- integers ceil(min) .. floor(max), "log" spreads samples evenly in log(value)
-- (map sizes, radii over decades).
local function check_range(name, r)
  if type(r) ~= "table" or type(r[1]) ~= "number" or type(r[2]) ~= "number" or r[1] > r[2] then
    error(string.format("sweep: range of %s must be {min, max [, 'int'|'log'|'int log']} with min <= max", name), 4)
  end
  local flags = r[3] or ""
  if flags:find("log") and r[1] <= 0 then
    error(string.format("sweep: log range of %s needs min > 0", name), 4)
  end
  if flags:find("int") and math.ceil(r[1]) > math.floor(r[2]) then
    error(string.format("sweep: int range of %s holds no integer", name), 4)
  end
  return flags:find("int") ~= nil, flags:find("log") ~= nil
end

-- The value at u in [0, 1) on a range. An integer k of an int range owns the
-- cell [k, k + 1) of the continuous range [lo, hi + 1), uniform or log-uniform,
-- and u is mapped onto that range and floored: every integer gets the weight
-- of its cell (all equal without "log"), and a stratum of u that spans one cell
-- lands in it exactly (rounding to the nearest instead gave the endpoints half
-- a cell, so a Latin sweep of n strata over n integers could miss one).
local function place(r, is_int, is_log, u)
  local lo, hi = r[1], r[2]
  if is_int then lo, hi = math.ceil(lo), math.floor(hi) + 1 end
  local v = is_log and math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))) or lo + u * (hi - lo)
  if is_int then v = math.tointeger(math.min(hi - 1, math.max(lo, math.floor(v)))) end
  return v
end

local function sample(ranges, n, seed, stratified)
  if math.type(n) ~= "integer" or n < 1 then error("sweep: the number of samples must be a positive integer", 3) end
  local keys, u = sorted_keys(ranges), sweep.rng(seed or 1)
  local points = {}
  for i = 1, n do points[i] = {} end
  for _, name in ipairs(keys) do
    local is_int, is_log = check_range(name, ranges[name])
    -- Latin hypercube: one sample in each of n strata, strata shuffled per axis.
    local order = {}
    for i = 1, n do order[i] = i end
    for i = n, 2, -1 do
      local j = math.floor(u() * i) + 1
      order[i], order[j] = order[j], order[i]
    end
    for i = 1, n do
      local t = stratified and (order[i] - 1 + u()) / n or u()
      points[i][name] = place(ranges[name], is_int, is_log, t)
    end
  end
  return points
end

-- n independent uniform samples: random({radius = {0.05, 0.5}}, 8, seed).
function sweep.random(ranges, n, seed) return sample(ranges, n, seed, false) end

-- n Latin-hypercube samples: every axis has one sample in each of n equal strata.
function sweep.latin(ranges, n, seed) return sample(ranges, n, seed, true) end

-- Ranges for the named parameters of a technique description (shadowlab.technique):
-- ints as "int", and "log" when the range spans a factor of 100 or more.
function sweep.ranges_of(technique, names)
  local ranges = {}
  for _, name in ipairs(names) do
    local found = technique.param[name]
    if not found then error(string.format("sweep.ranges_of: %s has no parameter %s", technique.name, name), 2) end
    if found.type ~= "int" and found.type ~= "float" then
      error(string.format("sweep.ranges_of: %s.%s is a %s, not a number", technique.name, name, found.type), 2)
    end
    local flags = (found.type == "int" and "int" or "") ..
                  ((found.min > 0 and found.max / found.min >= 100) and " log" or "")
    ranges[name] = { found.min, found.max, flags }
  end
  return ranges
end

return sweep
