-- error-vs-time.lua -- the headline plot: every registered technique (those
-- that land later appear with no edit: it reads the registry) at its
-- defaults and at a few values of its main parameter, on the default scene
-- and the Stanford bunny (sphere lights), plus a scene from scenes/ for each
-- technique that handles neither light (adaptive_area: rect lights only, so
-- contact.lua), against the Embree reference: error against frame time,
-- with the Pareto front of each scene marked.
--   build/shadowlab run experiments/error-vs-time.lua [--resume] [--shard I/N] ...
-- The main parameter is the one each technique declares in the registry
-- (`main parameter` in shadowlab list: K, layers, terms, map size...), unless
-- MAIN below names another; it is swept over 1/2, 1 and 2 times its default
-- (--factors), within its range and within what the technique accepts here
-- (see accepted_below). Images are 240x180 (--set camera.width=W --set
-- camera.height=H for others) and the reference takes 256 light samples: a
-- few minutes on 2 cores, the references cached for the next run.
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local MAIN = {} -- e.g. MAIN.pcf = "map_size" to sweep the map instead of the kernel
local SCENES = { "scenes/sphere-on-plane.lua", "scenes/bunny.lua" }
-- A scene per light type, for a technique that handles no light of SCENES.
local SCENE_FOR_LIGHT = { rect = "scenes/contact.lua", textured_rect = "scenes/textured-light.lua",
                          spot = "scenes/cones-and-hills.lua", directional = "scenes/overhead-plane.lua" }
local LIGHT = 1 -- the light every configuration uses (experiment.new's default)
local PROBE_VIEW = { ["camera.width"] = 8, ["camera.height"] = 6 }

local args = experiment.parse_args(arg, { factors = { default = "0.5,1,2",
                                                      help = "multiples of each main parameter's default" } })
local FACTORS = {}
for f in args.extra.factors:gmatch("[^,]+") do
  FACTORS[#FACTORS + 1] = tonumber(f) or error("--factors expects numbers separated by commas, got " .. f, 0)
end

-- Small-view Labs of the scenes (with the run's --set overrides), to read
-- their lights and to probe what a technique accepts.
local probes = {}
local function add_probe(file)
  local overrides = {}
  for k, v in pairs(args.set) do overrides[k] = v end
  for k, v in pairs(PROBE_VIEW) do overrides[k] = v end
  local lab = sl.open(sl.root .. "/" .. file, overrides)
  probes[#probes + 1] = { file = file, lab = lab, name = lab:info().name, light = lab:info().lights[LIGHT].type }
end
for _, file in ipairs(SCENES) do add_probe(file) end

-- Every technique gets a scene whose light it handles: SCENES, else the
-- first of its light types that SCENE_FOR_LIGHT has.
for _, t in ipairs(sl.techniques()) do
  local covered = false
  for _, p in ipairs(probes) do covered = covered or experiment.handles(t, p.light) end
  if not covered then
    local file
    for _, l in ipairs(t.lights) do file = file or SCENE_FOR_LIGHT[l] end
    if not file then
      error(string.format("error-vs-time: %s handles only %s lights, and no scene of SCENE_FOR_LIGHT has one: " ..
                          "add one", t.name, table.concat(t.lights, ", ")), 0)
    end
    add_probe(file)
  end
end

local function main_parameter(t)
  local name = MAIN[t.name] or t.main
  return name and t.param[name]
end

-- Why some scene of the experiment refuses technique t at params (nil: none
-- does). The probe renders on an 8x6 view: what refuses a point is its
-- resources (a moment map over the prefilter's memory cap, say), and they do
-- not depend on the view's size.
local function refusal(t, params)
  for _, p in ipairs(probes) do
    if experiment.handles(t, p.light) then
      local ok, msg = pcall(p.lab.render, p.lab, { technique = t.name, params = params, light = LIGHT })
      p.lab:drop_resources()
      if not ok then return p.name .. ": " .. tostring(msg) end
    end
  end
end

-- A point above the default that a scene refuses at this experiment's
-- settings is replaced by the largest accepted value below it, found by
-- bisection between the default (which the registry's defaults must run)
-- and the refused value, so a full run has no failed row. The case today:
-- csm at 2x its 16 terms, 32, needs a 64-channel f64 moment map of 3 GiB on
-- the sphere lights' cube maps, above the 2 GiB cap (prefilter.c). Neither
-- csm's f32 precision (an f32 summed-area table loses the moments' small
-- differences: catalogue §4.2, "never use an fp32 SAT") nor a smaller map
-- would be csm at its defaults but more terms, which is what the sweep means.
local function accepted_below(t, p, value)
  local why = refusal(t, { [p.name] = value })
  if not why then return value end
  local lo, hi = p.default, value
  for _ = 1, 12 do
    local mid = p.type == "int" and (lo + hi) // 2 or (lo + hi) / 2
    if mid == lo then break end
    if refusal(t, { [p.name] = mid }) then hi = mid else lo = mid end
  end
  io.stderr:write(string.format("error-vs-time: %s %s=%s is refused (%s): %s=%s instead, the largest accepted\n",
                                t.name, p.name, tostring(value), why:gsub("\n.*", ""), p.name, tostring(lo)))
  return lo
end

-- The points of a technique: its default, and FACTORS x default of its main
-- parameter, clamped to the parameter's range and to what the scenes accept;
-- every choice of an enum main parameter, both values of a bool.
local function points(t)
  local p = main_parameter(t)
  if p and p.type == "enum" then -- a choice of method (shadow_volume's z-pass, z-fail, ZP+): each one
    local list = {}
    for _, c in ipairs(p.choices) do list[#list + 1] = { [p.name] = c } end
    return list
  end
  if p and p.type == "bool" then return { { [p.name] = false }, { [p.name] = true } } end
  if not p or p.default == 0 then return { {} } end
  local list, seen = {}, {}
  for _, f in ipairs(FACTORS) do
    local v = math.max(p.min, math.min(p.max, p.default * f))
    if p.type == "int" then v = math.tointeger(math.floor(v + 0.5)) end
    if v > p.default then v = accepted_below(t, p, v) end
    if not seen[v] then
      seen[v] = true
      list[#list + 1] = { [p.name] = v }
    end
  end
  return list
end

local exp = experiment.new{
  name = "error-vs-time", samples = 256, repeats = 3, warmup = 1, light = LIGHT,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Every registered technique at its defaults and at 1/2, 1 and 2 times the default of its " ..
                "main parameter (a value the technique refuses here replaced by the largest it accepts), on " ..
                "sphere-on-plane, the Stanford bunny and, for techniques that handle neither's light, a scene " ..
                "with one.",
}
for _, p in ipairs(probes) do exp:scene(p.file) end
exp:add_registry{ points = points }
for _, p in ipairs(probes) do p.lab:close() end
report.write(exp:run(args), { title = "Error against frame time, every registered technique" })
