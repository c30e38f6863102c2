-- lab-aliasing.lua -- the teaching lab of course ch. 3 (shadow-map aliasing):
-- set the knobs, read the error maps, the error along the view, the storage
-- factor and the misclassification against the ray-traced truth; then sweep
-- one knob and watch the numbers move.
--   build/shadowlab run experiments/lab-aliasing.lua [KNOB=VALUE ...] [sweep=KNOB:V1,V2,...] [out=DIR]
-- Knobs (defaults in brackets):
--   scene        scene file [scenes/overhead-plane.lua: an overhead sun, the view perpendicular to it]
--   map_size     texels per side of each map [1024]
--   near, far    the view's z_n and z_f [the scene's]
--   gamma        degrees between the view direction and the light's (90: overhead, view perpendicular;
--                0: the light behind the viewer, along the view; 180: shining toward the viewer) [90]
--   projection   ortho (uniform) | psm | lispsm | tsm | logpsm [lispsm]
--   n            the warp's n as a multiple of n_opt = z_n + sqrt(z_f z_n) (lispsm, logpsm) [1]
--   n_world      a free n in world units instead (0: off; n and falloff then do nothing) [0]
--   falloff      lloyd | sin_gamma | none: how n grows as gamma shrinks [lloyd]
--   pseudo_near  compute warps and splits as if z_n were this (0: off) [0]
--   cascades     z-partitions [1];  split  practical | log | uniform | explicit | faces [practical];
--   lambda       [0.5];  split_1, split_2, split_3  explicit split view depths, world units [0: not given]
--   fit          body | body_visible | view | scene [body]
-- Writes DIR (default reports/lab-aliasing): the error map (m, Lloyd's colours: green at m = 1, dark red at
-- m >= 10), the map-index image, the shaded image and its error against the truth (images/), lab.md with
-- the numbers, the error along the view depth z and its histogram (plots/aliasing-depth.*,
-- plots/aliasing-hist.*; with a sweep, one curve per value in plots/sweep-depth.*, plots/sweep-hist.*;
-- their data in aliasing/, the format of `shadowlab aliasing`), and sweep.csv when a knob is swept.
--   Try: gamma=90 projection=ortho, then projection=lispsm (the error moves from the near plane to
--   everywhere and shrinks); gamma=10 (the warp fades: Lloyd's falloff); cascades=4 split=log;
--   far=10000 (r = z_f / z_n grows: uniform's error grows like r, LiSPSM's like sqrt(r), log's like ln r);
--   sweep=n:0.1,0.3,1,3,10,100 (PSM-like to uniform: the product of the two axes' maxima stays put).
local sl = require "shadowlab"
local aliasing_plots = dofile(sl.root .. "/experiments/lib/aliasing_plots.lua")

local knobs = { scene = "scenes/overhead-plane.lua", map_size = 1024, gamma = 90, projection = "lispsm", n = 1,
                n_world = 0, falloff = "lloyd", pseudo_near = 0, cascades = 1, split = "practical", lambda = 0.5,
                split_1 = 0, split_2 = 0, split_3 = 0, fit = "body", out = "reports/lab-aliasing" }
local numeric = { map_size = true, near = true, far = true, gamma = true, n = true, n_world = true, pseudo_near = true,
                  cascades = true, lambda = true, split_1 = true, split_2 = true, split_3 = true }
local sweep_knob, sweep_values
for _, a in ipairs(arg) do
  local k, v = a:match("^([%w_]+)=(.+)$")
  if not k then error("lab-aliasing: arguments are KNOB=VALUE (see the header of experiments/lab-aliasing.lua)", 0) end
  if k == "sweep" then
    local name, list = v:match("^([%w_]+):(.+)$")
    if not name then error("lab-aliasing: sweep=KNOB:V1,V2,...", 0) end
    sweep_knob, sweep_values = name, {}
    for x in list:gmatch("[^,]+") do sweep_values[#sweep_values + 1] = numeric[name] and tonumber(x) or x end
  elseif knobs[k] ~= nil or numeric[k] then
    knobs[k] = numeric[k] and tonumber(v) or v
    if numeric[k] and not knobs[k] then error("lab-aliasing: " .. k .. " must be a number", 0) end
  else
    error("lab-aliasing: unknown knob '" .. k .. "' (see the header of experiments/lab-aliasing.lua)", 0)
  end
end

-- The scene overrides and the map parameters of a knob setting.
local function setting(kn)
  local g = math.rad(kn.gamma)
  local ov = { ["lights[1].direction"] = { 0, -math.sin(g), -math.cos(g) } } -- the view looks along -z
  if kn.near then ov["camera.near"] = kn.near end
  if kn.far then ov["camera.far"] = kn.far end
  local params = { map_size = math.tointeger(kn.map_size), projection = kn.projection, warp_n = kn.n,
                   warp_n_world = kn.n_world, warp_falloff = kn.falloff, pseudo_near = kn.pseudo_near,
                   cascades = math.tointeger(kn.cascades), split_scheme = kn.split, split_lambda = kn.lambda,
                   split_1 = kn.split_1, split_2 = kn.split_2, split_3 = kn.split_3, fit = kn.fit }
  return ov, params
end

local function measure(kn, out)
  local ov, params = setting(kn)
  local lab <close> = sl.open(kn.scene, ov)
  local probe = lab:aliasing{ params = params }
  local zn, zf = probe.map.near, probe.map.far
  local axis = {}
  for k = 0, 9 do axis[#axis + 1] = zn * (zf / zn) ^ (k / 9) * (k == 0 and 1 + 1e-9 or k == 9 and 1 - 1e-9 or 1) end
  local a = lab:aliasing{ params = params, axis = axis, frustum = 16 }
  local run = lab:compare{ technique = "aliasing", params = params, samples = 1, out = out, png = out ~= nil,
                           exr = false }
  local m = run:record().metrics
  return a, m.false_shadow + m.false_lit, m.false_shadow, m.false_lit, zn, zf, lab:info()
end

local out = knobs.out
sl.mkdir(out)
local a, wrong, fs, fl, zn, zf, info = measure(knobs, out .. "/images")
local here = aliasing_plots.new(out)
here:add(string.format("%s, %d map%s", knobs.projection, knobs.cascades, knobs.cascades > 1 and "s" or ""), "setting",
         a.samples)
local plot_sub = string.format("%s, gamma %g deg, %d^2 per map, z_n = %g, z_f = %g", knobs.projection, knobs.gamma,
                               knobs.map_size, zn, zf)
local depth_img, hist_img = here:draw(out .. "/plots", "aliasing", "Aliasing lab", info, plot_sub)
local md = { "# Shadow-map aliasing lab", "" }
local settings = {}
for k, v in pairs(knobs) do if k ~= "out" then settings[#settings + 1] = k .. "=" .. tostring(v) end end
table.sort(settings)
md[#md + 1] = "Setting: " .. table.concat(settings, " ") .. string.format(" (z_n = %g, z_f = %g)", zn, zf)
md[#md + 1] = ""
md[#md + 1] = string.format("- maps: %d of %d^2 (%s)%s", a.map.faces, a.map.res, a.map.projection,
                            #a.map.splits > 0 and ", splits " .. table.concat(a.map.splits, ", ") or "")
md[#md + 1] = string.format("- visible samples: %.1f %% undersampled (m > 1), %d seen edge-on by the light (m unbounded); " ..
                            "of the others m max %.4g, mean %.4g; per axis max %.4g / %.4g",
                            100 * a.samples.undersampled_share, a.samples.singular, a.samples.m_max, a.samples.m_mean,
                            a.samples.m_s_max, a.samples.m_t_max)
md[#md + 1] = string.format("- over the view frustum (perspective aliasing only): m max %.4g, storage factor %.4g",
                            a.frustum.m_max, a.frustum.storage_factor)
md[#md + 1] = string.format("- against the truth: %d samples misclassified (%d false shadow, %d false lit)", wrong, fs, fl)
md[#md + 1] = ""
md[#md + 1] = "Along the view axis (a surface facing eye and light alike; e as in course §3.1.2):"
md[#md + 1] = ""
md[#md + 1] = "| z | map | e_x (across) | e_y (along the view) |"
md[#md + 1] = "|---:|---:|---:|---:|"
for _, p in ipairs(a.axis) do
  md[#md + 1] = string.format("| %.4g | %d | %.4g | %.4g |", p.z, p.cascade, p.e_x, p.e_y)
end
md[#md + 1] = ""
md[#md + 1] = "Images: images/aliasing-aux-m.png (m's integer part), images/aliasing-aux-cascade.png (map index), " ..
              "images/aliasing-shaded.png, images/aliasing-error.png (against the truth). For Lloyd's colour map " ..
              "of m run `shadowlab aliasing` with the same parameters."
md[#md + 1] = ""
md[#md + 1] = string.format("![error along z](%s) ![histogram](%s)", depth_img.svg, hist_img.svg)
if sweep_knob then
  local csv = { sweep_knob .. ",misclassified,m_max_samples,m_mean_samples,undersampled_share,storage_factor" }
  md[#md + 1] = ""
  md[#md + 1] = "Sweep of " .. sweep_knob .. ":"
  md[#md + 1] = ""
  md[#md + 1] = "| " .. sweep_knob .. " | misclassified | m max | m mean | undersampled | storage factor |"
  md[#md + 1] = "|---|---:|---:|---:|---:|---:|"
  local swept, swept_info = aliasing_plots.new(out), info
  for _, v in ipairs(sweep_values) do
    local kn = {}
    for k, x in pairs(knobs) do kn[k] = x end
    kn[sweep_knob] = v
    local s, w, _, _, _, _, at = measure(kn, nil)
    swept_info = at
    swept:add(sweep_knob .. "=" .. tostring(v), "sweep-" .. sweep_knob .. "-" .. tostring(v), s.samples)
    csv[#csv + 1] = string.format("%s,%d,%.6g,%.6g,%.6g,%.6g", tostring(v), w, s.samples.m_max, s.samples.m_mean,
                                  s.samples.undersampled_share, s.frustum.storage_factor)
    md[#md + 1] = string.format("| %s | %d | %.4g | %.4g | %.1f %% | %.4g |", tostring(v), w, s.samples.m_max,
                                s.samples.m_mean, 100 * s.samples.undersampled_share, s.frustum.storage_factor)
  end
  sl.write_file(out .. "/sweep.csv", table.concat(csv, "\n") .. "\n")
  local d, h = swept:draw(out .. "/plots", "sweep", "Aliasing lab, sweep of " .. sweep_knob, swept_info, plot_sub)
  md[#md + 1] = ""
  md[#md + 1] = string.format("![error along z](%s) ![histogram](%s)", d.svg, h.svg)
end
sl.write_file(out .. "/lab.md", table.concat(md, "\n") .. "\n")
print(table.concat(md, "\n"))
