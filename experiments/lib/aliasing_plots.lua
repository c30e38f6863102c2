-- aliasing_plots.lua -- per experiment, the aliasing error along the view
-- depth z and its histogram (issue 6), from the summaries lab:aliasing{}
-- returns (`samples`: the same bins as `shadowlab aliasing`): each
-- configuration's STEM-depth.csv and STEM-hist.csv in that command's format,
-- and two plots over all configurations (lua/shadowlab/plot.lua): the mean
-- error per view-depth bin (log bins over [z_n, z_f]) on the worse map axis,
-- max(mean m_s, mean m_t) (the maxima are in the CSVs: on real scenes a few
-- texels nearly edge-on to the light dominate them), and the share of
-- samples per bin of log10 m (0.1 wide; the end bins are open, and texels
-- seen edge-on by the light count in the last one).
--   local ap = dofile(sl.root .. "/experiments/lib/aliasing_plots.lua")
--   local set = ap.new(out)                      -- CSVs under out/aliasing/
--   set:add("LiSPSM, 2 maps", "lispsm-2", lab:aliasing{...}.samples)
--   set:draw(out .. "/plots", "NAME", title, lab:info())
local sl = require "shadowlab"
local plot = require "shadowlab.plot"

local ap = {}

local DEPTH_COLUMNS = { "z_lo", "z_hi", "count", "m_s_mean", "m_t_mean", "m_s_max", "m_t_max", "persp_s_mean",
                        "persp_t_mean" }
local HIST_COLUMNS = { "lo", "hi", "count" }

local function csv_text(header, columns, rows)
  local lines = { header }
  for _, r in ipairs(rows) do
    local cells = {}
    for i, c in ipairs(columns) do
      cells[i] = c == "count" and string.format("%d", r[c]) or string.format("%.6g", r[c])
    end
    lines[#lines + 1] = table.concat(cells, ",")
  end
  return table.concat(lines, "\n") .. "\n"
end

-- The worse axis's mean m per depth bin with samples, at the bin's geometric centre.
local function depth_points(s)
  local pts = {}
  for _, b in ipairs(s.depth) do
    if b.count > 0 then pts[#pts + 1] = { math.sqrt(b.z_lo * b.z_hi), math.max(b.m_s_mean, b.m_t_mean) } end
  end
  return pts
end

-- Percent of the measured samples per log10 m bin, at the bin's nominal centre.
local function hist_points(s)
  local pts, bins = {}, #s.hist
  for i, b in ipairs(s.hist) do
    local centre = 10 ^ (-2 + 4 * (i - 0.5) / bins)
    pts[#pts + 1] = { centre, s.measured > 0 and 100 * b.count / s.measured or 0 }
  end
  return pts
end

local Set = {}
Set.__index = Set

-- A set of configurations whose CSVs go to DIR/aliasing/.
function ap.new(dir)
  return setmetatable({ dir = dir .. "/aliasing", depth = {}, hist = {} }, Set)
end

-- One configuration: its label in the plots, its file stem, its summary.
function Set:add(label, stem, summary)
  sl.mkdir(self.dir)
  sl.write_file(self.dir .. "/" .. stem .. "-depth.csv",
                csv_text("z_lo,z_hi,count,m_s_mean,m_t_mean,m_s_max,m_t_max,persp_s_mean,persp_t_mean", DEPTH_COLUMNS,
                         summary.depth))
  sl.write_file(self.dir .. "/" .. stem .. "-hist.csv", csv_text("m_lo,m_hi,count", HIST_COLUMNS, summary.hist))
  self.depth[#self.depth + 1] = { title = label, points = depth_points(summary), style = "linespoints" }
  self.hist[#self.hist + 1] = { title = label, points = hist_points(summary), style = "linespoints" }
end

-- PLOTS/NAME-depth.{svg,png} and PLOTS/NAME-hist.{svg,png}; `scene` is the
-- lab:info() of the scene measured (the plots' provenance: the instrument
-- reads the maps' own mapping, no reference). Returns the two image paths
-- relative to PLOTS' parent.
function Set:draw(plots, name, title, scene, subtitle)
  local why = "Lloyd's m from the map's own mapping (pixel -> texel Jacobian)"
  local d = plot.draw(plots, name .. "-depth", { title = title .. ": aliasing error along the view depth",
    subtitle = subtitle, scene = scene, no_reference = why, xlabel = "view depth z (world units)",
    ylabel = "max(mean m_s, mean m_t) in the depth bin (pixels per texel)", series = self.depth, hline = 1,
    logx = true, logy = true })
  local h = plot.draw(plots, name .. "-hist", { title = title .. ": histogram of the aliasing error",
    subtitle = subtitle, scene = scene, no_reference = why,
    xlabel = "m = max(m_s, m_t) (bins of 0.1 in log10 m; the last also holds texels edge-on to the light)",
    ylabel = "% of the measured samples", series = self.hist, logx = true })
  return d, h
end

return ap
