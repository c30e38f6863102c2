-- issue5-combined.lua -- the combined report of the seed papers' soft-shadow
-- techniques and their baselines (issue 5): each on the bunny,
-- sphere-on-plane, overlap and contact scenes as the light grows from tiny to
-- large, error against time with the Pareto front of each scene variant.
--   build/shadowlab run experiments/issue5-combined.lua [--resume] [--shard I/N] ...
--   ISSUE5_TECHNIQUES=accumulation,pcss build/shadowlab run ...   (a subset)
-- Techniques are read from the registry: those of POINTS below that are
-- registered run (a technique that lands later joins with no edit here), each
-- at the listed points (nil: its defaults). Lights: sphere radius 0.02 to 0.8
-- on the sphere-light scenes; contact's square rect light 0.05 to 3 wide.
-- 240x180 view samples, 256-sample references (cached by content).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local RADII = { 0.02, 0.1, 0.4, 0.8 }
local WIDTHS = { 0.05, 0.25, 1.5, 3 }
-- Points per technique: a cheap one, the default and a quality one where the
-- technique has a cost knob, so each contributes a curve to the front.
local POINTS = {
  accumulation = { { K = 5 }, { K = 10 }, { K = 15 }, { K = 31 }, { K = 10, variant = "additive" },
                   { K = 15, variant = "additive" } },
  brabec = { { search_radius = 8 }, {}, { search_radius = 64 } },
  pcss = { {}, { blocker_taps = 64, filter_taps = 64 }, { sampling = "exhaustive" } },
  single_sample_rt = { {} },
  adaptive_area = { {} },
  shadow_width = { {} },
}
local ORDER = { "accumulation", "brabec", "pcss", "single_sample_rt", "adaptive_area", "shadow_width" }

local only
if os.getenv("ISSUE5_TECHNIQUES") then
  only = {}
  for name in os.getenv("ISSUE5_TECHNIQUES"):gmatch("[^,%s]+") do only[name] = true end
end
local registered = {}
for _, t in ipairs(sl.techniques()) do registered[t.name] = true end

local exp = experiment.new{
  name = "issue5-combined", samples = 256, repeats = 2, warmup = 1,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Issue 5: the seed papers' soft-shadow techniques and PCSS / single-sample baselines on four " ..
                "scenes, light radius 0.02-0.8 (contact: rect width 0.05-3), error against time.",
}
for _, s in ipairs({ "scenes/sphere-on-plane.lua", "scenes/bunny.lua", "scenes/overlap.lua" }) do
  exp:scene(s, sweep.grid{ ["lights[1].radius"] = RADII })
end
exp:scene("scenes/contact.lua", sweep.zip{ ["lights[1].width"] = WIDTHS, ["lights[1].height"] = WIDTHS })
for _, name in ipairs(ORDER) do
  if registered[name] and (not only or only[name]) then exp:add(name, POINTS[name]) end
end
report.write(exp:run(arg), { title = "Issue 5: soft shadows, error against frame time" })
