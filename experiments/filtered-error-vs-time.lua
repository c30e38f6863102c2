-- filtered-error-vs-time.lua -- issue 3's comparison of the filtered hard
-- shadows (course ch.4 and MSM): error against frame time at a matched
-- filter width (K = 7, hardware-style bilinear lookups, box prefilter, one
-- 1024^2 map) and at matched bits per texel (moment-map storage: 64, 128
-- and 256 bits; PCF reads a 32-bit depth map), on the Stanford bunny (a
-- sphere light: a six-face cube map) and the terrain (a sun: four cascades).
-- Frame time counts every resource rebuilt per frame (map, moments, blur)
-- plus the evaluation (median of 3). The bits per texel are measured from
-- the record (moment-map bytes over depth-map bytes, x 32).
--   SHADOWLAB_MODEL_PATH=../shared/models build/shadowlab run experiments/filtered-error-vs-time.lua
-- Writes reports/filtered-error-vs-time/: figure.html, and each scene's sweep in bunny/ and terrain/.
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local COMMON = { K = 7, map_size = 1024 }
-- { technique, its own settings, nominal bits per texel }
local CONFIGS = {
  { "pcf", { kernel = "bilinear" }, 32 },
  { "vsm", { precision = "f32" }, 64 },
  { "esm", { precision = "f64" }, 64 },
  { "evsm", { warps = "positive", precision = "f32" }, 64 },
  { "csm", { terms = 1, precision = "f32" }, 64 },
  { "vsm", { precision = "f64" }, 128 },
  { "evsm", { warps = "both", precision = "f32" }, 128 },
  { "msm", { precision = "f32" }, 128 },
  { "lvsm", { layers = 2, precision = "f32" }, 128 },
  { "csm", { terms = 2, precision = "f32" }, 128 },
  { "evsm", { warps = "both", precision = "f64" }, 256 },
  { "msm", { precision = "f64" }, 256 },
  { "lvsm", { layers = 4, precision = "f32" }, 256 },
  { "csm", { terms = 4, precision = "f32" }, 256 },
}

-- Per scene: the terrain's camera is 2 m above 1 km of ground, where one
-- map aliases whatever the filter (RMSE 0.40 for VSM against 0.15 with
-- cascades): every technique there reads 4 cascades fitted to the view.
local SCENES = { { "bunny", {} }, { "terrain", { cascades = 4, fit = "body" } } }
local base = experiment.parse_args(arg).out or "reports/filtered-error-vs-time"
local page = figures.page(base, "Filtered hard shadows at matched width and bits per texel",
  "K = 7, 1024^2 map (terrain: 4 cascades of 1024^2 fitted to the view), box prefilter, bilinear lookups; RMSE " ..
  "against a 256-sample Embree reference (240x180) against the frame time (resources rebuilt + median " ..
  "evaluation). One series per storage budget. The sweeps: bunny/index.html, terrain/index.html.")

local function run_scene(scene, extra)
  local exp = experiment.new{
    name = "filtered-error-vs-time-" .. scene, samples = 256, repeats = 3, warmup = 1,
    overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
    description = "Filtered hard shadows at K = 7 and matched bits per texel (64, 128, 256) on " .. scene .. ".",
  }
  exp:scene("scenes/" .. scene .. ".lua")
  for _, c in ipairs(CONFIGS) do
    local p = {}
    for _, t in ipairs({ COMMON, extra, c[2] }) do
      for k, v in pairs(t) do p[k] = v end
    end
    if c[1] ~= "pcf" then p.prefilter, p.lookup = "box", "bilinear" end
    exp:add(c[1], { p })
  end
  local argv = { "--out", base .. "/" .. scene }
  for i, a in ipairs(arg) do
    if a ~= "--out" and arg[i - 1] ~= "--out" then argv[#argv + 1] = a end
  end
  local result = exp:run(argv)
  report.write(result, { title = "Filtered hard shadows on " .. scene .. ": error against frame time (K = 7)" })
  return result
end

for _, sc in ipairs(SCENES) do
  local scene = sc[1]
  local result = run_scene(scene, sc[2])
  if result.sharded then return end
  local budgets, rows_table, used = {}, {}, {}
  for _, r in ipairs(result.rows) do
    if r.status == "ok" then
      used[#used + 1] = r
      local bits = figures.bits_per_texel(r)
      local budget = string.format("%d bits", math.floor(bits / 32 + 0.5) * 32)
      budgets[budget] = budgets[budget] or {}
      table.insert(budgets[budget], { 1e3 * r.record.timings_s.frame, r.record.metrics.all.rmse })
      local own = {}
      for k, v in pairs(r.params) do
        if k == "precision" or k == "warps" or k == "terms" or k == "layers" or (r.technique == "pcf" and k == "kernel") then
          own[#own + 1] = k .. "=" .. tostring(v)
        end
      end
      table.sort(own)
      rows_table[#rows_table + 1] = { r.technique, table.concat(own, " "), string.format("%.1f", bits),
                                      string.format("%.4f", r.record.metrics.all.rmse),
                                      string.format("%.4f", r.record.metrics.umbra.leak_mean),
                                      string.format("%.1f", 1e3 * r.record.timings_s.technique_build),
                                      string.format("%.1f", 1e3 * r.record.timings_s.evaluate_median),
                                      string.format("%.1f", 1e3 * r.record.timings_s.frame) }
    end
  end
  local series, names = {}, {}
  for b in pairs(budgets) do names[#names + 1] = b end
  table.sort(names, function(a, b) return tonumber(a:match("%d+")) < tonumber(b:match("%d+")) end)
  for _, b in ipairs(names) do series[#series + 1] = { title = b, points = budgets[b], style = "points" } end
  page:heading(scene)
  page:plot("filtered-" .. scene, { title = "RMSE against frame time, " .. scene, logx = true, rows = used,
                                    subtitle = "K = 7; one point per technique, grouped by bits per texel",
                                    xlabel = "frame time (ms, log scale)", ylabel = "RMSE", series = series })
  page:table({ "technique", "settings", "bits/texel", "RMSE", "umbra leak", "resources ms", "eval ms", "frame ms" },
             rows_table)
end
page:write()
