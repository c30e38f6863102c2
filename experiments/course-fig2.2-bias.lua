-- course-fig2.2-bias.lua -- course §2.1.2, Fig. 2.2 measured: shadow acne
-- (z-fighting, false shadow on lit surfaces) against light leaks (false lit,
-- "most visible at contact shadows") as the depth bias of `sm` grows, for a
-- constant bias (world units) and for the slope-scaled bias, on the boxes of
-- contact.lua (the figure's cube on a plane; its 1.5 m light shrunk to 1 cm
-- so the reference is a hard shadow) and on the grazing spot of
-- cones-and-hills.lua. Acne and leaks are the record's false_shadow and
-- false_lit counts (reference lit > 0.5 and estimate < 0.5, and the reverse)
-- over the light-facing samples.
--   build/shadowlab run experiments/course-fig2.2-bias.lua [--resume] ...
-- Writes reports/course-fig2.2-bias/: index.html (the sweep) and figure.html
-- (acne and leaks against each bias), reproduction.{md,csv} (the figure's
-- two claims per scene and bias kind). 240 x 180 views, a few seconds per
-- configuration on 2 cores.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local CONSTANT = { 0, 0.0003, 0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 0.5 } -- world units (the box is 1 tall)
local SLOPE = { 0, 0.25, 0.5, 1, 2, 4, 8, 16 }                      -- x depth slope
local ZERO_AT = { constant = 1e-4, slope = 0.1 }                      -- where 0 is drawn on the log axis

local exp = experiment.new{
  name = "course-fig2.2-bias", samples = 16, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course Fig. 2.2: acne against leaks as sm's constant or slope-scaled depth bias grows.",
}
exp:scene("scenes/contact.lua", { { ["lights[1].width"] = 0.01, ["lights[1].height"] = 0.01 } })
exp:scene("scenes/cones-and-hills.lua")
exp:add("sm", sweep.grid{ bias = CONSTANT, slope_bias = { 0 } })
exp:add("sm", sweep.grid{ bias = { 0 }, slope_bias = SLOPE })
local result = exp:run(arg)
report.write(result, { title = "Course Fig. 2.2: acne and leaks against depth bias (sm)" })
if result.sharded then return end

local page = figures.page(result.out, "Course Fig. 2.2: acne against leaks as the depth bias grows",
  "sm with a constant bias (slope bias 0) and with a slope-scaled bias (constant 0). Acne: light-facing samples " ..
  "the reference calls lit (> 0.5) that the map shadows; leaks: the reverse. The course: a bias lifts the " ..
  "depth ambiguities but 'can also introduce light leaks ... most visible at contact shadows'.")
-- Course §2.1.2, Fig. 2.2: a bias 'lifts the depth ambiguities (5th from left), but can also introduce light
-- leaks'. The course gives no figures: acne must fall and leaks grow from no bias to the largest swept.
local ACNE = reproduce.below("Fig. 2.2 shows no numbers: the largest bias's acne over no bias's, below 1")
local LEAKS = reproduce.above("Fig. 2.2 shows no numbers: leaks at the largest bias minus at no bias, above 0")
local claims = {}
for _, kind in ipairs({ "constant", "slope" }) do
  local function swept(r) return kind == "constant" and r.params.slope_bias == 0 and r.params.bias or r.params.slope_bias end
  local function mine(r) return kind == "constant" and r.params.slope_bias == 0 or (kind == "slope" and r.params.bias == 0) end
  local rows_table, used = {}, {}
  local series = { acne = {}, leaks = {} }
  for _, g in ipairs(figures.group(result, function(r) return r.variant.scene end, swept)) do
    local pts, ends = { acne = {}, leaks = {} }, {}
    for _, r in ipairs(g.rows) do
      if mine(r) then
        used[#used + 1] = r
        ends[1], ends[2] = ends[1] or r, r
        local x = swept(r) > 0 and swept(r) or ZERO_AT[kind]
        pts.acne[#pts.acne + 1] = { x, 100 * figures.acne(r) }
        pts.leaks[#pts.leaks + 1] = { x, 100 * figures.leaks(r) }
        rows_table[#rows_table + 1] = { g.key, string.format("%g", swept(r)), string.format("%.3f", 100 * figures.acne(r)),
                                        string.format("%.3f", 100 * figures.leaks(r)),
                                        string.format("%.4f", r.record.metrics.all.rmse) }
      end
    end
    for _, what in ipairs({ "acne", "leaks" }) do
      table.insert(series[what], { title = g.key, points = pts[what], style = "linespoints" })
    end
    local item = string.format("%s, %s bias %g -> %g", g.key, kind, swept(ends[1]), swept(ends[2]))
    claims[#claims + 1] = { item = item, quantity = "acne ratio", paper = 1,
                            measured = figures.acne(ends[2]) / figures.acne(ends[1]), rule = ACNE,
                            source = "course §2.1.2, Fig. 2.2" }
    claims[#claims + 1] = { item = item, quantity = "leak change", unit = "% points", paper = 0,
                            measured = 100 * (figures.leaks(ends[2]) - figures.leaks(ends[1])), rule = LEAKS,
                            source = "course §2.1.2, Fig. 2.2" }
  end
  page:heading(kind == "constant" and "Constant bias" or "Slope-scaled bias")
  for _, what in ipairs({ "acne", "leaks" }) do
    page:plot("fig2.2-" .. kind .. "-" .. what, {
      title = (what == "acne" and "Acne (false shadow on lit surfaces)" or "Leaks (false lit in shadow)") ..
              " against the " .. kind .. " bias (sm, 1024^2 map)",
      rows = used, subtitle = string.format("0 drawn at %g", ZERO_AT[kind]),
      xlabel = kind == "constant" and "constant bias (world units, log scale)" or "slope bias (x depth slope, log scale)",
      ylabel = "% of light-facing samples", logx = true, series = series[what],
    })
  end
  page:table({ "scene", kind .. " bias", "acne %", "leaks %", "RMSE" }, rows_table)
end
page:text(reproduce.compare(claims, { out = result.out, title = "Course Fig. 2.2",
                                      note = "sm, 1024^2 map; acne and leaks over the light-facing samples." }).html)
page:write()
