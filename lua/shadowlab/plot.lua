-- plot.lua -- one gnuplot plot in SVG and PNG: the data (NAME.dat, one block
-- per series), the script (NAME.gp, kept so a figure can be restyled and
-- redrawn by hand), and the two images. Series styles: "points",
-- "linespoints", "lines" (analytic curves), "front" (a Pareto staircase,
-- black), "labels" (each point's third value written beside it); a series
-- with `bars = "x"` or `"y"` draws each point's {x, y, low, high} as an
-- error bar along that axis. Within one plot every series has its own
-- colour (20) and its own marker (15), the pair unique beyond that.
-- `hline` draws a dashed horizontal line (the reference's noise,
-- `noise` = {label, value(record)} naming it in the subtitle);
-- `logx`, `logy` log scales. The subtitle's first part (scene, resolution,
-- reference samples and noise) is built from the records plotted; the
-- images are written under temporary names and renamed when gnuplot is done.
local sl = package.loaded.shadowlab or require "shadowlab"

local plot = {}

local function quoted(s) return '"' .. tostring(s):gsub('\\', '\\\\'):gsub('"', '\\"'):gsub("\n", "\\n") .. '"' end
local function shell_quoted(s) return "'" .. s:gsub("'", "'\\''") .. "'" end

local function data_text(series)
  local blocks = {}
  for i, s in ipairs(series) do
    local lines = { "# " .. s.title }
    for _, p in ipairs(s.points) do
      if s.style == "labels" then lines[#lines + 1] = string.format("%.9g %.9g %s", p[1], p[2], quoted(p[3]))
      elseif s.bars then lines[#lines + 1] = string.format("%.9g %.9g %.9g %.9g", p[1], p[2], p[3], p[4])
      else lines[#lines + 1] = string.format("%.9g %.9g", p[1], p[2]) end
    end
    blocks[i] = table.concat(lines, "\n")
  end
  return table.concat(blocks, "\n\n\n") .. "\n"
end

-- Distinct colours (Tableau's ten, then ten more told apart on white) and
-- markers (gnuplot's 15 point types on the cairo and SVG terminals).
local colours = { "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
                  "#7f7f7f", "#bcbd22", "#000080", "#008080", "#800000", "#808000", "#ff00ff", "#00c000",
                  "#4b0082", "#ff6060", "#a0522d", "#40e0d0" }
local markers = { 5, 7, 9, 11, 13, 15, 4, 6, 8, 10, 12, 14, 1, 2, 3 }

local function look(i)
  return string.format('pt %d lc rgb "%s"', markers[(i - 1) % #markers + 1], colours[(i - 1) % #colours + 1])
end

local function plot_clause(data, i, s)
  local style
  if s.style == "front" then
    return string.format('%s index %d using 1:2 with steps lw 2 lc rgb "black" title %s, ' ..
                         '%s index %d using 1:2 with points pt 6 ps 2.4 lc rgb "black" notitle',
                         quoted(data), i - 1, quoted(s.title), quoted(data), i - 1)
  elseif s.style == "labels" then
    return string.format('%s index %d using 1:2:3 with labels left offset 0.8,0.6 font ",8" tc rgb "black" notitle',
                         quoted(data), i - 1)
  elseif s.bars then
    local joined = s.style == "linespoints" and "lines" or "bars"
    style = string.format("using 1:2:3:4 with %serror%s ps 1.1 lw 1.2 %s", s.bars, joined, look(i))
    return string.format("%s index %d %s title %s", quoted(data), i - 1, style, quoted(s.title))
  elseif s.style == "linespoints" then style = "with linespoints ps 1.1 lw 1.5 " .. look(i)
  elseif s.style == "lines" then style = "with lines lw 2 " .. look(i)
  else style = "with points ps 1.3 " .. look(i) end
  return string.format("%s index %d using 1:2 %s title %s", quoted(data), i - 1, style, quoted(s.title))
end

-- The range of the numbers among values (json.null, an empty region's
-- statistic, is left out; "none" when no number is left).
local function range_text(values, fmt)
  local lo, hi = math.huge, -math.huge
  for _, v in ipairs(values) do
    if type(v) == "number" then lo, hi = math.min(lo, v), math.max(hi, v) end
  end
  if lo > hi then return "none" end
  if lo == hi then return string.format(fmt, lo) end
  return string.format(fmt .. "-" .. fmt, lo, hi)
end

-- The reference noise a plot of the whole image's RMSE states.
plot.all_noise = { label = "noise rms", value = function(rec) return rec.metrics.all.noise_rms end }

-- "bunny 320x240, reference 256 samples, noise rms 0.0041" for the records
-- (experiment rows or run:record() tables), one part per scene and
-- resolution (sep between them, "; " by default), ranges where they differ.
-- noise ({label, value(record)}, plot.all_noise by default) names the
-- noise of the region and statistic plotted.
function plot.caption(rows, sep, noise)
  noise = noise or plot.all_noise
  local groups, order = {}, {}
  for _, r in ipairs(rows) do
    local rec = r.record or r
    local id = string.format("%s %dx%d", rec.scene.name, rec.scene.width, rec.scene.height)
    if not groups[id] then
      groups[id] = { samples = {}, noise = {} }
      order[#order + 1] = id
    end
    -- a delta light's reference traces one exact ray whatever the samples asked
    if rec.reference.std_error == "exact" then groups[id].exact = true
    else table.insert(groups[id].samples, rec.reference.samples) end
    table.insert(groups[id].noise, noise.value(rec))
  end
  local parts = {}
  for i, id in ipairs(order) do
    local g = groups[id]
    local samples = #g.samples > 0 and range_text(g.samples, "%d") .. " samples" or nil
    if g.exact then samples = (samples and samples .. " and " or "") .. "one exact ray (delta light)" end
    parts[i] = string.format("%s, reference %s, %s %s", id, samples, noise.label, range_text(g.noise, "%.4f"))
  end
  return table.concat(parts, sep or "; ")
end

-- What the plot was measured on (issue 4: every plot states its scene,
-- resolution, reference samples and reference noise), from spec.rows (the
-- records plotted); a measure that needs no reference names its scene
-- (spec.scene, a lab:info() table) and says why (spec.no_reference);
-- closed-form curves say what they are (spec.analytic). Nothing else is
-- accepted, so no plot can leave it out.
local function provenance(name, spec)
  if spec.rows and #spec.rows > 0 then return plot.caption(spec.rows, "\n", spec.noise) end
  if spec.scene and spec.no_reference then
    return string.format("%s %dx%d, no reference: %s", spec.scene.name, spec.scene.width, spec.scene.height,
                         spec.no_reference)
  end
  if spec.analytic then return "closed form: " .. spec.analytic end
  error(string.format("plot %s: pass spec.rows (the records it shows: their scene, resolution, reference samples " ..
                      "and noise go in its subtitle), or spec.scene with spec.no_reference, or spec.analytic for " ..
                      "closed-form curves", name), 0)
end

local terminals = {
  { terminal = 'svg size 820,560 dynamic noenhanced font "sans,11" background rgb "white"', ext = ".svg",
    var = "svg_output" },
  { terminal = 'pngcairo size 820,560 noenhanced font "sans,10"', ext = ".png", var = "png_output" },
}

local function script_text(name, spec)
  local subtitle = provenance(name, spec) .. (spec.subtitle and "\n" .. spec.subtitle or "")
  local lines = {
    "# " .. name .. ": generated by shadowlab's report (lua/shadowlab/plot.lua); run gnuplot on it to redraw",
    "set title " .. quoted(spec.title .. "\n" .. subtitle),
    "set xlabel " .. quoted(spec.xlabel), "set ylabel " .. quoted(spec.ylabel),
    "set key below", "set grid",
  }
  local ymax = spec.hline or 0
  for _, s in ipairs(spec.series) do
    for _, p in ipairs(s.points) do ymax = math.max(ymax, s.bars == "y" and p[4] or p[2]) end
  end
  if spec.logy then lines[#lines + 1] = "set logscale y"
  else lines[#lines + 1] = ymax > 0 and string.format("set yrange [0:%.9g]", 1.08 * ymax) or "set yrange [0:*]" end
  if spec.logx then lines[#lines + 1] = "set logscale x" end
  if spec.hline then
    lines[#lines + 1] = string.format('set arrow from graph 0, first %.9g to graph 1, first %.9g nohead dt 2 lc rgb "gray40"',
                                      spec.hline, spec.hline)
  end
  local clauses = {}
  for i, s in ipairs(spec.series) do clauses[i] = plot_clause(name .. ".dat", i, s) end
  local body = "plot " .. table.concat(clauses, ", \\\n     ")
  for _, t in ipairs(terminals) do
    -- plot.draw names a temporary file in the variable; run by hand, the script writes NAME.svg/.png
    lines[#lines + 1] = string.format("if (!exists(%s)) %s = %s", quoted(t.var), t.var, quoted(name .. t.ext))
    lines[#lines + 1] = "set terminal " .. t.terminal
    lines[#lines + 1] = "set output " .. t.var
    lines[#lines + 1] = body
  end
  lines[#lines + 1] = "unset output"
  return table.concat(lines, "\n") .. "\n"
end

-- The images gnuplot wrote under temporary names, fsynced and renamed over
-- the final ones (one folder: rename is atomic), so a run killed while
-- gnuplot writes leaves the old plot or none, never a truncated one.
local function publish(dir, temps, finals)
  for i, tmp in ipairs(temps) do
    local f = io.open(dir .. "/" .. tmp, "rb")
    if not f or f:seek("end") == 0 then
      if f then f:close() end
      error(string.format("gnuplot wrote no %s/%s", dir, finals[i]), 0)
    end
    sl.fsync(f)
    f:close()
    local ok, msg = os.rename(dir .. "/" .. tmp, dir .. "/" .. finals[i])
    if not ok then error("cannot rename a plot into place: " .. msg, 0) end
  end
  sl.fsync_dir(dir)
end

-- Draw spec into DIR/NAME.{dat,gp,svg,png}; returns the image paths
-- relative to the report folder (DIR's parent).
function plot.draw(dir, name, spec)
  local script = script_text(name, spec)
  sl.mkdir(dir)
  sl.write_file(dir .. "/" .. name .. ".dat", data_text(spec.series))
  sl.write_file(dir .. "/" .. name .. ".gp", script)
  local temps, finals, vars = {}, {}, {}
  for i, t in ipairs(terminals) do
    finals[i] = name .. t.ext
    temps[i] = "." .. name .. t.ext .. ".partial"
    vars[i] = t.var .. " = " .. quoted(temps[i])
  end
  local cmd = string.format("cd %s && gnuplot -e %s %s 2>&1", shell_quoted(dir), shell_quoted(table.concat(vars, "; ")),
                            shell_quoted(name .. ".gp"))
  local pipe = io.popen(cmd)
  local output = pipe:read("a")
  local ok = pipe:close()
  if not ok then
    for _, tmp in ipairs(temps) do os.remove(dir .. "/" .. tmp) end
    error(string.format("gnuplot failed on %s/%s.gp (is gnuplot-nox installed? make deps): %s", dir, name, output), 0)
  end
  publish(dir, temps, finals)
  local base = dir:match("([^/]+)$")
  return { svg = base .. "/" .. name .. ".svg", png = base .. "/" .. name .. ".png" }
end

return plot
