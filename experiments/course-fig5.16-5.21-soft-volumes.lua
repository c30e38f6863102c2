-- course-fig5.16-5.21-soft-volumes.lua -- course §5.3.2, Figs. 5.16-5.21
-- measured: penumbra wedges (Akenine-Möller & Assarsson 2002), soft shadow
-- volumes (Assarsson & Akenine-Möller 2003) with the light split into 1,
-- 2x2 and 3x3 patches (§5.3.2.3), depth-complexity sampling (Laine et al.
-- 2005) at 16 (Forest 2008's GPU count) to 1024 samples and view-sample
-- mapping (§5.3.3), error against frame time on overlap.lua and the bunny
-- (sphere-on-plane when the bunny's model is absent), through the
-- standard report (error-vs-time plot, Pareto front). Then the course's
-- statements beside the lab's values:
--   * additive fusion "overestimates the umbra" (Figs. 1.7, 5.19): on
--     overlap.lua, the umbra share of soft_shadow_volume and penumbra_wedge
--     over the reference's, and their signed error in the penumbra;
--   * splitting the light into 2x2 or 3x3 patches: "better quality, but
--     execution time goes up rapidly" (§5.3.2.3): penumbra RMSE and frame
--     time at 3x3 over 1 patch;
--   * depth-complexity sampling is exact up to its sample count: its
--     penumbra RMSE at 1024 samples beside the reference's own noise.
--   build/shadowlab run experiments/course-fig5.16-5.21-soft-volumes.lua [--resume] ...
-- Images 240x180, 256 reference samples (--set camera.width=W ... for others).
-- Writes reports/course-fig5.16-5.21-soft-volumes/.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local SAMPLES = 256
local VIEW = { ["camera.width"] = 240, ["camera.height"] = 180 }
local NAME = "course-fig5.16-5.21-soft-volumes"

local exp = experiment.new{ error = "penumbra.rmse", name = NAME, samples = SAMPLES, repeats = 3, warmup = 1,
  overrides = VIEW,
  description = "Course Figs. 5.16-5.21: wedges, soft shadow volumes with light splitting, depth-complexity " ..
                "sampling and view-sample mapping, error against time." }
exp:scene("scenes/overlap.lua")
local second = "scenes/bunny.lua"
if not pcall(function() sl.open(sl.root .. "/" .. second, { ["camera.width"] = 8, ["camera.height"] = 6 }):close() end) then
  print(NAME .. ": the bunny's model did not load (SHADOWLAB_MODEL_PATH): sphere-on-plane in its place")
  second = "scenes/sphere-on-plane.lua"
end
exp:scene(second)
exp:add("penumbra_wedge")
exp:add("soft_shadow_volume", sweep.grid{ patches = { 1, 2, 3 } })
exp:add("depth_complexity", sweep.grid{ samples = { 16, 64, 256, 1024 } })
exp:add("view_sample_mapping", sweep.grid{ samples = { 64, 256 } })
local result = exp:run(arg)
report.write(result, { title = "Course Figs. 5.16-5.21: soft shadow volumes and depth-complexity sampling" })
if result.sharded then return end

-- The rows of one scene and technique, with a parameter value (or any).
local function row(scene_name, technique, key, value)
  for _, r in ipairs(result.rows) do
    if r.status == "ok" and r.record.scene.name == scene_name and r.technique == technique and
       (key == nil or r.params[key] == value) then return r end
  end
end
local function penumbra(r, field) return r and r.record.metrics.penumbra[field] end
local function frame(r) return r and r.record.timings_s.frame end

local claims = {}
local scenes = { "overlap", second:match("([^/]+)%.lua$") }
for _, s in ipairs(scenes) do
  local p1, p3 = row(s, "soft_shadow_volume", "patches", 1), row(s, "soft_shadow_volume", "patches", 3)
  claims[#claims + 1] = { item = s .. ": soft_shadow_volume 3x3 / 1 patch", quantity = "penumbra RMSE ratio",
                          paper = 1, measured = penumbra(p3, "rmse") and penumbra(p3, "rmse") / penumbra(p1, "rmse"),
                          rule = reproduce.below("splitting gives 'better quality'"), source = "course §5.3.2.3" }
  claims[#claims + 1] = { item = s .. ": soft_shadow_volume 3x3 / 1 patch", quantity = "frame time ratio",
                          paper = 1, measured = frame(p3) and frame(p3) / frame(p1),
                          rule = reproduce.above("'execution time goes up rapidly'"), source = "course §5.3.2.3" }
  local d = row(s, "depth_complexity", "samples", 1024)
  claims[#claims + 1] = { item = s .. ": depth_complexity, 1024 samples", quantity = "penumbra RMSE / reference noise",
                          paper = 2, measured = penumbra(d, "rmse") and penumbra(d, "noise_rms") > 0 and
                            penumbra(d, "rmse") / penumbra(d, "noise_rms") or 0 / 0,
                          rule = reproduce.below("exact up to its sample count: within twice the reference's noise"),
                          source = "Laine et al. 2005, course §5.3.2.3" }
end

-- Additive fusion on overlap.lua: umbra areas need the images, one more
-- render per configuration (the references are cached).
local lab = sl.open(sl.root .. "/scenes/overlap.lua", VIEW)
local fusion = {}
for _, cfg in ipairs{ { "soft_shadow_volume", { patches = 1 }, "soft_shadow_volume, 1 patch" },
                      { "penumbra_wedge", {}, "penumbra_wedge" },
                      { "depth_complexity", { samples = 256 }, "depth_complexity, 256" } } do
  local run = lab:compare{ technique = cfg[1], params = cfg[2], samples = SAMPLES, png = false, exr = false }
  local a, m = figures.areas(run), run:metrics()
  fusion[#fusion + 1] = { cfg[3], a.umbra, a.ref_umbra, m.penumbra.mean_signed }
  if cfg[1] ~= "depth_complexity" then
    claims[#claims + 1] = { item = "overlap: " .. cfg[3], quantity = "umbra share / reference's", paper = 1,
                            measured = a.ref_umbra > 0 and a.umbra / a.ref_umbra or 0 / 0,
                            rule = reproduce.above("additive fusion 'overestimates the umbra'"),
                            source = "course §5.3.2, Figs. 1.7, 5.19" }
    claims[#claims + 1] = { item = "overlap: " .. cfg[3], quantity = "mean signed error in the penumbra", paper = 0,
                            measured = m.penumbra.mean_signed,
                            rule = reproduce.below("too dark where the occluders overlap"),
                            source = "course §5.3.2, Figs. 1.7, 5.19" }
  end
end
lab:close()

local out = result.out
local page = figures.page(out, "Course Figs. 1.7, 5.19: additive fusion on overlap.lua",
  "Umbra (V <= 0.01) share of the light-facing samples, technique and reference, and the signed error in the " ..
  "reference's penumbra (negative: too dark).")
local t = {}
for i, f in ipairs(fusion) do
  t[i] = { f[1], string.format("%.2f", 100 * f[2]), string.format("%.2f", 100 * f[3]), string.format("%.4f", f[4]) }
end
page:table({ "technique", "umbra %", "reference umbra %", "penumbra mean signed error" }, t)
page:text(reproduce.compare(claims, { out = out, title = "Course Figs. 5.16-5.21",
                                      note = string.format("%d reference samples, %dx%d", SAMPLES,
                                                           VIEW["camera.width"], VIEW["camera.height"]) }).html)
page:write()
