-- lab-light-radius.lua -- a teaching lab: how each technique copes as the
-- light grows from nearly a point to a large sphere. Every registered
-- technique that handles sphere lights, at its defaults, on the default
-- scene, with lights[1].radius swept over 0.02 .. 0.8 (the ball's radius is
-- 0.6). Run: build/shadowlab run experiments/lab-light-radius.lua, then open
-- reports/lab-light-radius/index.html.
--
-- Questions for students (answer from the report's plots, table and images):
--  1. Which techniques' error grows with the radius (error-vs-radius plot),
--     and why can a single binary occlusion test (hard, sm) not follow? How
--     does their error relate to the area of the reference's penumbra?
--  2. As the radius shrinks to 0.02, which technique converges to the
--     reference, and which keeps an error floor? Name the cause of each
--     floor (aliasing, bias, a kernel that does not shrink with the light).
--  3. Does any technique's cost depend on the radius (cost-vs-radius plot)?
--     Which would, by design (course §4.3, PCSS's blocker search)?
--  4. At radius 0.8, compare the umbra, penumbra and lit RMSE in the table:
--     where does each technique lose most? Check against the signed-error
--     images (red: light leaking, blue: too dark).
--  5. The reference's noise grows with the radius at a fixed sample count
--     (why?): at which radius would you need more samples to trust the
--     smallest errors? (Look for errors below the dashed noise line.)
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local RADII = { 0.02, 0.05, 0.1, 0.2, 0.4, 0.8 }

local exp = experiment.new{
  name = "lab-light-radius", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 320, ["camera.height"] = 240 },
  description = "Every technique that handles sphere lights, at its defaults, as the light's radius grows.",
}
exp:scene("scenes/sphere-on-plane.lua", sweep.grid{ ["lights[1].radius"] = RADII })
exp:add_registry{ filter = function(t)
  for _, l in ipairs(t.lights) do
    if l == "sphere" then return true end
  end
  return false
end }
report.write(exp:run(arg), { title = "Lab: light radius" })
