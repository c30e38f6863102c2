-- issue5-combined.lua -- the combined report of issue 5: the seed papers'
-- soft-shadow techniques and their baselines (accumulation, adaptive_area,
-- single_sample_rt, shadow_width, brabec, pcss) on the bunny,
-- sphere-on-plane, overlap and contact scenes as the light grows from tiny to
-- large: error against frame time with the Pareto front of each scene
-- variant, and summary.md, the lowest RMSE of each technique per scene and
-- light size with the configurations on the front.
--   build/shadowlab run experiments/issue5-combined.lua [--resume] [--shard I/N] ...
--   ISSUE5_TECHNIQUES=accumulation,pcss build/shadowlab run ...   (a subset)
-- Lights: sphere radius R in RADII on the three sphere-light scenes. Their
-- rect stand-ins (adaptive_area handles rect lights only) are written to
-- OUT/scenes/NAME-rect.lua from the scene file with only lights[1]
-- replaced: a square of the sphere's projected area (side sqrt(pi) R), centred
-- where the sphere is and facing the camera's target (the scene's centre of
-- interest). contact's own rect light is swept over the same squares.
-- adaptive_area and pcss (the baseline it is compared with) run on the
-- stand-ins; every other technique on the sphere lights and on contact.
-- 240x180 view samples, 256-sample references (cached by content).
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local RADII = { 0.01, 0.05, 0.2, 0.4, 0.8 }
local SQRT_PI = math.sqrt(math.pi)
-- The side of the square of a sphere's projected area, rounded to 4 digits
-- (area within 0.03 %) for readable labels.
local function square_side(r) return tonumber(string.format("%.4g", SQRT_PI * r)) end
local SPHERE_SCENES = { "scenes/sphere-on-plane.lua", "scenes/bunny.lua", "scenes/overlap.lua" }
-- Points per technique: a cheap one, the default and a quality one where the
-- technique has a cost knob, so each contributes a curve to the front.
local POINTS = {
  accumulation = { { K = 5 }, { K = 10 }, { K = 15 }, { K = 31 }, { K = 10, variant = "additive" },
                   { K = 15, variant = "additive" } },
  adaptive_area = { { max_level = 0 }, {}, { fixed = true } },
  single_sample_rt = { {}, { analytic_spheres = false } },
  shadow_width = { { c_scale = 2 }, {}, { c_scale = 32 } },
  brabec = { { search_radius = 8 }, {}, { search_radius = 64 } },
  pcss = { {}, { blocker_taps = 64, filter_taps = 64 }, { sampling = "exhaustive" } },
}
local ORDER = { "accumulation", "adaptive_area", "single_sample_rt", "shadow_width", "brabec", "pcss" }
local ON_STAND_INS = { adaptive_area = true, pcss = true }

local o = experiment.parse_args(arg)
local out = o.out or "reports/issue5-combined"

---------------------------------------------------------------- rect stand-ins

-- A scene table as Lua source: keys sorted, arrays as arrays.
local function to_lua(v, indent)
  if type(v) == "string" then return string.format("%q", v) end
  if type(v) ~= "table" then return math.type(v) == "float" and string.format("%.15g", v) or tostring(v) end
  local inner, parts = indent .. "  ", {}
  if #v > 0 then
    for _, x in ipairs(v) do parts[#parts + 1] = to_lua(x, inner) end
    if type(v[1]) ~= "table" then return "{ " .. table.concat(parts, ", ") .. " }" end
    return "{\n" .. inner .. table.concat(parts, ",\n" .. inner) .. ",\n" .. indent .. "}"
  end
  local keys = {}
  for k in pairs(v) do keys[#keys + 1] = k end
  table.sort(keys)
  for _, k in ipairs(keys) do parts[#parts + 1] = k .. " = " .. to_lua(v[k], inner) end
  return "{\n" .. inner .. table.concat(parts, ",\n" .. inner) .. ",\n" .. indent .. "}"
end

-- OUT/scenes/NAME-rect.lua: the scene with its sphere light replaced by the
-- square of the same projected area (the width is swept by the variants).
local function rect_stand_in(path)
  local scene = assert(loadfile(path, "t", { math = math }) or loadfile(sl.root .. "/" .. path, "t", { math = math }))()
  local sphere = scene.lights[1]
  assert(sphere.type == "sphere", path .. ": lights[1] is not a sphere")
  scene.name = scene.name .. "-rect"
  scene.lights[1] = { type = "rect", position = sphere.position, target = scene.camera.target,
                      width = square_side(sphere.radius), height = square_side(sphere.radius), color = sphere.color,
                      intensity = sphere.intensity }
  local target = string.format("%s/scenes/%s.lua", out, scene.name)
  sl.mkdir(out .. "/scenes")
  sl.write_file(target, "-- " .. scene.name .. ": " .. path .. " with its sphere light replaced by the square of " ..
                        "its projected area, written by experiments/issue5-combined.lua.\nreturn " ..
                        to_lua(scene, "") .. "\n")
  return target
end

local function square_widths()
  local w = {}
  for i, r in ipairs(RADII) do w[i] = square_side(r) end
  return sweep.zip{ ["lights[1].width"] = w, ["lights[1].height"] = w }
end

---------------------------------------------------------------- the sweep

local only
if os.getenv("ISSUE5_TECHNIQUES") then
  only = {}
  for name in os.getenv("ISSUE5_TECHNIQUES"):gmatch("[^,%s]+") do only[name] = true end
end
local registered = {}
for _, t in ipairs(sl.techniques()) do registered[t.name] = true end

local exp = experiment.new{
  name = "issue5-combined", samples = 256, repeats = 3, warmup = 1,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Issue 5: the seed papers' soft-shadow techniques and the PCSS / single-sample baselines on four " ..
                "scenes, sphere light radius 0.01-0.8 (rect lights: squares of the same projected area, side " ..
                "sqrt(pi) R), error against frame time.",
}
local stand_in = {}
for _, s in ipairs(SPHERE_SCENES) do
  exp:scene(s, sweep.grid{ ["lights[1].radius"] = RADII })
  local rect = rect_stand_in(s)
  stand_in[rect] = true
  exp:scene(rect, square_widths())
end
exp:scene("scenes/contact.lua", square_widths())
for _, name in ipairs(ORDER) do
  if registered[name] and (not only or only[name]) then exp:add(name, POINTS[name]) end
end

-- The registry already keeps adaptive_area (rect lights only) off the sphere
-- lights; keep the sphere-light techniques off the stand-ins but for pcss.
local all_configurations = exp.configurations
function exp:configurations()
  local kept = {}
  for _, c in ipairs(all_configurations(self)) do
    if not stand_in[c.variant.file] or ON_STAND_INS[c.entry.technique.name] then
      c.index = #kept
      kept[#kept + 1] = c
    end
  end
  return kept
end

local result = exp:run(o)
report.write(result, { title = "Issue 5: soft shadows, error against frame time" })
if result.sharded then return end

---------------------------------------------------------------- summary.md

-- The sphere radius a variant stands for (rect lights: the R of their side).
local function radius_of(v)
  local r = v.overrides["lights[1].radius"]
  if r then return r end
  for _, radius in ipairs(RADII) do
    if square_side(radius) == v.overrides["lights[1].width"] then return radius end
  end
end
local function base_scene(name) return (name:gsub("%-rect$", "")) end

local best, front, radii_seen, scenes_seen, variants_seen = {}, {}, {}, {}, {}
for _, r in ipairs(result.rows) do
  if r.status == "ok" then
    local scene, radius = base_scene(r.variant.scene), radius_of(r.variant)
    local key = string.format("%s|%g", scene, radius)
    local tech = r.technique .. (r.variant.scene:match("%-rect$") and r.technique == "pcss" and " (rect)" or "")
    best[key] = best[key] or {}
    local m, t = r.record.metrics.all.rmse, r.record.timings_s.frame
    if not best[key][tech] or m < best[key][tech].rmse then best[key][tech] = { rmse = m, frame = t } end
    if r.on_front then
      local vkey = string.format("%s|%g", r.variant.scene, radius)
      front[vkey] = front[vkey] or {}
      table.insert(front[vkey], string.format("%s (%.3f, %.0f ms)", r.label, m, 1e3 * t))
    end
    radii_seen[radius] = true
    scenes_seen[scene] = true
    variants_seen[r.variant.scene] = true
  end
end
local columns = {}
for _, t in ipairs(ORDER) do
  columns[#columns + 1] = t
  if t == "pcss" then columns[#columns + 1] = "pcss (rect)" end
end
local md = { "# Issue 5, combined: lowest RMSE per technique (frame time of that configuration)", "",
             string.format("%dx%d view samples, %d-sample references. adaptive_area and `pcss (rect)` ran on the " ..
                           "rect stand-in (a square of the sphere's projected area, side sqrt(pi) R); contact's " ..
                           "light is that square for every technique.", exp.overrides["camera.width"],
                           exp.overrides["camera.height"], exp.samples), "",
             "| scene | R | " .. table.concat(columns, " | ") .. " |",
             "|---|---:|" .. string.rep("---:|", #columns) }
local scene_list, radius_list = {}, {}
for s in pairs(scenes_seen) do scene_list[#scene_list + 1] = s end
for rr in pairs(radii_seen) do radius_list[#radius_list + 1] = rr end
table.sort(scene_list)
table.sort(radius_list)
for _, s in ipairs(scene_list) do
  for _, rr in ipairs(radius_list) do
    local key = string.format("%s|%g", s, rr)
    if best[key] then
      local cells = {}
      for i, t in ipairs(columns) do
        local b = best[key][t]
        cells[i] = b and string.format("%.3f (%.0f ms)", b.rmse, 1e3 * b.frame) or "-"
      end
      md[#md + 1] = string.format("| %s | %g | %s |", s, rr, table.concat(cells, " | "))
    end
  end
end
md[#md + 1] = ""
md[#md + 1] = "## Pareto fronts (RMSE, frame time), per scene variant"
md[#md + 1] = ""
local variant_list = {}
for v in pairs(variants_seen) do variant_list[#variant_list + 1] = v end
table.sort(variant_list)
for _, s in ipairs(variant_list) do
  for _, rr in ipairs(radius_list) do
    local key = string.format("%s|%g", s, rr)
    if front[key] then md[#md + 1] = string.format("- %s, R = %g: %s", s, rr, table.concat(front[key], "; ")) end
  end
end
sl.write_file(result.out .. "/summary.md", table.concat(md, "\n") .. "\n")
io.stderr:write("issue5-combined: " .. result.out .. "/summary.md\n")
