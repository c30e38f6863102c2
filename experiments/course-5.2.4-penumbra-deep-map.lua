-- course-5.2.4-penumbra-deep-map.lua -- course §5.2.4 on penumbra deep
-- shadow maps (St-Amour, Paquette & Poulin 2005; src/techniques/
-- penumbra_deep_map.c): "rendering is real-time, but the build is
-- 'interactive rates, at best', so static scenes only". On sphere-on-plane,
-- penumbra_deep_map's build (the deep map's own build time and bytes, net of
-- the N sample maps it reads) against the light samples N and the
-- compression bound `error`, its lookup time, and its penumbra RMSE against
-- the Embree reference beside light_sampling and layered_attenuation with
-- the same N maps. The course's statement is printed beside the measured
-- build and lookup times with their ratio and verdict; timings are ratios
-- within this one run (state the machine's load beside them).
--   build/shadowlab run experiments/course-5.2.4-penumbra-deep-map.lua [--map-size N] [--set camera.width=W] ...
-- Writes reports/course-5.2.4-penumbra-deep-map/: figure.html, builds.csv
-- and reproduction.{md,csv}.
local sl = require "shadowlab"
local reproduce = require "shadowlab.reproduce"
local experiment = require "shadowlab.experiment"
local records = require "shadowlab.records"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local args = experiment.parse_args(arg, {
  ["map-size"] = { default = "256", help = "map_size of every technique's maps (texels a side)" } })
if args.threads then sl.threads(args.threads) end
local MAP_SIZE = math.tointeger(tonumber(args.extra["map-size"]))
if not MAP_SIZE or MAP_SIZE < 16 or MAP_SIZE > 2048 then
  io.stderr:write("course-5.2.4-penumbra-deep-map: --map-size expects an integer in [16, 2048], got " ..
                  tostring(args.extra["map-size"]) .. "\n")
  os.exit(2)
end
local SAMPLES = args.samples or 64
local NS = { 4, 8, 16 }                   -- light samples (the build's N)
local ERRORS = { 0, 0.02, 0.05, 0.1, 0.2 } -- the compression bound, at N = 16
local VIEW = { ["camera.width"] = 160, ["camera.height"] = 120 }
for k, v in pairs(args.set) do VIEW[k] = v end
local OUT = args.out or sl.root .. "/reports/course-5.2.4-penumbra-deep-map"

local lab = sl.open(sl.root .. "/scenes/sphere-on-plane.lua", VIEW)
local function run(technique, params)
  params.map_size = MAP_SIZE
  return lab:compare({ technique = technique, params = params, samples = SAMPLES, png = false, exr = false }):record()
end
-- The deep map's own build in a record (seconds, bytes, texels read: net of the sample maps it reads).
local function deep_build(rec)
  for _, r in ipairs(rec.resources) do
    if r.kind == "penumbra_deep_map" then return r.own_build_s, r.bytes, r.work.texel_fetches end
  end
  return 0 / 0, 0 / 0, 0 / 0
end

local rows = {}
local CSV_HEADER = { "n", "error", "build_s", "bytes", "build_texel_reads", "vertices_mean", "lookup_s",
                     "penumbra_rmse" }
local function measure(n, err)
  local rec = run("penumbra_deep_map", { samples = n, error = err, max_vertices = 256 })
  local build_s, bytes, fetches = deep_build(rec)
  local r = { n = n, err = err, build_s = build_s, bytes = bytes, fetches = fetches, vertices = rec.aux.vertices.mean,
              lookup_s = rec.timings_s.evaluate_median, rmse = rec.metrics.penumbra.rmse }
  rows[#rows + 1] = r
  return r
end
local by_n, by_err = {}, {}
for _, n in ipairs(NS) do by_n[n] = measure(n, 0.05) end
for _, e in ipairs(ERRORS) do by_err[e] = e == 0.05 and by_n[16] or measure(16, e) end
local ls = run("light_sampling", { samples = 16 })
local la = run("layered_attenuation", { samples = 16, epsilon = 0.2 })
lab:close()

local base = by_n[16]
local claims = {
  { item = "lookup / build of the deep map (N = 16)", quantity = "time ratio", paper = 1,
    measured = base.build_s > 0 and base.lookup_s / base.build_s or nil,
    rule = reproduce.below("'rendering is real-time, but the build is interactive rates, at best': a frame's " ..
                           "lookups cost less than one build"),
    source = "course §5.2.4" },
  { item = "build N = 16 / N = 4", quantity = "texels read ratio", paper = 4,
    measured = by_n[4].fetches > 0 and base.fetches / by_n[4].fetches or nil,
    rule = reproduce.factor(2, "every centre texel marches every sample's map: linear in N"),
    source = "course §5.2.4; penumbra_deep_map.c" },
  { item = "bytes at error 0.2 / error 0", quantity = "memory ratio", paper = 1,
    measured = by_err[0].bytes > 0 and by_err[0.2].bytes / by_err[0].bytes or nil,
    rule = reproduce.below("compression within an error bound (St-Amour et al. 2005 §4; Lokovic & Veach 2000): " ..
                           "fewer vertices as the bound grows"),
    source = "course §5.2.4" },
  { item = "penumbra RMSE: penumbra_deep_map (error 0) / light_sampling", quantity = "RMSE ratio", paper = 1,
    measured = ls.metrics.penumbra.rmse > 0 and by_err[0].rmse / ls.metrics.penumbra.rmse or nil,
    rule = reproduce.factor(1.3, "the same N depth tests, sampled on the centre's texel rays"),
    source = "course §5.2.4" },
}

local table_rows = {}
for _, r in ipairs(rows) do
  table_rows[#table_rows + 1] = { tostring(r.n), string.format("%g", r.err), string.format("%.3f", r.build_s),
                                  string.format("%.2f", r.bytes / 2 ^ 20), string.format("%.1f", r.vertices),
                                  string.format("%.4f", r.lookup_s), string.format("%.4f", r.rmse) }
end
print(string.format("course §5.2.4: 'rendering is real-time, but the build is interactive rates, at best'; measured " ..
                    "(N = 16, %d^2): build %.3f s, lookup %.4f s, build / lookup x%.0f: %s", MAP_SIZE, base.build_s,
                    base.lookup_s, base.build_s / base.lookup_s,
                    base.lookup_s < base.build_s and "holds" or "does not hold"))
print(string.format("build against N (error 0.05): %s", table.concat((function()
  local t = {}
  for _, n in ipairs(NS) do
    t[#t + 1] = string.format("N = %d %.3f s, %.0f texels read", n, by_n[n].build_s, by_n[n].fetches)
  end
  return t
end)(), "; ")))
print(string.format("penumbra RMSE (N = 16): penumbra_deep_map %.4f (error 0.05), %.4f (error 0), light_sampling " ..
                    "%.4f, layered_attenuation %.4f", base.rmse, by_err[0].rmse, ls.metrics.penumbra.rmse,
                    la.metrics.penumbra.rmse))

sl.mkdir(OUT)
local csv_rows = {}
for _, r in ipairs(rows) do
  csv_rows[#csv_rows + 1] = { r.n, r.err, r.build_s, r.bytes, r.fetches, r.vertices, r.lookup_s, r.rmse }
end
records.write_table(OUT .. "/builds.csv", CSV_HEADER, csv_rows)
local page = figures.page(OUT, "Course §5.2.4: penumbra deep shadow maps, build against lookup",
  string.format("sphere-on-plane, maps of %d^2: the deep map's own build (net of the N sample maps) and bytes " ..
                "against N and error, its lookup (one evaluation) and penumbra RMSE against the reference (%d " ..
                "samples); light_sampling %.4f, layered_attenuation %.4f (N = 16).", MAP_SIZE, SAMPLES,
                ls.metrics.penumbra.rmse, la.metrics.penumbra.rmse))
page:table({ "N", "error", "build (s)", "MiB", "vertices per receiver texel", "lookup (s)", "penumbra RMSE" },
           table_rows)
page:text(reproduce.compare(claims, { out = OUT, title = "Course §5.2.4 penumbra deep shadow maps",
  note = string.format("penumbra_deep_map, maps of %d^2, %sx%s, %d reference samples", MAP_SIZE,
                       tostring(VIEW["camera.width"]), tostring(VIEW["camera.height"]), SAMPLES) }).html)
page:write()
