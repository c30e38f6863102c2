-- lab-kernel-size.lua -- a teaching lab: the filter kernel of percentage-closer
-- filtering (course §4.1.2, Eq. 4.1) against the ray-traced reference, for a
-- small and a large spherical light. It sweeps pcf's kernel width K, all else
-- at its defaults, and keeps `sm` (no filtering) as the baseline; other
-- techniques with a parameter K on request (--techniques pcf,vsm, or all).
-- The ball rests on the ground here (the scene's ball floats 0.4 above it),
-- so its shadow has a contact point. Run:
--   build/shadowlab run experiments/lab-kernel-size.lua [--techniques pcf,vsm]
-- then open reports/lab-kernel-size/index.html, which starts with the
-- questions below; the plots, the results table and the images answer them.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local QUESTIONS = {
  "For the small light (radius 0.1), which K gives the lowest penumbra RMSE (the error-vs-K plot, the table's " ..
  "penumbra RMSE column)? For the large light (0.4)? Why does the best K grow with the light, and why is a " ..
  "fixed K wrong for both at once?",
  "The shadow map is rendered from the light's centre, so its key ignores K: in the table's resources column " ..
  "only the first K of each light size is \"cold\" (it built the map) and every other K is \"warm\" (it reused " ..
  "it). Why does the frame time still count the map's build time (see the definition of frame time above)? " ..
  "What does it tell you about how much PCF knows of the light's size? (Run with --techniques csm and every " ..
  "row is cold: csm's moment map and summed-area table, 3.3 GiB at map_size 1024, exceed the experiment's " ..
  "2 GiB resource budget, so they are dropped and rebuilt for every K.)",
  "How does the cost grow with K for the box kernel (the cost-vs-K plot, log scales)? Explain the shape from " ..
  "the number of depth comparisons per pixel.",
  "Look at the signed-error images for the largest K: where does PCF leak light (red) and where does it " ..
  "over-darken (blue)? Is its error larger near the point where the ball touches the ground or at the " ..
  "shadow's outer edge? Explain from the true penumbra's width, which grows with the distance from the ball " ..
  "to the ground, against PCF's kernel, whose width in texels is the same everywhere.",
  "Which configurations are on the Pareto front (the error-vs-time plot's labelled points, the table's green " ..
  "rows)? Is the unfiltered shadow map (sm) ever on it, and why?",
}

local KERNELS = { 1, 3, 5, 9, 15, 25 }
local args = experiment.parse_args(arg, { techniques = { default = "pcf",
  help = "comma-separated techniques with a parameter K to sweep (all: every one)" } })
local chosen = experiment.technique_set(args.extra.techniques)

local exp = experiment.new{ error = "penumbra.rmse", -- progress lines and plots
  name = "lab-kernel-size", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 320, ["camera.height"] = 240, ["objects[2].translate"] = { 0, 0.6, 0 } },
  description = "PCF kernel width K against the reference, for a small and a large spherical light, " ..
                "the ball resting on the ground.",
}
exp:scene("scenes/sphere-on-plane.lua", sweep.grid{ ["lights[1].radius"] = { 0.1, 0.4 } })

local with_k = 0
for _, t in ipairs(sl.techniques()) do
  local p = t.param.K
  if p and (chosen.all or chosen[t.name]) then
    local ks = {}
    for _, k in ipairs(KERNELS) do
      if k >= p.min and k <= p.max then ks[#ks + 1] = k end
    end
    exp:add(t.name, sweep.grid{ K = ks })
    with_k = with_k + 1
  end
end
if with_k == 0 then
  error("lab-kernel-size: no chosen technique has a parameter K (pcf should: see `shadowlab list`)", 0)
end
if pcall(sl.technique, "sm") then exp:add("sm") end
report.write(exp:run(args), { title = "Lab: PCF kernel size", questions = QUESTIONS })
