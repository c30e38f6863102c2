-- course-fig4.3-pcf-umbra.lua -- course §4.1.2, Fig. 4.3 measured: PCF
-- tests rays from the light's centre, not from the shaded point, with a
-- window that ignores distances, so against a physical area light "the
-- resulting umbra is too large and the penumbra too small". `pcf` (box) at
-- K = 1 .. 31 on sphere-on-plane.lua for a small (0.1) and a large (0.4)
-- light: the share of light-facing samples in umbra (V <= 0.01) and in
-- penumbra (0.01 < V < 0.99) for PCF and for the Embree reference, and the
-- errors per region.
--   build/shadowlab run experiments/course-fig4.3-pcf-umbra.lua [--resume] ...
-- Writes reports/course-fig4.3-pcf-umbra/: index.html, figure.html and
-- reproduction.{md,csv}: per light, the claim at the K whose penumbra error
-- is lowest (the window a user would pick).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local KERNELS = { 1, 3, 5, 9, 15, 23, 31 }
local RADII = { 0.1, 0.4 }
local SAMPLES = 256
local VIEW = { ["camera.width"] = 240, ["camera.height"] = 180 }

local exp = experiment.new{ error = "penumbra.rmse", -- progress lines and plots
  name = "course-fig4.3-pcf-umbra", samples = SAMPLES, repeats = 1, warmup = 0, overrides = VIEW,
  description = "Course Fig. 4.3: PCF's umbra and penumbra against the reference's, over K, for two light sizes.",
}
exp:scene("scenes/sphere-on-plane.lua", sweep.grid{ ["lights[1].radius"] = RADII })
exp:add("pcf", sweep.grid{ K = KERNELS, kernel = { "box" } })
local result = exp:run(arg)
report.write(result, { title = "Course Fig. 4.3: PCF's umbra and penumbra" })
if result.sharded then return end

-- Areas need the images: one more render per configuration (the references are cached).
local page = figures.page(result.out, "Course Fig. 4.3: PCF's umbra is too large, its penumbra too small",
  "Share of the light-facing samples in umbra (V <= 0.01) and penumbra (0.01 < V < 0.99), PCF (box, 1024^2 map) " ..
  "against the Embree reference, for sphere-on-plane with light radius 0.1 and 0.4 (the ball's is 0.6).")
local umbra, penumbra, rows_table, runs = {}, {}, {}, {}
local claims = {}
for _, radius in ipairs(RADII) do
  local overrides = { ["lights[1].radius"] = radius }
  for k, v in pairs(VIEW) do overrides[k] = v end
  local lab = sl.open(sl.root .. "/scenes/sphere-on-plane.lua", overrides)
  local u, p = {}, {}
  local ref_area, best
  for _, K in ipairs(KERNELS) do
    local run = lab:compare{ technique = "pcf", params = { K = K, kernel = "box" }, samples = SAMPLES, png = false,
                             exr = false }
    local a, m = figures.areas(run), run:metrics()
    runs[#runs + 1] = run:record()
    ref_area = a
    if not best or m.penumbra.rmse < best.rmse then best = { K = K, a = a, rmse = m.penumbra.rmse } end
    u[#u + 1] = { K, 100 * a.umbra }
    p[#p + 1] = { K, 100 * a.penumbra }
    rows_table[#rows_table + 1] = { string.format("%g", radius), tostring(K), string.format("%.2f", 100 * a.umbra),
                                    string.format("%.2f", 100 * a.ref_umbra), string.format("%.2f", 100 * a.penumbra),
                                    string.format("%.2f", 100 * a.ref_penumbra), string.format("%.4f", m.umbra.rmse),
                                    string.format("%.4f", m.penumbra.rmse) }
  end
  lab:close()
  local item = string.format("radius %g, best-fitting K = %d", radius, best.K)
  claims[#claims + 1] = { item = item, quantity = "umbra share, pcf / reference", paper = 1,
                          measured = best.a.umbra / best.a.ref_umbra,
                          rule = reproduce.above("'the resulting umbra is too large' (no figure): above 1"),
                          source = "course §4.1.2, Fig. 4.3" }
  claims[#claims + 1] = { item = item, quantity = "penumbra share, pcf / reference", paper = 1,
                          measured = best.a.penumbra / best.a.ref_penumbra,
                          rule = reproduce.below("'and the penumbra too small' (no figure): below 1"),
                          source = "course §4.1.2, Fig. 4.3" }
  local tag = string.format("radius %g", radius)
  umbra[#umbra + 1] = { title = "pcf, " .. tag, points = u, style = "linespoints" }
  umbra[#umbra + 1] = { title = "reference, " .. tag, style = "linespoints",
                        points = { { KERNELS[1], 100 * ref_area.ref_umbra }, { KERNELS[#KERNELS], 100 * ref_area.ref_umbra } } }
  penumbra[#penumbra + 1] = { title = "pcf, " .. tag, points = p, style = "linespoints" }
  penumbra[#penumbra + 1] = { title = "reference, " .. tag, style = "linespoints",
                              points = { { KERNELS[1], 100 * ref_area.ref_penumbra },
                                         { KERNELS[#KERNELS], 100 * ref_area.ref_penumbra } } }
end
page:plot("fig4.3-umbra", { title = "Umbra area against K", rows = runs, subtitle = "light radius 0.1 and 0.4",
                            xlabel = "K (texels)", ylabel = "% of light-facing samples", series = umbra })
page:plot("fig4.3-penumbra", { title = "Penumbra area against K", rows = runs, subtitle = "light radius 0.1 and 0.4",
                               xlabel = "K (texels)", ylabel = "% of light-facing samples", series = penumbra })
page:table({ "radius", "K", "umbra % (pcf)", "umbra % (ref)", "penumbra % (pcf)", "penumbra % (ref)", "umbra RMSE",
             "penumbra RMSE" }, rows_table)
page:text(reproduce.compare(claims, { out = result.out, title = "Course Fig. 4.3",
                                      note = "pcf (box, 1024^2), the K of lowest penumbra RMSE per light." }).html)
page:write()
