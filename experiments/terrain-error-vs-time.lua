-- terrain-error-vs-time.lua -- hard-shadow error against frame time on the
-- terrain (scenes/terrain.lua: 1 km of hills, near 0.1, far 1500): `sm`
-- (nearest lookups, the same biases everywhere) on a uniform map, LiSPSM,
-- PSSM with m = 1..8 cascades and practical splits lambda in {0, 0.5, 0.9, 1}
-- (Zhang et al. 2006; 0 uniform, 1 log), and LogPSM (ray cast per texel),
-- each at 1024^2, 2048^2 and 4096^2 per map, all fitted to the intersection
-- body B. Error: the share of lit candidates misclassified against the
-- ray-traced truth (one exact shadow ray per sample for the sun). Time: the
-- frame time (the maps rebuilt every frame, then the lookups: lab.h).
--   build/shadowlab run experiments/terrain-error-vs-time.lua [--sizes 1024,2048,4096] [--out DIR]
--       [--repeat N] [-s camera.width=W ...] [--no-images]
-- Each (map size, scheme) group runs as its own experiment (its maps are
-- freed before the next: 8 cascades of 4096^2 are 512 MiB), under
-- DIR/<size>-<scheme>/ (default DIR reports/terrain-error-vs-time); then
-- DIR/summary.md, DIR/results.csv and DIR/plots/error-vs-time-<size>.*.
local sl = require "shadowlab"
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local plot = require "shadowlab.plot"

local out, sizes, passthrough = "reports/terrain-error-vs-time", { 1024, 2048, 4096 }, {}
local i = 1
while arg[i] do
  if arg[i] == "--out" then out = arg[i + 1]; i = i + 2
  elseif arg[i] == "--sizes" then
    sizes = {}
    for s in arg[i + 1]:gmatch("[^,]+") do sizes[#sizes + 1] = math.tointeger(tonumber(s)) end
    i = i + 2
  else passthrough[#passthrough + 1] = arg[i]; i = i + 1 end
end

local function schemes(size)
  local base = { map_size = { size }, fit = { "body" } }
  local function with(t) local g = {} for k, v in pairs(base) do g[k] = v end for k, v in pairs(t) do g[k] = v end return g end
  return {
    { name = "uniform", points = sweep.grid(with{ projection = { "ortho" } }) },
    { name = "lispsm", points = sweep.grid(with{ projection = { "lispsm" } }) },
    { name = "pssm", points = sweep.grid(with{ projection = { "ortho" }, cascades = { 1, 2, 3, 4, 5, 6, 7, 8 },
                                               split_lambda = { 0, 0.5, 0.9, 1 } }) },
    { name = "logpsm", points = sweep.grid(with{ projection = { "logpsm" } }) },
  }
end

local function label(r)
  local p = r.params
  if p.cascades > 1 or (p.projection == "ortho" and r.group == "pssm") then
    return string.format("PSSM m=%d lambda=%g", p.cascades, p.split_lambda)
  end
  return ({ ortho = "uniform", lispsm = "LiSPSM", logpsm = "LogPSM" })[p.projection] or p.projection
end

local rows = {}
for _, size in ipairs(sizes) do
  for _, s in ipairs(schemes(size)) do
    local exp = experiment.new{ name = "terrain-error-vs-time", samples = 1, repeats = 3, warmup = 1,
                                description = string.format("terrain, %s at %d^2 per map", s.name, size) }
    exp:scene("scenes/terrain.lua")
    exp:add("sm", s.points)
    local argv = { "--out", string.format("%s/%d-%s", out, size, s.name) }
    for _, a in ipairs(passthrough) do argv[#argv + 1] = a end
    local result = exp:run(argv)
    for _, r in ipairs(result.rows) do
      if r.status == "ok" then r.group, r.size = s.name, size; rows[#rows + 1] = r end
    end
  end
end

local csv = { "map_size,configuration,maps,misclassified,frame_s,technique_build_s,evaluate_s" }
local md = { "# Hard-shadow error against frame time on the terrain", "",
             "`sm` (nearest lookups, default biases) against the ray-traced truth; misclassified = share of the " ..
             "lit candidates whose shadow state is wrong; frame = the maps rebuilt + the lookups.", "",
             "| map size | configuration | maps | misclassified | frame (s) |", "|---:|---|---:|---:|---:|" }
local by_size, rows_of_size = {}, {}
for _, r in ipairs(rows) do
  local m, t = r.record.metrics.all.misclassified, r.record.timings_s
  local maps = r.params.cascades
  csv[#csv + 1] = string.format("%d,%s,%d,%.6g,%.6g,%.6g,%.6g", r.size, label(r), maps, m, t.frame, t.technique_build,
                                t.evaluate_median)
  md[#md + 1] = string.format("| %d | %s | %d | %.3f %% | %.3f |", r.size, label(r), maps, 100 * m, t.frame)
  by_size[r.size] = by_size[r.size] or {}
  rows_of_size[r.size] = rows_of_size[r.size] or {}
  table.insert(rows_of_size[r.size], r)
  local key = r.group == "pssm" and string.format("PSSM lambda=%g", r.params.split_lambda) or label(r)
  by_size[r.size][key] = by_size[r.size][key] or {}
  table.insert(by_size[r.size][key], { t.frame, 100 * m })
end
sl.mkdir(out)
for size, groups in pairs(by_size) do
  local series, names = {}, {}
  for k in pairs(groups) do names[#names + 1] = k end
  table.sort(names)
  for _, k in ipairs(names) do
    series[#series + 1] = { title = k, points = groups[k], style = k:match("PSSM") and "linespoints" or "points" }
  end
  plot.draw(out .. "/plots", "error-vs-time-" .. size, { title = string.format("Terrain: error against time, %d^2 per map", size),
    rows = rows_of_size[size], subtitle = "PSSM: m = 1..8 along each line", xlabel = "frame time (s)",
    ylabel = "misclassified (% of lit candidates)",
    series = series, logx = true })
  md[#md + 1] = ""
  md[#md + 1] = string.format("![%d](plots/error-vs-time-%d.svg)", size, size)
end
sl.write_file(out .. "/results.csv", table.concat(csv, "\n") .. "\n")
sl.write_file(out .. "/summary.md", table.concat(md, "\n") .. "\n")
print(table.concat(md, "\n"))
