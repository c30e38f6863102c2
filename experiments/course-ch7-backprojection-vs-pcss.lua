-- course-ch7-backprojection-vs-pcss.lua -- the course's chapter 7 summary
-- table on backprojection with bitmasks and microquads (§5.2.3), the choice
-- for "precision and robustness": its drawback, "coarse levels can look worse
-- than PCSS". backprojection and hsm (src/techniques/backprojection.c) at
-- texel budgets T = 2 .. 64 (course §5.2.3.5, Fig. 5.11: the finest level
-- whose window fits T lexels a side) against pcss at its defaults, on
-- sphere-on-plane, overlap and the bunny (scenes/bunny.lua; skipped, said on
-- stderr, when its model is not on SHADOWLAB_MODEL_PATH): the penumbra RMSE
-- against the Embree reference, and its ratio backprojection / pcss per
-- budget. The claim is judged at the coarsest budgets (T = 2 and 4): above 1.
--   build/shadowlab run experiments/course-ch7-backprojection-vs-pcss.lua [--resume] ...
-- Writes reports/course-ch7-backprojection-vs-pcss/: index.html, figure.html
-- and reproduction.{md,csv}.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local BUDGETS = { 2, 4, 8, 16, 32, 64 }
local VARIANTS = { "backprojection", "hsm" }
local SCENES = { "sphere-on-plane", "overlap", "bunny" }
-- The budgets judged: hsm is backprojection plus the early outs, which skip only receivers whose V they know
-- (measured equal at every budget), so one of its budgets checks that.
local COARSEST = { backprojection = { 2, 4 }, hsm = { 2 } }

local exp = experiment.new{ error = "penumbra.rmse",
  name = "course-ch7-backprojection-vs-pcss", samples = 256, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course ch. 7: coarse backprojection levels (small texel budgets) against PCSS, penumbra RMSE.",
}
for _, s in ipairs(SCENES) do
  local file = sl.root .. "/scenes/" .. s .. ".lua"
  local ok, lab = pcall(sl.open, file, { ["camera.width"] = 8, ["camera.height"] = 6 }) -- a model may be absent
  if ok then
    lab:close()
    exp:scene(file)
  else
    io.stderr:write("skipped " .. s .. ": " .. tostring(lab) .. "\n")
  end
end
exp:add("pcss")
for _, t in ipairs(VARIANTS) do exp:add(t, sweep.grid{ budget = BUDGETS }) end
local result = exp:run(arg)
report.write(result, { title = "Course ch. 7: coarse backprojection levels against PCSS" })
if result.sharded then return end

local rmse = {} -- rmse[scene][technique][budget or "default"]
for _, r in ipairs(result.rows) do
  if r.status == "ok" then
    local s, t = r.variant.scene, r.technique
    rmse[s] = rmse[s] or {}
    rmse[s][t] = rmse[s][t] or {}
    rmse[s][t][t == "pcss" and "default" or r.params.budget] = r.record.metrics.penumbra.rmse
  end
end

local claims, rows_table, series = {}, {}, {}
for _, s in ipairs(SCENES) do
  local e = rmse[s]
  local pcss = e and e.pcss and e.pcss.default
  if pcss then
    for _, t in ipairs(VARIANTS) do
      local pts = {}
      for _, T in ipairs(BUDGETS) do
        local v = e[t] and e[t][T]
        if v then
          pts[#pts + 1] = { T, v / pcss }
          rows_table[#rows_table + 1] = { s, t, tostring(T), string.format("%.4f", v), string.format("%.4f", pcss),
                                          string.format("%.3f", v / pcss) }
        end
      end
      series[#series + 1] = { title = s .. ", " .. t, points = pts, style = "linespoints" }
      for _, T in ipairs(COARSEST[t]) do
        local v = e[t] and e[t][T]
        claims[#claims + 1] = { item = string.format("%s: %s T = %d / pcss", s, t, T),
                                quantity = "penumbra RMSE ratio", paper = 1, measured = v and v / pcss,
                                rule = reproduce.above("'coarse levels can look worse than PCSS': above 1 at the " ..
                                                       "coarsest budgets"),
                                source = "course ch. 7 summary table (§5.2.3.5, Fig. 5.11)" }
      end
    end
  end
end

local page = figures.page(result.out, "Course ch. 7: coarse backprojection levels against PCSS",
  "Penumbra RMSE against the Embree reference of backprojection and hsm (microquads, 256-sample bitmask, 1024^2) " ..
  "at each texel budget T, over pcss's at its defaults, per scene.")
page:plot("ch7-budget-vs-pcss", { title = "Penumbra RMSE / PCSS's against the texel budget", rows = result.rows,
                                  xlabel = "texel budget T (lexels)", ylabel = "penumbra RMSE / pcss",
                                  series = series })
page:table({ "scene", "technique", "T", "penumbra RMSE", "pcss penumbra RMSE", "ratio" }, rows_table)
local w, h = exp.overrides["camera.width"], exp.overrides["camera.height"]
page:text(reproduce.compare(claims, { out = result.out, title = "Course ch. 7: backprojection against PCSS",
  note = string.format("backprojection and hsm at their defaults but for the budget, pcss at its defaults; %sx%s, " ..
                       "%d reference samples", tostring(w), tostring(h), exp.samples) }).html)
page:write()
