-- lab-aliasing.lua -- the teaching lab of course ch. 3 (shadow-map aliasing):
-- set the knobs, read the error maps, the error along the view, the storage
-- factor and the misclassification against the ray-traced truth, with one
-- knob swept so the numbers move side by side. Run:
--   build/shadowlab run experiments/lab-aliasing.lua [--gamma 120] [--projection lispsm] [--sweep KNOB:V1,V2,...]
-- then open reports/lab-aliasing/index.html, which starts with the questions
-- below. Every experiment flag works (--out, --set, --resume, --fresh, ...);
-- the knobs are the script's own flags (`shadowlab run experiments/lab-aliasing.lua --help`):
--   --scene FILE     [scenes/overhead-plane.lua: a directional light, the view looking along -z]
--   --gamma DEG      degrees between the view direction and the light's: 90 overhead (the course's
--                    setting, but the posts' shadows fall under them), 0 the light behind the viewer,
--                    180 shining toward the viewer [120: shadows fall toward the viewer, in sight]
--   --near, --far    the view's z_n and z_f [the scene's]
--   --map_size, --projection (ortho | psm | lispsm | tsm | logpsm), --n (x n_opt), --n_world, --falloff,
--   --pseudo_near, --cascades, --split, --lambda, --split_1..3, --fit: the shared map parameters
--                    (`shadowlab list`) [1024, lispsm, 1, 0, lloyd, 0, 1, practical, 0.5, 0, body]
--   --sweep KNOB:V1,V2,...  one knob swept [projection:ortho,lispsm]; --sweep none for one setting
-- Counts (misclassified, undersampled) are over the samples the analysis is about: lit candidates
-- that the map sees at a finite m (a face edge-on to the light has no finite m and is left out).
--   Try: --sweep n:0.1,0.3,1,3,10,100 (PSM-like to uniform: watch the two axes' maxima and their product);
--   --sweep gamma:30,60,90,120 (Lloyd's falloff); --cascades 4 --split log; --far 10000.
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local html = require "shadowlab.html"
local aliasing_plots = dofile(sl.root .. "/experiments/lib/aliasing_plots.lua")

local QUESTIONS = {
  "Which setting misclassifies fewer samples against the ray-traced truth (the aliasing table's " ..
  "\"misclassified\" column, with its false shadow and false lit counts), and where do those samples lie " ..
  "(the signed-error images, colour bar above them)?",
  "Where along the view is each setting's error largest (the error-along-z plot, and the table along the " ..
  "view axis: e_x across, e_y along the view)? Where does the uniform (ortho) map waste texels, and where " ..
  "does the warp put them instead?",
  "The per-axis maxima m_s max and m_t max (table): which axis does the warp improve and which does it " ..
  "give up? Does their product (the \"m_s max x m_t max\" column) move as much as either factor?",
  "What share of the analysed samples is undersampled (m > 1: the \"undersampled\" column; the m maps, " ..
  "colour key beside them), and what does the storage factor (the texels a uniform m = 1 over the " ..
  "whole view would need, as a multiple of the map's) tell you about how far a single map is from that?",
  "Up to which view depth does the map's fitted region reach (the table's \"fitted z\" column), against " ..
  "the camera's z_f? Why does the fit end there in this scene?",
}

-- Knobs: the script's flags; scene knobs become scene overrides, the others
-- the aliasing technique's shared map parameters (checked by the registry).
local KNOBS = {
  { "scene", "scenes/overhead-plane.lua", "scene file" },
  { "gamma", "120", "degrees between the view direction and the light's (90 overhead; 0 light behind the viewer)" },
  { "near", "scene", "the view's z_n (scene: the scene's)" },
  { "far", "scene", "the view's z_f (scene: the scene's)" },
  { "map_size", "1024", "texels per side of each map", param = "map_size" },
  { "projection", "lispsm", "ortho | psm | lispsm | tsm | logpsm", param = "projection" },
  { "n", "1", "the warp's n as a multiple of n_opt (lispsm, logpsm)", param = "warp_n" },
  { "n_world", "0", "a free n in world units (0: off)", param = "warp_n_world" },
  { "falloff", "lloyd", "lloyd | sin_gamma | none", param = "warp_falloff" },
  { "pseudo_near", "0", "pseudo-near plane, world units (0: off)", param = "pseudo_near" },
  { "cascades", "1", "z-partitions", param = "cascades" },
  { "split", "practical", "practical | log | uniform | explicit | faces", param = "split_scheme" },
  { "lambda", "0.5", "practical split weight", param = "split_lambda" },
  { "split_1", "0", "explicit split view depth 1", param = "split_1" },
  { "split_2", "0", "explicit split view depth 2", param = "split_2" },
  { "split_3", "0", "explicit split view depth 3", param = "split_3" },
  { "fit", "body", "body | body_visible | view | scene", param = "fit" },
  { "sweep", "projection:ortho,lispsm", "KNOB:V1,V2,... one knob swept (none: one setting)" },
}
local extra, knob_of = {}, {}
for _, k in ipairs(KNOBS) do
  extra[k[1]] = { default = k[2], help = k[3] }
  knob_of[k[1]] = k
end
local args = experiment.parse_args(arg, extra)

-- A knob's text as the value its parameter takes (int, float or enum name).
local param = sl.technique("aliasing").param
local function number_of(name, text)
  local v = tonumber(text)
  if not v then error(string.format("lab-aliasing: --%s expects a number, got '%s'", name, text), 0) end
  return v
end
local function param_value(knob, text)
  local t = param[knob.param].type
  if t == "int" then return math.tointeger(number_of(knob[1], text)) or number_of(knob[1], text) end
  if t == "float" then return number_of(knob[1], text) end
  return text
end

-- The scene overrides of gamma, near and far (the view looks along -z).
local function scene_overrides(values)
  local g = math.rad(number_of("gamma", values.gamma))
  local ov = { ["lights[1].direction"] = { 0, -math.sin(g), -math.cos(g) } }
  if values.near ~= "scene" then ov["camera.near"] = number_of("near", values.near) end
  if values.far ~= "scene" then ov["camera.far"] = number_of("far", values.far) end
  return ov
end
-- The map parameters of a setting, those at the registry's defaults left
-- out (so the configurations' labels name what was set).
local function map_params(values)
  local p = {}
  for _, k in ipairs(KNOBS) do
    if k.param then
      local v = param_value(k, values[k[1]])
      local d = param[k.param].default
      if (type(v) == "number" and type(d) == "number" and v ~= d) or (type(v) ~= "number" and tostring(v) ~= tostring(d)) then
        p[k.param] = v
      end
    end
  end
  return p
end

local sweep_knob, sweep_values = nil, { false }
if args.extra.sweep ~= "none" then
  local name, list = args.extra.sweep:match("^([%w_]+):(.+)$")
  if not name or not knob_of[name] or name == "sweep" or name == "scene" then
    error("lab-aliasing: --sweep expects KNOB:V1,V2,... with KNOB one of gamma, near, far or a map knob, got '" ..
          args.extra.sweep .. "'", 0)
  end
  sweep_knob, sweep_values = name, {}
  for v in list:gmatch("[^,]+") do sweep_values[#sweep_values + 1] = v end
end

-- Every setting: the knobs with the swept one at each of its values.
local settings = {}
for _, v in ipairs(sweep_values) do
  local values = {}
  for name, x in pairs(args.extra) do values[name] = x end
  if sweep_knob then values[sweep_knob] = v end
  settings[#settings + 1] = values
end

local exp = experiment.new{
  name = "lab-aliasing", samples = 1, repeats = 1, warmup = 0,
  overrides = scene_overrides(args.extra),
  description = "Shadow-map aliasing (course ch. 3): the error m per map axis, where it lies along the view, " ..
                "and the samples it misclassifies against the ray-traced truth" ..
                (sweep_knob and ", " .. sweep_knob .. " swept." or "."),
}
local scene_knob = sweep_knob == "gamma" or sweep_knob == "near" or sweep_knob == "far"
if scene_knob then
  local variants = {}
  for _, values in ipairs(settings) do variants[#variants + 1] = scene_overrides(values) end
  exp:scene(args.extra.scene, variants)
  exp:add("aliasing", map_params(args.extra))
else
  exp:scene(args.extra.scene)
  local points = {}
  for _, values in ipairs(settings) do points[#points + 1] = map_params(values) end
  exp:add("aliasing", points)
end
local result = exp:run(args)
if result.sharded then return report.write(result) end

---------------------------------------------------------------- the analysis of each row

-- Counts over the samples the analysis is about: a finite, positive m (a
-- lit candidate the map sees; faces edge-on to the light have none).
-- Misclassified: |estimate - reference| > 0.5 (the nearest-texel test
-- answers 0 or 1, the directional light's truth too).
local function restricted_counts(m_img, err_img)
  local w, h = m_img:size()
  local ew, eh = err_img:size()
  if w ~= ew or h ~= eh then error(string.format("lab-aliasing: m map %dx%d, error image %dx%d", w, h, ew, eh), 0) end
  local c = { analysed = 0, undersampled = 0, false_shadow = 0, false_lit = 0, edge_on = 0 }
  for y = 1, h do
    for x = 1, w do
      local m, e = m_img:get(x, y, 1), err_img:get(x, y, 1)
      if m == math.huge then c.edge_on = c.edge_on + 1
      elseif m == m and m > 0 then
        c.analysed = c.analysed + 1
        if m > 1 then c.undersampled = c.undersampled + 1 end
        if e < -0.5 then c.false_shadow = c.false_shadow + 1 elseif e > 0.5 then c.false_lit = c.false_lit + 1 end
      end
    end
  end
  return c
end

-- The view depth where the fitted region ends: the last of 48 log-spaced
-- depths in [z_n, z_f] the map still covers on the view axis.
local function fitted_end(lab, params, zn, zf)
  local probe = {}
  for k = 0, 47 do probe[#probe + 1] = zn * (zf / zn) ^ (k / 47) * (k == 0 and 1 + 1e-9 or k == 47 and 1 - 1e-9 or 1) end
  local last = zn
  for _, p in ipairs(lab:aliasing{ params = params, axis = probe }.axis) do
    if p.cascade > 0 and p.e_x == p.e_x then last = p.z end
  end
  return last
end

local function analyse(row)
  local lab <close> = sl.open(row.variant.file, row.variant.overrides)
  local map = lab:aliasing{ params = row.params }.map
  local zn, z_end = map.near, fitted_end(lab, row.params, map.near, map.far)
  local axis = {}
  for k = 0, 9 do axis[#axis + 1] = zn * (z_end / zn) ^ (k / 9) * (k == 0 and 1 + 1e-9 or k == 9 and 1 - 1e-9 or 1) end
  local a = lab:aliasing{ params = row.params, axis = axis, frustum = 16, image = true }
  local run = lab:compare{ technique = "aliasing", params = row.params, samples = 1, png = false, exr = false }
  return { a = a, counts = restricted_counts(a.image, run:image("error")), zn = zn, zf = map.far, z_end = z_end,
           info = lab:info() }
end

local function fmt(v, f) return type(v) == "number" and v == v and string.format(f, v) or "-" end

local out, rows = result.out, {}
for _, r in ipairs(result.rows) do
  if r.status == "ok" then rows[#rows + 1] = { row = r, an = analyse(r) } end
end
local set, info = aliasing_plots.new(out), nil
local h = { '<table><tr><th>configuration</th><th>analysed samples</th><th>misclassified</th><th>false shadow</th>' ..
            "<th>false lit</th><th>edge-on (left out)</th><th>undersampled (m &gt; 1)</th><th>m mean</th>" ..
            "<th>m_s max</th><th>m_t max</th><th>m_s max x m_t max</th><th>storage factor</th>" ..
            "<th>z_n</th><th>fitted z (ends near)</th><th>camera z_f</th></tr>" }
for _, e in ipairs(rows) do
  local c, s, an = e.an.counts, e.an.a.samples, e.an
  local label = e.row.variant.label ~= "" and e.row.variant.label or e.row.label
  if scene_knob then label = sweep_knob .. "=" .. settings[e.row.index + 1][sweep_knob] end
  e.title = label
  set:add(label, "row-" .. e.row.index, s)
  info = an.info
  h[#h + 1] = string.format("<tr><td>%s</td><td class=\"n\">%d</td><td class=\"n\">%d</td><td class=\"n\">%d</td>" ..
                            "<td class=\"n\">%d</td><td class=\"n\">%d</td><td class=\"n\">%s</td><td class=\"n\">%s</td>" ..
                            "<td class=\"n\">%s</td><td class=\"n\">%s</td><td class=\"n\">%s</td><td class=\"n\">%s</td>" ..
                            "<td class=\"n\">%s</td><td class=\"n\">%s</td><td class=\"n\">%s</td></tr>",
                            html.escape(label), c.analysed, c.false_shadow + c.false_lit, c.false_shadow, c.false_lit,
                            c.edge_on, c.analysed > 0 and string.format("%.1f %%", 100 * c.undersampled / c.analysed) or "-",
                            fmt(s.m_mean, "%.4g"), fmt(s.m_s_max, "%.4g"), fmt(s.m_t_max, "%.4g"),
                            fmt(s.m_s_max * s.m_t_max, "%.4g"), fmt(an.a.frustum.storage_factor, "%.4g"),
                            fmt(an.zn, "%.4g"), fmt(an.z_end, "%.4g"), fmt(an.zf, "%.4g"))
end
h[#h + 1] = "</table>"
local sections = { { title = "Aliasing, per setting", html = table.concat(h, "\n") } }
if #rows > 0 then
  local d, hist = set:draw(out .. "/plots", "aliasing", "Aliasing lab", info, "one curve per setting")
  local axes = { "<table><tr><th>setting</th><th>z</th><th>map</th><th>e_x (across)</th><th>e_y (along the view)</th></tr>" }
  for _, e in ipairs(rows) do
    for _, p in ipairs(e.an.a.axis) do
      axes[#axes + 1] = string.format('<tr><td>%s</td><td class="n">%.4g</td><td class="n">%d</td><td class="n">%s</td>' ..
                                      '<td class="n">%s</td></tr>', html.escape(e.title), p.z, p.cascade,
                                      fmt(p.e_x, "%.4g"), fmt(p.e_y, "%.4g"))
    end
  end
  axes[#axes + 1] = "</table>"
  sections[#sections + 1] = { title = "The error along the view", html =
    string.format('<div class="plots"><p><img src="%s" alt="error along z"></p><p><img src="%s" alt="histogram of m">' ..
                  "</p></div>", html.escape(d.svg), html.escape(hist.svg)) ..
    '<p class="note">Along the view axis, on a surface facing eye and light alike (e as in course §3.1.2), ' ..
    "from z_n to where the fitted region ends:</p>" .. table.concat(axes, "\n") }
  -- the m maps (the aliasing technique's aux channels, report.c's aux colours) with their key
  local maps = { '<p class="note">Key of the m maps: <span style="background:#595959;color:#fff">&nbsp;0&nbsp;</span> ' ..
                 '<span style="background:#e61a1a;color:#fff">&nbsp;1&nbsp;</span> ' ..
                 '<span style="background:#1acc1a">&nbsp;2&nbsp;</span> ' ..
                 '<span style="background:#264dff;color:#fff">&nbsp;3&nbsp;</span> ' ..
                 '<span style="background:#ffe61a">&nbsp;4 and above&nbsp;</span>: the integer part of m (pixels per ' ..
                 "texel; 0: oversampled, m &lt; 1); for the map index 1 red, 2 green, 3 blue, 4 and above yellow; " ..
                 "black: not a lit sample.</p>", '<div class="grid">' }
  for _, e in ipairs(rows) do
    local dir = e.row.images and e.row.images.visibility:match("^(.*)/")
    if dir then
      maps[#maps + 1] = string.format('<figure><img src="%s/aliasing-aux-m.png" alt="m"><figcaption>%s: m</figcaption></figure>',
                                      html.escape(dir), html.escape(e.title))
      maps[#maps + 1] = string.format('<figure><img src="%s/aliasing-aux-cascade.png" alt="map index"><figcaption>%s: ' ..
                                      "map index</figcaption></figure>", html.escape(dir), html.escape(e.title))
      maps[#maps + 1] = string.format('<figure><img src="%s" alt="error"><figcaption>%s: signed error against the ' ..
                                      "truth (colour bar under Images)</figcaption></figure>",
                                      html.escape(e.row.images.error), html.escape(e.title))
    end
  end
  maps[#maps + 1] = "</div>"
  sections[#sections + 1] = { title = "The m maps", html = table.concat(maps, "\n") }
end
report.write(result, { title = "Lab: shadow-map aliasing", error = "all.misclassified", questions = QUESTIONS,
                       sections = sections })
