-- error-vs-time.lua -- the headline plot: every registered technique (those
-- that land later appear with no edit: it reads the registry) at its
-- defaults and at a few values of its main parameter, on the default scene
-- and the Stanford bunny, against the Embree reference: error against frame
-- time, with the Pareto front of each scene marked.
--   build/shadowlab run experiments/error-vs-time.lua [--resume] [--shard I/N] ...
-- The main parameter is the one each technique declares in the registry
-- (`main parameter` in shadowlab list: K, layers, terms, map size...), unless
-- MAIN below names another; it
-- is swept over 1/2, 1 and 2 times its default (--factors), within its range. Images
-- are 240x180 (--set camera.width=W --set camera.height=H for others) and
-- the reference takes 256 light samples: a few minutes on 2 cores, the
-- references cached for the next run.
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local MAIN = {} -- e.g. MAIN.pcf = "map_size" to sweep the map instead of the kernel
local args = experiment.parse_args(arg, { factors = { default = "0.5,1,2",
                                                      help = "multiples of each main parameter's default" } })
local FACTORS = {}
for f in args.extra.factors:gmatch("[^,]+") do
  FACTORS[#FACTORS + 1] = tonumber(f) or error("--factors expects numbers separated by commas, got " .. f, 0)
end

local function main_parameter(t)
  local name = MAIN[t.name] or t.main
  for _, p in ipairs(t.params) do
    if p.name == name then return p end
  end
end

-- The points of a technique: its default, and FACTORS x default of its main parameter.
local function points(t)
  local p = main_parameter(t)
  if not p or p.default == 0 then return { {} } end
  local list, seen = {}, {}
  for _, f in ipairs(FACTORS) do
    local v = math.max(p.min, math.min(p.max, p.default * f))
    if p.type == "int" then v = math.tointeger(math.floor(v + 0.5)) end
    if not seen[v] then
      seen[v] = true
      list[#list + 1] = { [p.name] = v }
    end
  end
  return list
end

local exp = experiment.new{
  name = "error-vs-time", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Every registered technique at its defaults and at 1/2, 1 and 2 times the default of its " ..
                "main parameter, on sphere-on-plane and the Stanford bunny.",
}
exp:scene("scenes/sphere-on-plane.lua")
exp:scene("scenes/bunny.lua")
exp:add_registry{ points = points }
report.write(exp:run(args), { title = "Error against frame time, every registered technique" })
