-- course-fig5.5-5.8-occluders.lua -- course §5.2.3.1 and §5.2.3.3, Figs. 5.5
-- and 5.8 measured: the documented biases of backprojection's occluder
-- approximations (src/techniques/backprojection.c), each representation x
-- gap filling x accumulation against the Embree reference:
--   Fig. 5.5 / §5.2.3.1: summing micropatch areas "over-occludes where
--     patches overlap" (accumulate=area: mean signed error < 0, and below the
--     bitmask's), and micropatches without gap filling leak light through the
--     slits between neighbours at different depths ("gaps leak light":
--     gaps=none leaks more than guennebaud's and the diagonal's filling).
--   Fig. 5.8 / §5.2.3.3: micropatches "overestimate occluders" (mean signed
--     < 0), microquads "underestimate" them (> 0) and "miss twigs one texel
--     wide" (scenes/twig.lua: a comb of one-texel bars; microquad's leak >
--     micropatch's).
-- Signed error e = V - V_ref over the reference's umbra and penumbra samples
-- together (count-weighted from the record's per-region metrics): leak =
-- mean max(e, 0) (too lit), dark = mean max(-e, 0) (too dark).
--   build/shadowlab run experiments/course-fig5.5-5.8-occluders.lua [--resume] ...
-- Writes reports/course-fig5.5-5.8-occluders/: index.html, figure.html and
-- reproduction.{md,csv}.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local reproduce = require "shadowlab.reproduce"
local figures = dofile(sl.root .. "/experiments/lib/figures.lua")

local SCENES = { "sphere-on-plane", "overlap", "twig" }
local BIAS_SCENES = { "sphere-on-plane", "overlap" } -- Fig. 5.5's overlaps and gaps, Fig. 5.8's over/under

local exp = experiment.new{ error = "penumbra.rmse",
  name = "course-fig5.5-5.8-occluders", samples = 256, repeats = 1, warmup = 0,
  overrides = { ["camera.width"] = 240, ["camera.height"] = 180 },
  description = "Course Figs. 5.5 and 5.8: signed error of backprojection's occluder approximations " ..
                "(micropatch with each gap filling, microquad, microtri) by bitmask and by summed area.",
}
for _, s in ipairs(SCENES) do exp:scene("scenes/" .. s .. ".lua") end
exp:add("backprojection", sweep.grid{ occluder = { "micropatch" }, gaps = { "none", "guennebaud", "diagonal" },
                                      accumulate = { "bitmask", "area" } })
exp:add("backprojection", sweep.grid{ occluder = { "microquad", "microtri" }, accumulate = { "bitmask", "area" } })
local result = exp:run(arg)
report.write(result, { title = "Course Figs. 5.5 and 5.8: occluder approximations" })
if result.sharded then return end

-- A configuration's name: its representation, gap filling (micropatches only) and accumulation.
local function label(p)
  return p.occluder .. (p.occluder == "micropatch" and "/" .. p.gaps or "") .. ", " .. p.accumulate
end

-- Count-weighted means of the umbra's and penumbra's signed, leak and dark errors (NaN without samples).
-- A region without samples holds json.null for its means: it adds nothing.
local function shadowed(m)
  local regions = { m.umbra, m.penumbra }
  local n = m.umbra.count + m.penumbra.count
  local function mean(k)
    local sum = 0
    for _, g in ipairs(regions) do
      if g.count > 0 then sum = sum + g.count * g[k] end
    end
    return n > 0 and sum / n or 0 / 0
  end
  return { n = n, signed = mean("mean_signed"), leak = mean("leak_mean"), dark = mean("dark_mean") }
end

local err, rows_table = {}, {} -- err[scene][label] = shadowed(...)
for _, r in ipairs(result.rows) do
  if r.status == "ok" then
    local s, l = r.variant.scene, label(r.params)
    local e = shadowed(r.record.metrics)
    err[s] = err[s] or {}
    err[s][l] = e
    rows_table[#rows_table + 1] = { s, l, tostring(e.n), string.format("%+.4f", e.signed), string.format("%.4f", e.leak),
                                    string.format("%.4f", e.dark),
                                    string.format("%.4f", r.record.metrics.penumbra.rmse) }
  end
end

local function get(s, l, k) return err[s] and err[s][l] and err[s][l][k] end
local function over(a, b) return a and b and a / b end
local claims = {}
for _, s in ipairs(BIAS_SCENES) do
  claims[#claims + 1] = { item = s .. ": micropatch/diagonal, area", quantity = "mean signed error", paper = 0,
                          measured = get(s, "micropatch/diagonal, area", "signed"),
                          rule = reproduce.below("summing areas 'over-occludes where patches overlap': below 0"),
                          source = "course §5.2.3.1, Fig. 5.5" }
  local a, b = get(s, "micropatch/diagonal, area", "signed"), get(s, "micropatch/diagonal, bitmask", "signed")
  claims[#claims + 1] = { item = s .. ": micropatch/diagonal, area - bitmask", quantity = "mean signed error",
                          paper = 0, measured = a and b and a - b,
                          rule = reproduce.below("the overlap's share of it (bitmask unions count each sample " ..
                                                 "once, course §5.2.3.2): below 0"),
                          source = "course §5.2.3.1-2, Fig. 5.5" }
  for _, filled in ipairs({ "guennebaud", "diagonal" }) do
    claims[#claims + 1] = { item = string.format("%s: micropatch/none / micropatch/%s, bitmask", s, filled),
                            quantity = "leak ratio", paper = 1,
                            measured = over(get(s, "micropatch/none, bitmask", "leak"),
                                            get(s, "micropatch/" .. filled .. ", bitmask", "leak")),
                            rule = reproduce.above("'gaps leak light', filling fixes it: above 1"),
                            source = "course §5.2.3.3, Fig. 5.5" }
  end
  claims[#claims + 1] = { item = s .. ": micropatch/diagonal, bitmask", quantity = "mean signed error", paper = 0,
                          measured = get(s, "micropatch/diagonal, bitmask", "signed"),
                          rule = reproduce.below("micropatches 'overestimate occluders': below 0"),
                          source = "course §5.2.3.3, Fig. 5.8" }
  claims[#claims + 1] = { item = s .. ": microquad, bitmask", quantity = "mean signed error", paper = 0,
                          measured = get(s, "microquad, bitmask", "signed"),
                          rule = reproduce.above("microquads 'underestimate occluders': above 0"),
                          source = "course §5.2.3.3, Fig. 5.8" }
end
claims[#claims + 1] = { item = "twig: microquad / micropatch/diagonal, bitmask", quantity = "leak ratio", paper = 1,
                        measured = over(get("twig", "microquad, bitmask", "leak"),
                                        get("twig", "micropatch/diagonal, bitmask", "leak")),
                        rule = reproduce.above("microquads 'miss twigs one texel wide', micropatches keep them: " ..
                                               "above 1"),
                        source = "course §5.2.3.3, Fig. 5.8" }

local page = figures.page(result.out, "Course Figs. 5.5 and 5.8: occluder approximations",
  "Signed error V - V_ref over the reference's umbra and penumbra (leak: too lit, dark: too dark) for each occluder " ..
  "representation, gap filling and accumulation of backprojection (1024^2 map, 256-sample bitmask), on " ..
  "sphere-on-plane, overlap and twig (a comb of one-texel bars).")
page:table({ "scene", "configuration", "umbra + penumbra samples", "mean signed", "leak", "dark", "penumbra RMSE" },
           rows_table)
local w, h = exp.overrides["camera.width"], exp.overrides["camera.height"]
page:text(reproduce.compare(claims, { out = result.out, title = "Course Figs. 5.5 and 5.8",
  note = string.format("backprojection at its defaults but for occluder, gaps and accumulate; %sx%s, %d reference " ..
                       "samples; errors over the reference's umbra and penumbra", tostring(w), tostring(h),
                       exp.samples) }).html)
page:write()
