-- lab-kernel-size.lua -- a teaching lab: the filter kernel of percentage-closer
-- filtering (course §4.1.2, Eq. 4.1) against the ray-traced reference, for a
-- small and a large spherical light. It sweeps the kernel width K of every
-- registered technique that has a parameter K (pcf, the filtered maps, and
-- whatever lands later; --techniques pcf,vsm for some), all else at its
-- defaults, and keeps `sm` (no filtering) as the baseline. Run:
-- build/shadowlab run experiments/lab-kernel-size.lua, then open
-- reports/lab-kernel-size/index.html.
--
-- Questions for students (answer from the report's plots, table and images):
--  1. For the small light (radius 0.1), which K gives the lowest penumbra
--     RMSE? For the large light (0.4)? Why does the best K grow with the
--     light, and why is a fixed K wrong for both at once?
--  2. The shadow map is built once for both light sizes: it is rendered
--     from the light's centre, so its key ignores the radius. Find in
--     records.jsonl that only a technique's first configuration builds it
--     and every other K, on either radius, reuses it ("action": "reused").
--     Why does the frame time still count its build time (see the definition
--     in the report)? What does it tell you about how much PCF knows of the
--     light's size?
--  3. How does the cost grow with K for the box kernel (cost-vs-K plot)?
--     Explain the shape from the number of depth comparisons per pixel.
--  4. Look at the signed-error images for the largest K: where does PCF leak
--     light (red) and where does it over-darken (blue)? Why near the contact
--     of the ball's shadow with the ground less than at its outer edge?
--  5. Which configurations are on the Pareto front? Is the unfiltered shadow
--     map ever on it, and why?
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local KERNELS = { 1, 3, 5, 9, 15, 25 }
local args = experiment.parse_args(arg, { techniques = { default = "all",
  help = "comma-separated techniques to sweep (all: every one with a parameter K)" } })
local chosen = {}
for name in args.extra.techniques:gmatch("[^,]+") do chosen[name] = true end

local exp = experiment.new{
  name = "lab-kernel-size", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 320, ["camera.height"] = 240 },
  description = "PCF kernel width K against the reference, for a small and a large spherical light.",
}
exp:scene("scenes/sphere-on-plane.lua", sweep.grid{ ["lights[1].radius"] = { 0.1, 0.4 } })

local with_k = 0
for _, t in ipairs(sl.techniques()) do
  for _, p in ipairs(t.params) do
    if p.name == "K" and (chosen.all or chosen[t.name]) then
      local ks = {}
      for _, k in ipairs(KERNELS) do
        if k >= p.min and k <= p.max then ks[#ks + 1] = k end
      end
      exp:add(t.name, sweep.grid{ K = ks })
      with_k = with_k + 1
    end
  end
end
if with_k == 0 then
  error("lab-kernel-size: no chosen technique has a parameter K (pcf should: see `shadowlab list`)", 0)
end
if pcall(sl.technique, "sm") then exp:add("sm") end
report.write(exp:run(args), { title = "Lab: PCF kernel size", error = "penumbra.rmse" })
