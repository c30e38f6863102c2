-- seed003-shadow-width.lua -- seed 003 (Kirsch & Döllner 2003) against the
-- Embree reference: Fig. 7's claim that with linear filtering even a 64 x 64
-- depth map gives an acceptable shadow of a simple occluder (artefacts only
-- where blocker and receiver are close, and intensity discontinuities at the
-- shadow's outer border), §5's self-shadowing treatment (back faces, a
-- z-greater test), its failure on overlapping blockers (overlap.lua: the
-- united occlusion map makes widths too high, the shadow too dark), and the
-- softness constant c_scale, beside `sm` and `hard`. One perspective map from
-- the light's centre everywhere (the paper's setting).
--   build/shadowlab run experiments/seed003-shadow-width.lua [--resume] ...
-- Writes reports/seed003-shadow-width/: the usual report, plus fig7.md (the
-- images at 64^2 nearest and bilinear and at 1024^2, with their errors) and
-- errors.md (error per region, over-darkening and leaks, per configuration).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local exp = experiment.new{
  name = "seed003-shadow-width", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 320, ["camera.height"] = 240 },
  description = "Seed 003: shadow_width at 64^2 and 1024^2 with nearest and bilinear lookups (Fig. 7), with " ..
                "the back-face depth map of §5, and across c_scale, beside sm and hard, on ball-and-disk, " ..
                "sphere-on-plane, " ..
                "contact and overlap.",
}
exp:scene("scenes/ball-and-disk.lua") -- Fig. 7's setting: the map's texels spent on a ball and a disk
exp:scene("scenes/sphere-on-plane.lua")
exp:scene("scenes/contact.lua")
exp:scene("scenes/overlap.lua")
exp:add("shadow_width", sweep.grid{ projection = { "perspective" }, map_size = { 64, 1024 },
                                     filter = { "nearest", "bilinear" } })
exp:add("shadow_width", sweep.grid{ projection = { "perspective" }, self_shadow = { "backfaces" } })
exp:add("shadow_width", sweep.grid{ projection = { "perspective" }, c_scale = { 2, 4, 16, 32 } })
exp:add("sm", sweep.grid{ projection = { "perspective" } })
exp:add("hard")
local result = exp:run(arg)
report.write(result, { title = "Seed 003: shadow-width soft shadows", error = "all.mae" })
if result.sharded then return end

local function label(r)
  if r.technique ~= "shadow_width" then return r.technique end
  local p = r.params
  return string.format("shadow_width %d^2 %s%s c_scale %g", p.map_size, p.filter,
                       p.self_shadow == "backfaces" and " backfaces" or "", p.c_scale)
end

local err_md = { "# Seed 003: errors against the reference", "",
                 string.format("%d reference samples, %s; MAE per region; dark/leak: mean over-darkening and " ..
                               "leaking over the penumbra.", exp.samples, "320 x 240"), "",
                 "| scene | configuration | MAE all | MAE penumbra | MAE umbra | dark (penumbra) | leak (penumbra) |",
                 "|---|---|---:|---:|---:|---:|---:|" }
local fig7 = { "# Seed 003, Fig. 7: a 64 x 64 depth map", "",
               "Shaded images and signed error (blue: too dark, red: leaking) at 64^2 with nearest and bilinear " ..
               "lookups, and at 1024^2.", "" }
for _, r in ipairs(result.rows) do
  if r.status == "ok" then
    local m = r.record.metrics
    err_md[#err_md + 1] = string.format("| %s | %s | %.4f | %.4f | %.4f | %.4f | %.4f |", r.variant.scene, label(r),
                                        m.all.mae, m.penumbra.mae, m.umbra.mae, m.penumbra.dark_mean,
                                        m.penumbra.leak_mean)
    local p = r.params
    if r.images and r.technique == "shadow_width" and p.self_shadow == "blockers" and p.c_scale == 8 then
      fig7[#fig7 + 1] = string.format("## %s: %s (MAE %.4f, penumbra %.4f)\n\n![shaded](%s) ![error](%s)\n",
                                      r.variant.scene, label(r), m.all.mae, m.penumbra.mae, r.images.shaded,
                                      r.images.error)
    end
  end
end
sl.write_file(result.out .. "/errors.md", table.concat(err_md, "\n") .. "\n")
sl.write_file(result.out .. "/fig7.md", table.concat(fig7, "\n") .. "\n")
io.stderr:write("seed003: " .. result.out .. "/fig7.md, errors.md\n")
