-- soft-failures.lua -- where single-map soft shadows fail, measured for every
-- registered soft technique (the registry's family "soft", those added later
-- included) at its defaults, against the Embree reference:
--   (a) occluder fusion, course §1 Fig. 1.6, Eq. 1.5, Figs. 1.7 and 5.19:
--       scenes/fusion-separate.lua, fusion-overlap.lua, fusion-hidden.lua.
--       Each occluder's own reference (the other one's caster flag off: same
--       view samples) gives the sum, product and max combinations
--       (lua/shadowlab/fusion.lua); each technique's signed error against the
--       truth and the combination it is nearest to by RMSE over the region
--       where truth or any combination is in penumbra;
--   (b) the planar-occluder assumption, course §5.2.2.1, Figs. 5.3 and 5.4
--       (scenes/planar-occluder.lua): the worst shading at a lit point (course:
--       25%), the worst visibility at an umbra point (course: 50%) and the
--       penumbra's area over the reference's (course: too wide);
--   (c) penumbra width against light size, course §5.1 Fig. 5.1
--       (scenes/parallel-planes.lua, square light of half side r): against the
--       closed form W = w_light (d_r - d_o) / d_o, and the umbra's loss;
--   (d) one depth layer against the complete geometry, course §1 Fig. 1.8
--       (scenes/one-layer.lua): the share of a box's shadow, hidden from the
--       light's centre under a slab, that each technique recovers.
--   build/shadowlab run experiments/soft-failures.lua [--mode quick|full]
--       [--family soft[,geometry]] [--techniques a,b] [--samples N] [--out DIR]
-- quick (the default): the scenes' 160 x 120, 64 reference samples, r in
-- {0.03, 0.1, 0.3, 1}; full: 320 x 240, 256 samples, r in {0.01, 0.03, 0.1,
-- 0.3, 1}. Writes reports/soft-failures/: failures.csv (one row per technique
-- and case), failures.md (technique x case: signed error, classified),
-- combinations.md (truth against each combination) and reproduction.{md,csv}
-- (course value, measured, ratio, verdict).
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"
local reproduce = require "shadowlab.reproduce"
local fusion = require "shadowlab.fusion"
local scenefile = require "shadowlab.scenefile"

local args = experiment.parse_args(arg, {
  mode = { default = "quick", help = "quick (160 x 120, 64 samples, 4 light sizes) or full (320 x 240, 256, 5)" },
  family = { default = "soft", help = "comma-separated registry families to run (soft; geometry adds the shadow volumes)" },
  techniques = { default = "all", help = "comma-separated techniques of those families (all: every one)" },
})
local MODES = {
  quick = { width = 160, height = 120, samples = 64, radii = { 0.03, 0.1, 0.3, 1 } },
  full = { width = 320, height = 240, samples = 256, radii = { 0.01, 0.03, 0.1, 0.3, 1 } },
}
local mode = MODES[args.extra.mode]
if not mode then
  io.stderr:write("error: --mode must be quick or full, got '", tostring(args.extra.mode), "'\n")
  os.exit(2)
end
local SAMPLES = args.samples or mode.samples
local VIEW = { ["camera.width"] = mode.width, ["camera.height"] = mode.height }
for k, v in pairs(args.set) do VIEW[k] = v end
if args.threads then sl.threads(args.threads) end
local OUT = args.out or "reports/soft-failures"
local LIGHT = "rect" -- every scene here has one square rect light: the type each technique must handle
local quiet = args.quiet

local families, chosen = {}, experiment.technique_set(args.extra.techniques)
for f in args.extra.family:gmatch("[^,%s]+") do families[f] = true end
local TECHNIQUES = {}
for _, t in ipairs(sl.techniques()) do
  if families[t.family] and (chosen.all or chosen[t.name]) and experiment.handles(t, LIGHT) then
    TECHNIQUES[#TECHNIQUES + 1] = t.name
  end
end
if #TECHNIQUES == 0 then error("soft-failures: no registered technique of family " .. args.extra.family ..
                               " handles " .. LIGHT .. " lights", 0) end

local FIXED = experiment.fixed_params(args.params, TECHNIQUES) -- --param: e.g. map_size=256 in the tests

local function log(...) if not quiet then io.stderr:write(string.format(...), "\n") end end
local function finite(x) return type(x) == "number" and x == x and x ~= math.huge and x ~= -math.huge end
local function scene_path(name) return sl.root .. "/scenes/" .. name .. ".lua" end
local function with(base, extra)
  local t = {}
  for k, v in pairs(base) do t[k] = v end
  for k, v in pairs(extra or {}) do t[k] = v end
  return t
end

-- A run's image as one flat array in pixel order: each lit candidate's value
-- (class 1, the samples the metrics score), false at every other sample.
local function pixels(run, field)
  local img, cls = run:image(field), run:image("class")
  local w, h = img:size()
  local out = {}
  for y = 1, h do
    for x = 1, w do
      out[#out + 1] = cls:get(x, y) == 1 and img:get(x, y)
    end
  end
  return out
end

local function reference(lab)
  return pixels(lab:reference{ samples = SAMPLES, png = false, exr = false }, "reference")
end

local function estimate(lab, technique)
  local run = lab:compare{ technique = technique, params = FIXED[technique], samples = SAMPLES, png = false,
                           exr = false }
  return pixels(run, "visibility")
end

local rows = {}   -- failures.csv: technique, case, quantity, value, class
local cells = {}  -- failures.md: cells[technique][case] = text
local claims = {} -- reproduction rows
local function cell(t, case, text) cells[t] = cells[t] or {}; cells[t][case] = text end
local function row(t, case, quantity, value, class)
  rows[#rows + 1] = { t, case, quantity, value, class or "" }
end

---------------------------------------------------------------- (a) fusion

-- Each scene's occluders are objects[2] and objects[3] (objects[1]: the ground).
local FUSION = {
  { scene = "fusion-separate", expect = "sum", why = "disjoint projections: the occlusions add" },
  { scene = "fusion-overlap", expect = "product", why = "partial overlap: a multiplication is closer" },
  { scene = "fusion-hidden", expect = "max", why = "one hidden behind the other: the maximum" },
}
local combo_md = { "| scene | samples | RMSE sum | RMSE product | RMSE max | nearest rule | course (Fig. 1.6) |",
                   "|---|---:|---:|---:|---:|---|---|" }

local function fusion_case(case)
  local path = scene_path(case.scene)
  local both = sl.open(path, VIEW)
  local v1 = reference(sl.open(path, with(VIEW, { ["objects[3].caster"] = false })))
  local v2 = reference(sl.open(path, with(VIEW, { ["objects[2].caster"] = false })))
  local truth = reference(both)
  local samples, where = {}, {}
  for i, t in ipairs(truth) do
    if t and fusion.in_region(v1[i], v2[i]) then
      local c = fusion.combine(v1[i], v2[i])
      samples[#samples + 1] = { truth = t, sum = c.sum, product = c.product, max = c.max }
      where[#where + 1] = i
    end
  end
  -- The truth itself against the rules: which one the scene is an example of.
  local rules = {}
  for i, s in ipairs(samples) do rules[i] = with(s, { estimate = s.truth }) end
  local _, rmse = fusion.classify(rules)
  local nearest, other
  for _, k in ipairs({ "sum", "product", "max" }) do
    if not nearest or rmse[k] < rmse[nearest] then nearest = k end
  end
  for _, k in ipairs({ "sum", "product", "max" }) do
    if k ~= case.expect and (not other or rmse[k] < other) then other = rmse[k] end
  end
  combo_md[#combo_md + 1] = string.format("| %s | %d | %.4f | %.4f | %.4f | %s | %s |", case.scene, #samples, rmse.sum,
                                          rmse.product, rmse.max, nearest, case.expect)
  claims[#claims + 1] = { item = case.scene .. ": the reference against the rule " .. case.expect,
                          quantity = "RMSE to " .. case.expect .. " / RMSE to the nearest other rule",
                          paper = 1, measured = rmse[case.expect] / other,
                          rule = reproduce.below("Fig. 1.6 names the rule closest to the truth (" .. case.why ..
                                                 "): below 1"),
                          source = "course §1, Fig. 1.6, Eq. 1.5" }
  for _, t in ipairs(TECHNIQUES) do
    local est = estimate(both, t)
    local scored, nonfinite = {}, 0
    for j, i in ipairs(where) do
      if finite(est[i]) then scored[#scored + 1] = with(samples[j], { estimate = est[i] })
      else nonfinite = nonfinite + 1 end
    end
    local label, r, n, bias = fusion.classify(scored)
    row(t, case.scene, "signed error (penumbra mean)", bias, label)
    row(t, case.scene, "RMSE to truth", r.truth, label)
    for _, k in ipairs({ "sum", "product", "max" }) do row(t, case.scene, "RMSE to " .. k, r[k], label) end
    if nonfinite > 0 then row(t, case.scene, "non-finite estimates (left out)", nonfinite) end
    cell(t, case.scene, string.format("%+.3f, %s%s", bias, label, nonfinite > 0 and " (" .. nonfinite .. " NaN)" or ""))
    log("%-18s %-16s n %5d  signed %+.4f  rmse truth %.4f sum %.4f product %.4f max %.4f  -> %s", t, case.scene, n,
        bias, r.truth, r.sum, r.product, r.max, label)
  end
  both:close()
end

---------------------------------------------------------------- (b) planar occluder

local function planar_case()
  local lab = sl.open(scene_path("planar-occluder"), VIEW)
  local ref = reference(lab)
  for _, t in ipairs(TECHNIQUES) do
    local est = estimate(lab, t)
    -- worst shading (1 - V) at a fully lit point, worst visibility at an
    -- umbra point (reference within 0.001 of 1 or 0), penumbra areas (0.01 < V < 0.99).
    local lit_worst, umbra_worst, lit_n, umbra_n, pen, pen_ref = 0, 0, 0, 0, 0, 0
    for i, r in ipairs(ref) do
      local v = est[i]
      if r and finite(v) then
        if r >= 0.999 then lit_n = lit_n + 1; if 1 - v > lit_worst then lit_worst = 1 - v end end
        if r <= 0.001 then umbra_n = umbra_n + 1; if v > umbra_worst then umbra_worst = v end end
        if v > 0.01 and v < 0.99 then pen = pen + 1 end
        if r > 0.01 and r < 0.99 then pen_ref = pen_ref + 1 end
      end
    end
    local ratio = pen_ref > 0 and pen / pen_ref or 0 / 0
    row(t, "planar-occluder", "worst shading at a lit point", lit_worst)
    row(t, "planar-occluder", "worst visibility at an umbra point", umbra_worst)
    row(t, "planar-occluder", "penumbra area / reference's", ratio)
    cell(t, "planar-occluder", string.format("lit %.2f, umbra %.2f, width x%.2f", lit_worst, umbra_worst, ratio))
    log("%-18s planar-occluder   lit %.3f (%d)  umbra %.3f (%d)  penumbra x%.3f", t, lit_worst, lit_n, umbra_worst,
        umbra_n, ratio)
    if t == "pcss" then
      local SCHEMATIC = reproduce.factor(2, "Fig. 5.3's values count 1 or 2 of 4 filter samples in a schematic; " ..
                                            "a scene can agree in size only")
      claims[#claims + 1] = { item = "pcss: worst lit point", quantity = "shading (1 - V)", paper = 0.25,
                              measured = lit_worst, rule = SCHEMATIC, source = "course §5.2.2.1, Fig. 5.3 (left)" }
      claims[#claims + 1] = { item = "pcss: worst umbra point", quantity = "visibility", paper = 0.5,
                              measured = umbra_worst, rule = SCHEMATIC, source = "course §5.2.2.1, Fig. 5.3 (right)" }
      claims[#claims + 1] = { item = "pcss: penumbra", quantity = "area / reference's", paper = 1, measured = ratio,
                              rule = reproduce.above("'too large penumbrae': above 1"),
                              source = "course §5.2.2.1, Fig. 5.4" }
    end
  end
  lab:close()
end

---------------------------------------------------------------- (c) parallel planes

-- The scene's geometry, read from the file itself: ground at
-- y = 0, the plate objects[2] and the light lights[1] straight above it, the
-- camera looking straight down from between them (vertical fov), so every
-- pixel covers side^2 of ground, side = 2 D tan(fov / 2) / height (D: the
-- camera's height, the view's height in pixels as the lab opened it).
local function parallel_geometry()
  local s = scenefile.load(scene_path("parallel-planes"))
  local light_y, plate_y = s.lights[1].position[2], s.objects[2].translate[2]
  local d_r, d_o = light_y, light_y - plate_y -- distances from the light (world units)
  return { d_r = d_r, d_o = d_o, s = s.objects[2].size[1], camera_height = s.camera.position[2],
           tan_half_fov = math.tan(math.rad(s.camera.fov) / 2) }
end

-- Penumbra width from the penumbra's area: with a square light, a square
-- occluder and the receiver parallel and aligned, the shadow's outer edge is
-- a square of side a + W and the umbra's a - W (a = s d_r / d_o, the
-- occluder's shadow), so the penumbra covers (a + W)^2 - (a - W)^2 = 4 a W
-- [OWN, from course Fig. 5.1's similar triangles], for W <= a.
local function penumbra_width(area, a) return area / (4 * a) end

local function parallel_case()
  local g = parallel_geometry()
  local a = g.s * g.d_r / g.d_o
  local width_cells = {}
  for _, r in ipairs(mode.radii) do
    local w_light = 2 * r
    -- course §5.1, Fig. 5.1: W = w_light (d_r - d_o) / d_o (parallel planes)
    local W = w_light * (g.d_r - g.d_o) / g.d_o
    local umbra_closed = W < a and (a - W) * (a - W) or 0
    local lab = sl.open(scene_path("parallel-planes"), with(VIEW, { ["lights[1].width"] = w_light,
                                                                    ["lights[1].height"] = w_light }))
    g.pixel = 2 * g.camera_height * g.tan_half_fov / lab:info().height -- world units
    g.pixel_area = g.pixel * g.pixel
    local function measure(vals)
      local pen, umbra = 0, 0
      for _, v in ipairs(vals) do
        if v and finite(v) then
          if v <= 0.01 then umbra = umbra + 1 elseif v < 0.99 then pen = pen + 1 end
        end
      end
      return penumbra_width(pen * g.pixel_area, a), umbra * g.pixel_area
    end
    local W_ref, U_ref = measure(reference(lab))
    row("reference", "parallel r=" .. r, "penumbra width / closed form", W_ref / W)
    -- Judged where the penumbra spans 4 pixels or more: below, the pixel grid decides the measured width.
    local judged = W >= 4 * g.pixel
    if judged then claims[#claims + 1] = { item = string.format("reference, r = %g", r), quantity = "penumbra width",
                            unit = "world units", paper = W, measured = W_ref,
                            rule = reproduce.within(0.25, string.format("the 1%% and 99%% thresholds trim 2%% of " ..
                              "the ramp; a pixel is %.3g wide", g.pixel)),
                            source = "course §5.1, Fig. 5.1 (closed form)" } end
    for _, t in ipairs(TECHNIQUES) do
      local Wt, Ut = measure(estimate(lab, t))
      local umbra_ratio = umbra_closed > 0 and Ut / umbra_closed or 0 / 0
      row(t, "parallel r=" .. r, "penumbra width / closed form", Wt / W)
      row(t, "parallel r=" .. r, "umbra area / closed form", umbra_ratio)
      width_cells[t] = (width_cells[t] and width_cells[t] .. ", " or "") .. string.format("x%.2f", Wt / W)
      cell(t, "umbra", (cells[t] and cells[t].umbra and cells[t].umbra .. ", " or "") ..
                       (umbra_ratio == umbra_ratio and string.format("x%.2f", umbra_ratio) or "-"))
      log("%-18s parallel r=%-5g W %.4f (closed %.4f, ref %.4f)  umbra %.4f (closed %.4f, ref %.4f)", t, r, Wt, W,
          W_ref, Ut, umbra_closed, U_ref)
      if judged and r == 0.3 then
        claims[#claims + 1] = { item = string.format("%s, r = %g", t, r), quantity = "penumbra width",
                                unit = "world units", paper = W, measured = Wt,
                                rule = reproduce.within(0.25, "as the reference's"),
                                source = "course §5.1, Fig. 5.1 (closed form)" }
      end
    end
    lab:close()
  end
  for t, text in pairs(width_cells) do cell(t, "width", text) end
end

---------------------------------------------------------------- (d) one layer

local function one_layer_case()
  local path = scene_path("one-layer")
  local lab = sl.open(path, VIEW)
  local truth = reference(lab)
  local slab_only = reference(sl.open(path, with(VIEW, { ["objects[3].caster"] = false })))
  -- The box's own shadow: where it changes the truth by more than 0.02.
  local where, box_shadow = {}, 0
  for i, t in ipairs(truth) do
    if t and slab_only[i] - t > 0.02 then where[#where + 1] = i; box_shadow = box_shadow + (slab_only[i] - t) end
  end
  for _, t in ipairs(TECHNIQUES) do
    local est = estimate(lab, t)
    -- recovered: the technique's darkening against the slab alone, over the
    -- box's (1: the complete geometry; 0: one depth layer, the box missed).
    local darkening, bias, n = 0, 0, 0
    for _, i in ipairs(where) do
      if finite(est[i]) then
        darkening = darkening + (slab_only[i] - est[i])
        bias = bias + (est[i] - truth[i])
        n = n + 1
      end
    end
    local recovered = box_shadow > 0 and darkening / box_shadow or 0 / 0
    local label = recovered ~= recovered and "-" or recovered < 0.25 and "one layer" or
                  math.abs(recovered - 1) <= 0.25 and "complete" or recovered > 1.25 and "too dark" or "partial"
    bias = n > 0 and bias / n or 0 / 0
    row(t, "one-layer", "signed error (box shadow mean)", bias, label)
    row(t, "one-layer", "box shadow recovered", recovered, label)
    cell(t, "one-layer", string.format("%+.3f, %s (%.2f)", bias, label, recovered))
    log("%-18s one-layer         samples %d  signed %+.4f  recovered %.3f -> %s", t, #where, bias, recovered, label)
  end
  lab:close()
end

---------------------------------------------------------------- run and write

-- The 1-minute load average (Linux), stated beside the run time.
local function load_average()
  local f = io.open("/proc/loadavg")
  local text = f and f:read("l")
  if f then f:close() end
  return text and text:match("^(%S+)") or "?"
end

local load_before, t0 = load_average(), sl.now()
for _, case in ipairs(FUSION) do fusion_case(case) end
planar_case()
parallel_case()
one_layer_case()
local seconds = sl.now() - t0

sl.mkdir(OUT)
local function csv_field(v)
  v = type(v) == "number" and (v == v and string.format("%.6g", v) or "nan") or tostring(v)
  return v:find('[,"\n]') and '"' .. v:gsub('"', '""') .. '"' or v
end
local csv = { "technique,case,quantity,value,class" }
for _, r in ipairs(rows) do
  local f = {}
  for i, v in ipairs(r) do f[i] = csv_field(v) end
  csv[#csv + 1] = table.concat(f, ",")
end
sl.write_file(OUT .. "/failures.csv", table.concat(csv, "\n") .. "\n")

local radii = {}
for i, r in ipairs(mode.radii) do radii[i] = string.format("%g", r) end
local setting = string.format("%dx%d view, %d r2 reference samples, techniques at their defaults, %.0f s on %s " ..
                              "(load %s before, %s after)", VIEW["camera.width"], VIEW["camera.height"], SAMPLES,
                              seconds, sl.machine().cpu or "?", load_before, load_average())
local md = { "# Soft-shadow failure cases, every soft technique", "", setting .. ".", "",
  "Fusion cells: signed error against the truth (mean over the fusion region: the samples each occluder " ..
  "alone leaves in penumbra, where the rules differ; negative: too dark), then the combination the technique's " ..
  "answer is nearest to by RMSE there " ..
  "(`a=b`: within 10% + 0.005 of each other). Planar occluder: the worst shading at a lit point (course Fig. 5.3: " ..
  "0.25), the worst visibility at an umbra point (0.5) and the penumbra's area over the reference's " ..
  "(Fig. 5.4: above 1). Width: penumbra width over the closed form W = w_light (d_r - d_o) / d_o at r = " ..
  table.concat(radii, ", ") .. " (Fig. 5.1); umbra: umbra area over the closed form (a - W)^2 at the same r " ..
  "('-': none left). One layer: signed error over the hidden box's shadow, and the share of it recovered " ..
  "(Fig. 1.8; below 0.25: one layer; 0.75 to 1.25: complete; above: too dark; else partial).", "",
  "| technique | fusion: separate | fusion: overlap | fusion: hidden | planar occluder | width (r = " ..
  table.concat(radii, ", ") .. ") | umbra | one layer |", "|---|---|---|---|---|---|---|---|" }
for _, t in ipairs(TECHNIQUES) do
  local c = cells[t] or {}
  md[#md + 1] = string.format("| %s | %s | %s | %s | %s | %s | %s | %s |", t, c["fusion-separate"] or "-",
                              c["fusion-overlap"] or "-", c["fusion-hidden"] or "-", c["planar-occluder"] or "-",
                              c.width or "-", c.umbra or "-", c["one-layer"] or "-")
end
sl.write_file(OUT .. "/failures.md", table.concat(md, "\n") .. "\n")
sl.write_file(OUT .. "/combinations.md", "# Occluder fusion: the reference against each combination\n\n" ..
              "RMSE of the sum, product and max of the two occluders' own references against the reference " ..
              "with both, over the samples each occluder alone leaves in penumbra (" .. setting .. ").\n\n" ..
              table.concat(combo_md, "\n") .. "\n")
if not quiet then io.stdout:write(table.concat(md, "\n"), "\n\n", table.concat(combo_md, "\n"), "\n") end
reproduce.compare(claims, { out = OUT, title = "Soft-shadow failure cases (course Figs. 1.6, 5.1, 5.3, 5.4)",
                            note = setting .. "; the reference's own noise enters each combination." })
log("soft-failures: %s/failures.md, failures.csv, combinations.md, reproduction.md (%.0f s)", OUT, seconds)
