-- course-fig2.4-2.10-shadow-volumes.lua -- course §2.2, Figs. 2.4-2.10
-- measured: shadow volumes by z-pass (Heidmann 1991), z-fail (Carmack's
-- reverse, Bilodeau & Songy 1999) and ZP+ (Hornus et al. 2005).
--   1. Correctness: each method's disagreement with `hard` (the same
--      light-centre visibility by one ray per sample), camera outside every
--      volume and inside the ball's (Fig. 2.6: z-pass counts wrong once the
--      near plane cuts a volume; z-fail and ZP+ do not).
--   2. Cost: frame time (counts built + evaluation) against the possible
--      silhouette edges (the ball's tessellation, 24 ... 384 segments) and
--      the fill (fragments the camera-space counting pass counted), beside
--      `hard` and `sm`; on the bunny and terrain too when their models load.
--   3. Hornus et al. 2005 §6 (quoted by the course, §2.2): z-fail "up to 80%"
--      slower than z-pass, ZP+ "less than 10%" slower: the lab's ratios
--      (frame time, the same view, light and threads, alternating methods in
--      each round; the median over rounds) beside those bounds.
--   build/shadowlab run experiments/course-fig2.4-2.10-shadow-volumes.lua [--quick 1] [--rounds N]
--     [--out DIR] [--threads N] [--set KEY=VALUE ...]
-- --quick 1: 160x120, two tessellations, sphere-on-plane only (for tests).
-- Writes reports/course-fig2.4-2.10-shadow-volumes/ (or DIR): index.html,
-- cost.csv, agreement.csv and reproduction.{md,csv}.
local sl = require "shadowlab"
local reproduce = require "shadowlab.reproduce"
local experiment = require "shadowlab.experiment"
local records = require "shadowlab.records"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local args = experiment.parse_args(arg, {
  quick = { default = "0", help = "1: 160x120, two tessellations, sphere-on-plane only" },
  rounds = { default = "9", help = "alternating timed rounds per scene (the median is reported)" } })
if args.threads then sl.threads(args.threads) end
local quick = args.extra.quick == "1"

local METHODS = { "zpass", "zfail", "zpplus" }
local SEGMENTS = quick and { 24, 96 } or { 24, 48, 96, 192, 384 }
local ROUNDS = math.tointeger(tonumber(args.extra.rounds)) or error("--rounds expects an integer", 0)
local VIEW = quick and { ["camera.width"] = 160, ["camera.height"] = 120 }
                    or { ["camera.width"] = 480, ["camera.height"] = 360 }
for k, v in pairs(args.set) do VIEW[k] = v end
-- The camera under the ball on the axis from the light's centre through the
-- ball's centre, 0.79 from it: inside its shadow volume (the unit test's).
local INSIDE = { ["camera.position"] = { -0.27, 0.28, -0.18 }, ["camera.target"] = { 2, 0, 2 } }
local OUT = args.out or sl.root .. "/reports/course-fig2.4-2.10-shadow-volumes"

local function with(a, b)
  local m = {}
  for k, v in pairs(a) do m[k] = v end
  for k, v in pairs(b or {}) do m[k] = v end
  return m
end

local function render(lab, technique, params)
  return lab:compare{ technique = technique, params = params, samples = 16, png = false, exr = false, repeats = 1 }
end

-- Samples (lit candidates) where two visibility images differ, and those
-- `hard` shadows.
local function disagreement(run, hard_run)
  local v, h, c = run:image("visibility"), hard_run:image("visibility"), hard_run:image("class")
  local w, ht = c:size()
  local n, shadowed, differ = 0, 0, 0
  for y = 1, ht do
    for x = 1, w do
      if c:get(x, y) == 1 then
        n = n + 1
        local hv = h:get(x, y)
        if hv < 0.5 then shadowed = shadowed + 1 end
        if (v:get(x, y) < 0.5) ~= (hv < 0.5) then differ = differ + 1 end
      end
    end
  end
  return { candidates = n, shadowed = shadowed, differ = differ }
end

-- The counting pass's cost, as the shadow-volume resource logs it
-- (shadow_volume.c: silhouette edges, volume triangles, drawn, fragments).
local function fill_of(record)
  for _, e in ipairs(record.resources or {}) do
    if e.kind == "shadow_volume_counts" then
      local edges, tris, drawn, frags =
        e.desc:match("(%d+) silhouette edges, (%d+) volume triangles, (%d+) drawn, (%d+) fragments counted")
      if edges then return { edges = tonumber(edges), triangles = tonumber(tris), drawn = tonumber(drawn),
                             fragments = tonumber(frags) } end
    end
  end
  error("course-fig2.4-2.10: no shadow_volume_counts entry with its fill in the record")
end

local function median(t)
  local s = {}
  for i, v in ipairs(t) do s[i] = v end
  table.sort(s)
  local n = #s
  return n % 2 == 1 and s[(n + 1) / 2] or 0.5 * (s[n / 2] + s[n / 2 + 1])
end

---------------------------------------------------------------- 1. correctness

local agreement_rows, inside_share = {}, {}
for _, view in ipairs{ { "camera outside", {} }, { "camera inside the ball's volume", INSIDE } } do
  local lab = sl.open(sl.root .. "/scenes/sphere-on-plane.lua", with(VIEW, view[2]))
  local hard = render(lab, "hard")
  for _, m in ipairs(METHODS) do
    local d = disagreement(render(lab, "shadow_volume", { method = m }), hard)
    agreement_rows[#agreement_rows + 1] = { view[1], m, d.candidates, d.shadowed, d.differ, d.differ / d.candidates }
    if view[2] == INSIDE then inside_share[m] = d.differ / d.candidates end
  end
  lab:close()
end

---------------------------------------------------------------- 2. cost

local shown_records = {} -- the records the plots show (their scene, resolution, samples)

-- Frame time of every method in each round, the methods alternating after
-- one untimed warm-up render each, so load drifts hit all alike.
local function time_methods(lab)
  local runs = { { "hard" }, { "sm" } }
  for _, m in ipairs(METHODS) do runs[#runs + 1] = { "shadow_volume", { method = m }, m } end
  local times, fill = {}, nil
  for _, r in ipairs(runs) do render(lab, r[1], r[2]); times[r[3] or r[1]] = {} end
  for _ = 1, ROUNDS do
    for _, r in ipairs(runs) do
      local rec = render(lab, r[1], r[2]):record()
      local t = times[r[3] or r[1]]
      t[#t + 1] = rec.timings_s.frame
      if r[3] == "zpass" then fill = fill_of(rec); shown_records[#shown_records + 1] = rec end
    end
  end
  local med = {}
  for k, t in pairs(times) do med[k] = median(t) end
  return med, fill
end

local variants = {}
for _, seg in ipairs(SEGMENTS) do
  variants[#variants + 1] = { label = string.format("sphere-on-plane, %d segments", seg),
                              scene = "scenes/sphere-on-plane.lua", overrides = { ["objects[2].segments"] = seg } }
end
if not quick then
  variants[#variants + 1] = { label = "sphere-on-plane, camera inside", scene = "scenes/sphere-on-plane.lua",
                              overrides = INSIDE }
  variants[#variants + 1] = { label = "bunny", scene = "scenes/bunny.lua", overrides = {} }
  variants[#variants + 1] = { label = "terrain", scene = "scenes/terrain.lua", overrides = {} }
end

local cost_rows, ratios = {}, { zfail = {}, zpplus = {} }
local edges_series, fill_series = {}, {}
for _, m in ipairs(METHODS) do edges_series[m] = {}; fill_series[m] = {} end
for _, v in ipairs(variants) do
  local ok, lab = pcall(sl.open, sl.root .. "/" .. v.scene, with(VIEW, v.overrides))
  if not ok then
    print(string.format("course-fig2.4-2.10: %s left out: %s", v.label, tostring(lab)))
  else
    local med, fill = time_methods(lab)
    lab:close()
    local rz, rp = med.zfail / med.zpass, med.zpplus / med.zpass
    ratios.zfail[#ratios.zfail + 1] = { v.label, rz }
    ratios.zpplus[#ratios.zpplus + 1] = { v.label, rp }
    cost_rows[#cost_rows + 1] = { v.label, fill.edges, fill.triangles, fill.fragments, 1e3 * med.hard, 1e3 * med.sm,
                                  1e3 * med.zpass, 1e3 * med.zfail, 1e3 * med.zpplus, rz, rp }
    if v.overrides["objects[2].segments"] then
      for _, m in ipairs(METHODS) do
        local e, f = edges_series[m], fill_series[m]
        e[#e + 1] = { fill.edges, 1e3 * med[m] }
        f[#f + 1] = { fill.fragments, 1e3 * med[m] }
      end
    end
  end
end

---------------------------------------------------------------- 3. the claims

local function worst(list)
  local w
  for _, r in ipairs(list) do if not w or r[2] > w[2] then w = r end end
  return w
end
local claims = {}
local wz, wp = worst(ratios.zfail), worst(ratios.zpplus)
claims[#claims + 1] = { item = "z-fail / z-pass, slowest of the scenes (" .. wz[1] .. ")",
                        quantity = "frame time ratio", paper = 1.8, measured = wz[2],
                        rule = reproduce.below("z-fail 'up to 80% slower' than z-pass"),
                        source = "Hornus et al. 2005 §6, course §2.2" }
claims[#claims + 1] = { item = "ZP+ / z-pass, slowest of the scenes (" .. wp[1] .. ")",
                        quantity = "frame time ratio", paper = 1.1, measured = wp[2],
                        rule = reproduce.below("ZP+ 'less than 10% slower' than z-pass"),
                        source = "Hornus et al. 2005 §6, course §2.2" }
claims[#claims + 1] = { item = "z-pass, camera inside a volume", quantity = "share of samples wrong", paper = 0.1,
                        measured = inside_share.zpass,
                        rule = reproduce.above("z-pass fails once the near plane clips a volume (Fig. 2.6): a share, not a rim"),
                        source = "course §2.2, Fig. 2.6" }
for _, m in ipairs{ "zfail", "zpplus" } do
  claims[#claims + 1] = { item = m .. ", camera inside a volume", quantity = "share of samples wrong", paper = 0.01,
                          measured = inside_share[m],
                          rule = reproduce.below("correct inside a volume (Figs. 2.7-2.10): at most a rim at faces"),
                          source = "course §2.2, Figs. 2.7-2.10" }
end

---------------------------------------------------------------- the report

local page = figures.page(OUT, "Course Figs. 2.4-2.10: z-pass, z-fail and ZP+ shadow volumes",
  string.format("Disagreement with `hard` (one ray to the light's centre) and frame time (median of %d alternating " ..
                "rounds, %s threads) against silhouette edges and fill, %dx%d.", ROUNDS, tostring(sl.machine().threads),
                VIEW["camera.width"], VIEW["camera.height"]))
page:table({ "view", "method", "lit candidates", "shadowed (hard)", "disagree", "share" }, (function()
  local t = {}
  for i, r in ipairs(agreement_rows) do t[i] = { r[1], r[2], tostring(r[3]), tostring(r[4]), tostring(r[5]),
                                                 string.format("%.4f", r[6]) } end
  return t
end)())
local shown = {}
for i, r in ipairs(cost_rows) do
  shown[i] = { r[1], tostring(r[2]), tostring(r[3]), tostring(r[4]) }
  for k = 5, 9 do shown[i][k] = string.format("%.3f", r[k]) end
  shown[i][10], shown[i][11] = string.format("%.3f", r[10]), string.format("%.3f", r[11])
end
page:table({ "scene", "silhouette edges", "volume triangles", "fragments (z-pass)", "hard ms", "sm ms", "z-pass ms",
             "z-fail ms", "ZP+ ms", "z-fail / z-pass", "ZP+ / z-pass" }, shown)
local function series(by)
  local s = {}
  for _, m in ipairs(METHODS) do s[#s + 1] = { title = m, points = by[m], style = "linespoints" } end
  return s
end
page:plot("cost-edges", { title = "Frame time against silhouette edges", subtitle = "sphere-on-plane, 24 ... 384 segments",
                          xlabel = "possible silhouette edges", ylabel = "frame ms", series = series(edges_series),
                          rows = shown_records })
page:plot("cost-fill", { title = "Frame time against fill", subtitle = "fragments the z-pass count touched",
                         xlabel = "fragments counted", ylabel = "frame ms", series = series(fill_series),
                         rows = shown_records })
local rep = reproduce.compare(claims, { out = OUT, title = "Course Figs. 2.4-2.10 and Hornus et al. 2005",
                                        note = "frame time ratios are medians over alternating rounds in one run" })
page:text(rep.html)
page:write()

records.write_table(OUT .. "/agreement.csv", { "view", "method", "lit_candidates", "shadowed_hard", "disagree",
                                              "share" }, agreement_rows)
records.write_table(OUT .. "/cost.csv", { "scene", "silhouette_edges", "volume_triangles", "fragments_zpass", "hard_ms",
                                         "sm_ms", "zpass_ms", "zfail_ms", "zpplus_ms", "zfail_over_zpass",
                                         "zpplus_over_zpass" }, cost_rows)
