-- course-fig5.10-5.11-multiscale.lua -- course §5.2.3.4-5, Figs. 5.10 and
-- 5.11 measured on the multiscale backprojection variants (hsm, mssm, ysm;
-- src/techniques/backprojection.c):
--   Fig. 5.10: the share of receivers that need backprojection after the
--     early outs (aux `class`: 0 lit, 1 umbra, 2 backprojected), per
--     variant, on the bunny (scenes/bunny.lua; SHADOWLAB_MODEL_PATH, glmark2's
--     bunny the fallback) and spheres.lua. The course: MSSM gives "much
--     better classification" than HSM; YSM is "a good choice in practice"
--     (close to MSSM's classification).
--   Fig. 5.11: hsm's accuracy against the texel budget T (penumbra RMSE
--     against the Embree reference, T = 2 .. 64), and the level-switch
--     artefacts at a small budget without and with `blend`: the excess
--     roughness, the mean over horizontally adjacent penumbra samples of
--     max(0, |dV| - |dV_ref|) (a jump the reference does not have), and
--     blending's cost (evaluation time ratio, one run: state the load).
--   build/shadowlab run experiments/course-fig5.10-5.11-multiscale.lua [--resume] ...
-- Writes reports/course-fig5.10-5.11-multiscale/: index.html, figure.html
-- and reproduction.{md,csv}.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local BUDGETS = { 2, 4, 8, 16, 32, 64 }
local SMALL_BUDGET = 4
local VARIANTS = { "hsm", "mssm", "ysm" }

local exp = experiment.new{ error = "penumbra.rmse",
  name = "course-fig5.10-5.11-multiscale", samples = 256, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course Figs. 5.10 and 5.11: the share of receivers needing backprojection for HSM, MSSM and " ..
                "YSM; accuracy against the texel budget and level-switch artefacts with and without blending.",
}
exp:scene("scenes/bunny.lua")
exp:scene("scenes/spheres.lua")
for _, t in ipairs(VARIANTS) do exp:add(t) end
exp:add("hsm", sweep.grid{ budget = BUDGETS, blend = { false, true } })
local result = exp:run(arg)
report.write(result, { title = "Course Figs. 5.10 and 5.11: multiscale backprojection" })
if result.sharded then return end

local function ok(r) return r.status == "ok" end
local function scene_of(r) return r.variant.scene end
local file_of = {} -- scene name -> its file, for the extra runs below
for _, r in ipairs(result.rows) do file_of[r.variant.scene] = r.variant.file end
-- Share of the lit candidates backprojected (aux `class` counts: [1] lit, [2] umbra, [3] backprojected).
local function backprojected(r)
  local c = r.record.aux and r.record.aux.class
  if not c or c.lit_candidates == 0 then return 0 / 0 end
  return c.counts[3] / c.lit_candidates
end
local function is_default(r) return r.params.budget == 32 and not r.params.blend end

local page = figures.page(result.out, "Course Figs. 5.10 and 5.11: multiscale backprojection",
  "Share of receivers that need backprojection after the early outs, per min-max structure (Fig. 5.10), and " ..
  "hsm's accuracy against the texel budget with and without level blending (Fig. 5.11).")

-- Fig. 5.10
local share, rows_table, claims = {}, {}, {}
for _, r in ipairs(result.rows) do
  if ok(r) and is_default(r) then
    local s = scene_of(r)
    share[s] = share[s] or {}
    share[s][r.technique] = share[s][r.technique] or backprojected(r)
  end
end
for _, s in ipairs({ "bunny", "spheres" }) do
  local sh = share[s]
  if sh then
    for _, t in ipairs(VARIANTS) do
      rows_table[#rows_table + 1] = { s, t, string.format("%.2f", 100 * (sh[t] or 0 / 0)) }
    end
    claims[#claims + 1] = { item = s .. ": mssm / hsm", quantity = "share backprojected, ratio", paper = 1,
                            measured = sh.mssm and sh.hsm and sh.mssm / sh.hsm,
                            rule = reproduce.below("'much better classification' than HSM (Fig. 5.10): below 1"),
                            source = "course §5.2.3.4, Fig. 5.10" }
    claims[#claims + 1] = { item = s .. ": ysm / hsm", quantity = "share backprojected, ratio", paper = 1,
                            measured = sh.ysm and sh.hsm and sh.ysm / sh.hsm,
                            rule = reproduce.below("YSM adds MSSM levels above HSM's first n: below 1"),
                            source = "course §5.2.3.4" }
    claims[#claims + 1] = { item = s .. ": ysm / mssm", quantity = "share backprojected, ratio", paper = 1,
                            measured = sh.ysm and sh.mssm and sh.ysm / sh.mssm,
                            rule = reproduce.factor(1.1, "'a good choice in practice' (no figure): YSM's " ..
                                                         "classification within 10% of MSSM's"),
                            source = "course §5.2.3.4" }
  end
end
page:heading("Fig. 5.10: receivers needing backprojection")
page:table({ "scene", "technique", "backprojected % of lit candidates" }, rows_table)

-- Fig. 5.11: accuracy against T (hsm, no blending), on each scene.
local acc, acc_rows, series = {}, {}, {}
for _, g in ipairs(figures.group(result, function(r)
    return r.technique == "hsm" and scene_of(r) .. (r.params.blend and ", blend" or "") or "" end,
  function(r) return r.params.budget end)) do
  if g.key ~= "" then
    local pts = {}
    for _, r in ipairs(g.rows) do
      local e = r.record.metrics.penumbra.rmse
      pts[#pts + 1] = { r.params.budget, e }
      acc[g.key] = acc[g.key] or {}
      acc[g.key][r.params.budget] = e
      acc_rows[#acc_rows + 1] = { g.key, tostring(r.params.budget), string.format("%.4f", e),
                                  string.format("%.3f", r.record.timings_s.evaluate_median) }
    end
    series[#series + 1] = { title = g.key, points = pts, style = "linespoints" }
  end
end
page:plot("fig5.11-budget", { title = "Penumbra RMSE against the texel budget (hsm)", rows = result.rows,
                              xlabel = "texel budget T (lexels)", ylabel = "penumbra RMSE", series = series })
page:table({ "scene", "T", "penumbra RMSE", "evaluate (s)" }, acc_rows)
for _, s in ipairs({ "bunny", "spheres" }) do
  local a = acc[s]
  if a and a[BUDGETS[1]] and a[BUDGETS[#BUDGETS]] then
    claims[#claims + 1] = { item = string.format("%s: hsm, T = %d / T = %d", s, BUDGETS[1], BUDGETS[#BUDGETS]),
                            quantity = "penumbra RMSE ratio", paper = 1,
                            measured = a[BUDGETS[1]] / a[BUDGETS[#BUDGETS]],
                            rule = reproduce.above("coarser levels for a smaller budget lose accuracy (Fig. 5.11): " ..
                                                   "above 1"),
                            source = "course §5.2.3.5, Fig. 5.11" }
  end
end

-- Level-switch artefacts at T = SMALL_BUDGET: excess roughness and cost, blend off and on, one run each.
local function roughness(run)
  local v, ref, region = run:image("visibility"), run:image("reference"), run:image("region")
  local w, h = v:size()
  local sum, n = 0, 0
  for y = 1, h do
    for x = 1, w - 1 do
      if region:get(x, y) == 1 and region:get(x + 1, y) == 1 then
        local d = math.abs(v:get(x + 1, y) - v:get(x, y)) - math.abs(ref:get(x + 1, y) - ref:get(x, y))
        sum, n = sum + math.max(d, 0), n + 1
      end
    end
  end
  return n > 0 and sum / n or 0 / 0, n
end
local switch_rows = {}
for _, s in ipairs({ "bunny", "spheres" }) do
  local okopen, lab = false, "not in this run"
  if file_of[s] then okopen, lab = pcall(sl.open, file_of[s], exp.overrides) end
  if okopen then
    local rough, time, pairs_n = {}, {}, {}
    for round = 1, 3 do -- alternating, so both see the same load; the least disturbed of 15 evaluations each
      for _, blend in ipairs({ false, true }) do
        local run = lab:compare{ technique = "hsm", params = { budget = SMALL_BUDGET, blend = blend },
                                 samples = exp.samples, repeats = 5, warmup = 1, png = false, exr = false }
        if round == 1 then rough[blend], pairs_n[blend] = roughness(run) end
        local t = run:record().timings_s.evaluate_min
        time[blend] = math.min(time[blend] or t, t)
      end
    end
    for _, blend in ipairs({ false, true }) do
      switch_rows[#switch_rows + 1] = { s, tostring(blend), tostring(pairs_n[blend]),
                                        string.format("%.5f", rough[blend]), string.format("%.4f", time[blend]) }
    end
    lab:close()
    local item = string.format("%s: hsm T = %d, blend / no blend", s, SMALL_BUDGET)
    claims[#claims + 1] = { item = item, quantity = "excess roughness ratio", paper = 1,
                            measured = rough[true] / rough[false],
                            rule = reproduce.below("'blending two levels fixes this' (Fig. 5.11f): below 1"),
                            source = "course §5.2.3.5, Fig. 5.11f" }
    claims[#claims + 1] = { item = item, quantity = "evaluation time ratio", paper = 1,
                            measured = time[true] / time[false],
                            rule = reproduce.above("'at extra cost': above 1 (one run; the load is the machine's)"),
                            source = "course §5.2.3.5" }
  else
    io.stderr:write("skipped " .. s .. ": " .. tostring(lab) .. "\n")
  end
end
page:heading("Fig. 5.11f: level switches")
page:table({ "scene", "blend", "penumbra pairs", "excess roughness", "evaluate (s)" }, switch_rows)
local f = io.open("/proc/loadavg", "r")
local load = f and f:read("*l"):match("^(%S+)") or "unknown"
if f then f:close() end
local w, h = exp.overrides["camera.width"], exp.overrides["camera.height"]
page:text(reproduce.compare(claims, { out = result.out, title = "Course Figs. 5.10 and 5.11",
  note = string.format("hsm, mssm, ysm at their defaults (1024^2, budget 32, microquads, 256-sample bitmask); " ..
                       "hsm's budget sweep without and with blending; %sx%s, %d reference samples; time ratios " ..
                       "are minima of 15 evaluations, alternating, in one run, load average %s", tostring(w), tostring(h),
                       exp.samples, load) }).html)
page:write()
