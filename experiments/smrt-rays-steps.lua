-- smrt-rays-steps.lua -- shadow-map ray tracing (`smrt`: UE5's virtual shadow
-- maps, Blender's EEVEE Next) against rays x steps, beside `pcss` at its
-- defaults, on sphere-on-plane (one ball over a plane) and overlap.lua (a
-- small slab high up over the edge of a large low one: the map stores only
-- the high one where they overlap, the leak Epic's cvar help admits "behind
-- second occluders"). Error (penumbra RMSE by default; umbra leak in the
-- table and records) against frame time, reported like the other
-- experiments: reports/smrt-rays-steps/index.html (error vs time, the
-- Pareto front, results.csv). Engine defaults for comparison: UE5 7 rays x 8
-- samples per ray for local lights; EEVEE's shadow_ray_count 1 to 4,
-- shadow_step_count 1 to 16 (default 6). Run:
--   build/shadowlab run experiments/smrt-rays-steps.lua [--set camera.width=320 --set camera.height=240]
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local RAYS = { 1, 2, 4, 8 }
local STEPS = { 1, 2, 4, 8, 16 }

local args = experiment.parse_args(arg, {})
local exp = experiment.new{ error = "penumbra.rmse",
  name = "smrt-rays-steps", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 160, ["camera.height"] = 120 },
  description = "smrt's rays per receiver x depth-map samples per ray against the Embree reference, beside " ..
                "pcss at its defaults, on sphere-on-plane and overlap.lua (occluders overlapping in depth).",
}
exp:scene("scenes/sphere-on-plane.lua")
exp:scene("scenes/overlap.lua")
exp:add("smrt", sweep.grid{ rays = RAYS, steps = STEPS })
exp:add("pcss")
report.write(exp:run(args), { title = "smrt: rays x steps against pcss" })
