-- course-fig5.14-outer-penumbra.lua -- course §5.3.1 (Fig. 5.14, missing
-- from the course text) measured: the outer-penumbra methods, single-sample
-- soft shadows (seed 002, `single_sample_rt`), smoothies (Chan & Durand
-- 2003) and penumbra maps (Wyman & Hansen 2003), add a penumbra outside the
-- light centre's hard shadow only, "so the umbra is overestimated for large
-- lights" (course §5.3.1 [OWN]). On sphere-on-plane.lua at light radius
-- 0.1 .. 0.8 (the ball's is 0.6): the share of light-facing samples each
-- method puts in umbra (V <= 0.01) against the Embree reference's, and the
-- share of its umbra the reference sees lit (V_ref > 0.05).
--   build/shadowlab run experiments/course-fig5.14-outer-penumbra.lua [--resume] ...
-- Writes reports/course-fig5.14-outer-penumbra/: index.html (the sweep's
-- errors and times), figure.html and reproduction.{md,csv}: per method, the
-- umbra share over the reference's at the largest light (the claim: above
-- 1) and its growth from the smallest light to the largest (above 1).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local RADII = { 0.1, 0.2, 0.4, 0.8 }
local TECHS = { "smoothies", "penumbra_map", "single_sample_rt" }
local SCENE = "scenes/sphere-on-plane.lua"

local exp = experiment.new{ error = "penumbra.rmse",
  name = "course-fig5.14-outer-penumbra", samples = 256, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course §5.3.1: the umbra of the outer-penumbra methods (smoothies, penumbra_map, " ..
                "single_sample_rt) against the reference's as the light grows.",
}
exp:scene(SCENE, sweep.grid{ ["lights[1].radius"] = RADII })
for _, t in ipairs(TECHS) do exp:add(t) end
local result = exp:run(arg)
report.write(result, { title = "Course §5.3.1: outer-penumbra methods as the light grows" })
if result.sharded then return end

-- The share of a method's umbra (V <= 0.01) that the reference sees lit (V_ref > 0.05).
local function excess_umbra(run)
  local vis, ref, cls = run:image("visibility"), run:image("reference"), run:image("class")
  local w, h = vis:size()
  local claimed, lit = 0, 0
  for y = 1, h do
    for x = 1, w do
      if cls:get(x, y) == 1 and vis:get(x, y) <= 0.01 then
        claimed = claimed + 1
        if ref:get(x, y) > 0.05 then lit = lit + 1 end
      end
    end
  end
  return claimed > 0 and lit / claimed or 0 / 0
end

local page = figures.page(result.out, "Course §5.3.1: outer penumbrae overestimate the umbra of large lights",
  string.format("Share of the light-facing samples in umbra (V <= 0.01), each method at its defaults against " ..
                "the Embree reference (%d samples), on sphere-on-plane with light radius %s (the ball's is 0.6).",
                exp.samples, table.concat(RADII, ", ")))
local series, rows_table, runs, by_tech = {}, {}, {}, {}
local ref_points = {}
for _, radius in ipairs(RADII) do
  local overrides = { ["lights[1].radius"] = radius }
  for k, v in pairs(exp.overrides) do overrides[k] = v end
  local lab = sl.open(sl.root .. "/" .. SCENE, overrides)
  for _, t in ipairs(TECHS) do
    local run = lab:compare{ technique = t, samples = exp.samples, png = false, exr = false }
    local a, m = figures.areas(run), run:metrics()
    runs[#runs + 1] = run:record()
    local ratio = a.ref_umbra > 0 and a.umbra / a.ref_umbra or 0 / 0
    by_tech[t] = by_tech[t] or {}
    by_tech[t][#by_tech[t] + 1] = { radius = radius, ratio = ratio, excess = excess_umbra(run), a = a }
    if t == TECHS[1] then ref_points[#ref_points + 1] = { radius, 100 * a.ref_umbra } end
    rows_table[#rows_table + 1] = { t, string.format("%g", radius), string.format("%.2f", 100 * a.umbra),
                                    string.format("%.2f", 100 * a.ref_umbra), string.format("%.3f", ratio),
                                    string.format("%.3f", by_tech[t][#by_tech[t]].excess),
                                    string.format("%.4f", m.umbra.rmse), string.format("%.4f", m.penumbra.rmse) }
  end
  lab:close()
end

local claims = {}
for _, t in ipairs(TECHS) do
  local pts, first, last = {}, by_tech[t][1], by_tech[t][#by_tech[t]]
  for _, p in ipairs(by_tech[t]) do pts[#pts + 1] = { p.radius, 100 * p.a.umbra } end
  series[#series + 1] = { title = t, points = pts, style = "linespoints" }
  claims[#claims + 1] = { item = string.format("%s, light radius %g", t, last.radius),
                          quantity = "umbra share, method / reference", paper = 1, measured = last.ratio,
                          rule = reproduce.above("'the umbra is overestimated for large lights' (no figure): above 1"),
                          source = "course §5.3.1 [OWN]" }
  claims[#claims + 1] = { item = string.format("%s, radius %g over %g", t, last.radius, first.radius),
                          quantity = "growth of the umbra share ratio", paper = 1,
                          measured = last.ratio / first.ratio,
                          rule = reproduce.above("outer penumbra only: the overestimate grows with the light: above 1"),
                          source = "course §5.3.1 [OWN]" }
end
series[#series + 1] = { title = "reference", points = ref_points, style = "linespoints" }
page:plot("fig5.14-umbra", { title = "Umbra area against the light's radius", rows = runs,
                             subtitle = "sphere-on-plane", xlabel = "light radius (world units)",
                             ylabel = "% of light-facing samples", series = series })
page:table({ "technique", "radius", "umbra % (method)", "umbra % (ref)", "ratio", "umbra lit in ref", "umbra RMSE",
             "penumbra RMSE" }, rows_table)
page:text(reproduce.compare(claims, { out = result.out, title = "Course §5.3.1, Fig. 5.14",
                                      note = "each method at its defaults; umbra: V <= 0.01." }).html)
page:write()
