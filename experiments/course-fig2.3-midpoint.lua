-- course-fig2.3-midpoint.lua -- course §2.1.2, Fig. 2.3 measured: midpoint
-- shadow maps (Woo 1992, z_ref = (z1 + z2) / 2) need no bias in principle
-- but fail both ways through the map's discretisation: incorrect
-- unshadowing where the surface is nearer to the light than a texel's
-- midpoint (false lit), and incorrect self-shadowing where lit parts lie
-- behind it (false shadow). `sm` with layers single (no bias, and the
-- slope-bias baseline), midpoint, dual (Weiskopf & Ertl 2003: the midpoint
-- capped at dual_max beyond the first layer) and second_depth (Wang &
-- Molnar 1994), at map sizes 256^2 to 2048^2, on contact.lua (boxes and a
-- 2 cm plate on the floor, light shrunk to 1 cm so the reference is a hard
-- shadow) and cones-and-hills.lua (a grazing spot).
--   build/shadowlab run experiments/course-fig2.3-midpoint.lua [--resume] ...
-- Writes reports/course-fig2.3-midpoint/: index.html, figure.html and
-- reproduction.{md,csv} (the figure's claims at 1024^2).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local SIZES = { 256, 512, 1024, 2048 }

local exp = experiment.new{
  name = "course-fig2.3-midpoint", samples = 16, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course Fig. 2.3: midpoint, dual-layer and second-depth maps against the map size: false lit " ..
                "(incorrect unshadowing) and false shadow (incorrect self-shadowing).",
}
exp:scene("scenes/contact.lua", { { ["lights[1].width"] = 0.01, ["lights[1].height"] = 0.01 } })
exp:scene("scenes/cones-and-hills.lua")
exp:add("sm", sweep.grid{ layers = { "single", "midpoint", "dual", "second_depth" }, map_size = SIZES,
                          slope_bias = { 0 } })
exp:add("sm", sweep.grid{ layers = { "single" }, map_size = SIZES, slope_bias = { 1 } })
local result = exp:run(arg)
report.write(result, { title = "Course Fig. 2.3: midpoint shadow maps against the map size (sm)" })
if result.sharded then return end

local function mode(r) return r.params.layers .. (r.params.slope_bias > 0 and " + slope bias 1" or "") end
local page = figures.page(result.out, "Course Fig. 2.3: where midpoint shadow maps fail",
  "Light-facing samples the map gets wrong against a hard-shadow reference: false lit (the figure's left case, " ..
  "incorrect unshadowing) and false shadow (its right case, incorrect self-shadowing), per depth-layer mode " ..
  "and map size. No constant or slope bias except the baseline.")
for _, scene in ipairs({ "contact", "cones-and-hills" }) do
  local series = { acne = {}, leaks = {} }
  local rows_table, used = {}, {}
  for _, g in ipairs(figures.group(result, function(r) return r.variant.scene .. "|" .. mode(r) end,
                                   function(r) return r.params.map_size end)) do
    if g.key:match("^[^|]*") == scene then
      local label = g.key:match("|(.*)$")
      local pts = { acne = {}, leaks = {} }
      for _, r in ipairs(g.rows) do
        used[#used + 1] = r
        pts.acne[#pts.acne + 1] = { r.params.map_size, 100 * figures.acne(r) }
        pts.leaks[#pts.leaks + 1] = { r.params.map_size, 100 * figures.leaks(r) }
        rows_table[#rows_table + 1] = { label, tostring(r.params.map_size), string.format("%.3f", 100 * figures.leaks(r)),
                                        string.format("%.3f", 100 * figures.acne(r)),
                                        string.format("%.4f", r.record.metrics.all.rmse) }
      end
      for _, what in ipairs({ "acne", "leaks" }) do
        table.insert(series[what], { title = label, points = pts[what], style = "linespoints" })
      end
    end
  end
  page:heading(scene)
  for _, what in ipairs({ "leaks", "acne" }) do
    page:plot("fig2.3-" .. scene .. "-" .. what, {
      title = (what == "leaks" and "False lit (incorrect unshadowing)" or "False shadow (incorrect self-shadowing)") ..
              " on " .. scene,
      rows = used, subtitle = "sm depth layers without bias", xlabel = "map size (texels per side, log scale)",
      ylabel = "% of light-facing samples", logx = true, series = series[what],
    })
  end
  page:table({ "layers", "map size", "false lit %", "false shadow %", "RMSE" }, rows_table)
end
-- Course §2.1.2, Fig. 2.3 (no figures given): the midpoint needs no bias against acne, but fails both ways.
local at = {} -- "scene|mode" -> the 1024^2 row
for _, r in ipairs(result.rows) do
  if r.status == "ok" and r.params.map_size == 1024 then at[r.variant.scene .. "|" .. mode(r)] = r end
end
local claims = {}
local FEWER = reproduce.below("the map 'can then be safely set to the average distance' (Woo 1992), no bias: " ..
                              "its false shadow below a bias-free single map's")
local FAILS = reproduce.above("Fig. 2.3's two failure cases occur: a share above 0")
for _, scene in ipairs({ "contact", "cones-and-hills" }) do
  local mid, single = at[scene .. "|midpoint"], at[scene .. "|single"]
  if mid and single then
    claims[#claims + 1] = { item = scene .. ", 1024^2: midpoint / single (no bias)", quantity = "false shadow ratio",
                            paper = 1, measured = figures.acne(mid) / figures.acne(single), rule = FEWER,
                            source = "course §2.1.2" }
    claims[#claims + 1] = { item = scene .. ", 1024^2 midpoint: incorrect unshadowing", quantity = "false lit",
                            unit = "%", paper = 0, measured = 100 * figures.leaks(mid), rule = FAILS,
                            source = "course Fig. 2.3 (left)" }
    claims[#claims + 1] = { item = scene .. ", 1024^2 midpoint: incorrect self-shadowing", quantity = "false shadow",
                            unit = "%", paper = 0, measured = 100 * figures.acne(mid), rule = FAILS,
                            source = "course Fig. 2.3 (right)" }
  end
end
page:text(reproduce.compare(claims, { out = result.out, title = "Course Fig. 2.3",
                                      note = "sm without bias, shares of the light-facing samples." }).html)
page:write()
