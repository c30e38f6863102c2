-- report.lua -- reports/NAME/: index.html (self-contained: inline style, no
-- network, relative links, opens from disk), results.csv and records.jsonl
-- (written by the sweep), the images of every configuration beside the
-- reference, and gnuplot plots in SVG and PNG: error against time with the
-- Pareto front marked, error against each machine-independent work counter
-- (texel fetches, rays, triangles, fragments, bytes: what transfers to
-- another machine), error against each swept parameter, cost against each
-- swept parameter. Every plot names its scene, resolution, reference samples
-- and reference noise (plot.lua builds that from the rows it is given).
local json = require "shadowlab.json"
local records = require "shadowlab.records"
local pareto = require "shadowlab.pareto"
local plot = require "shadowlab.plot"
local html = require "shadowlab.html"
local sl = package.loaded.shadowlab or require "shadowlab"

local report = {}

local function ok_rows(rows)
  local out = {}
  for _, r in ipairs(rows) do
    if r.status == "ok" then out[#out + 1] = r end
  end
  return out
end

local field_names = { rmse = "RMSE", mae = "MAE", max_abs = "max |error|", mean_signed = "mean signed error",
                      leak_mean = "mean light leak", dark_mean = "mean over-darkening",
                      misclassified = "fraction |error| > 0.5" }

-- The reference noise a statistic of a region is compared with: its rms for
-- RMSE, sqrt(2/pi) times its mean for MAE (the mean |e| of Gaussian noise);
-- nil for statistics without a noise model (max, signed, leak, dark, >0.5).
local function noise_of(region, field)
  local function number(v) return type(v) == "number" and v or nil end
  if field == "rmse" or field == "rmse_debiased" then
    return { label = "noise rms" .. (region == "all" and "" or " (" .. region .. ")"),
             value = function(rec) return number(rec.metrics[region] and rec.metrics[region].noise_rms) end }
  elseif field == "mae" then
    return { label = "noise MAE" .. (region == "all" and "" or " (" .. region .. ")"),
             value = function(rec)
               local v = number(rec.metrics[region] and rec.metrics[region].noise_mean)
               return v and math.sqrt(2 / math.pi) * v
             end }
  end
  return nil
end

-- The names report.write accepts: error = "REGION.FIELD" (or FIELD, the
-- whole image's), time = one of time_order; the metrics are the record's
-- per-region statistics (src/lab/record.c).
local time_order = { "frame", "evaluate_median", "evaluate_min" }

local function member(list, v)
  for _, x in ipairs(list) do if x == v then return true end end
  return false
end

-- The error metric: a path into the record's metrics, "all.rmse" by default;
-- the getter returns nil for an empty region (json.null), so it is not
-- plotted. An unknown region or field is refused with the valid names.
local function metric_getter(path)
  local region, field = records.metric_path(path)
  if not region then error("report.write: " .. field .. "; the rows are recorded: rerun with --resume", 3) end
  local label = (field_names[field] or field) .. (region == "all" and "" or " (" .. region .. ")")
  return function(r)
    local m = r.record.metrics[region]
    local v = m and m[field]
    return type(v) == "number" and v or nil
  end, label, noise_of(region, field), region .. "." .. field
end

-- The dashed line of a plot of rows: the largest noise among them of the
-- region and statistic plotted (nil when it has none).
local function noise_line(ctx, rows)
  if not ctx.noise then return nil end
  local top
  for _, r in ipairs(rows) do
    local v = ctx.noise.value(r.record)
    if v and (not top or v > top) then top = v end
  end
  return top
end

local time_fields = { frame = "frame time", evaluate_median = "median evaluation", evaluate_min = "minimum evaluation" }

local function group_by(rows, key_of)
  local groups, order = {}, {}
  for _, r in ipairs(rows) do
    local k = key_of(r)
    if not groups[k] then
      groups[k] = {}
      order[#order + 1] = k
    end
    table.insert(groups[k], r)
  end
  return groups, order
end

local function slug(s) return (s:gsub("[^%w]+", "-"):gsub("^-+", ""):gsub("-+$", "")) end

---------------------------------------------------------------- which plots

-- Swept quantities: a technique parameter that takes several values among
-- one technique's rows on one scene file, or a scene override that takes
-- several values across the variants of a scene file.
local function swept_names(rows)
  local values = {}
  local function note(kind, name, scope, v)
    local id = kind .. ":" .. name
    values[id] = values[id] or { kind = kind, name = name, scopes = {} }
    local s = values[id].scopes
    s[scope] = s[scope] or {}
    s[scope][json.encode(v)] = true
  end
  for _, r in ipairs(rows) do
    for name, v in pairs(r.params) do
      if type(v) == "number" then note("param", name, r.variant.file .. "|" .. r.technique, v) end
    end
    for name, v in pairs(r.variant.overrides) do
      if type(v) == "number" then note("scene", name, r.variant.file, v) end
    end
  end
  local out = {}
  for id, e in pairs(values) do
    for _, set in pairs(e.scopes) do
      local n = 0
      for _ in pairs(set) do n = n + 1 end
      if n > 1 then
        out[#out + 1] = { id = id, kind = e.kind, name = e.name }
        break
      end
    end
  end
  table.sort(out, function(a, b) return a.id < b.id end)
  return out
end

local function x_value(axis, r)
  if axis.kind == "param" then return r.params[axis.name] end
  return r.variant.overrides[axis.name]
end

-- Series along an axis: rows that differ only in that axis' value.
local function series_along(axis, rows)
  local function rest_label(r)
    local parts = { r.technique }
    local keys = {}
    for k, v in pairs(r.params) do
      if not (axis.kind == "param" and k == axis.name) and r.swept_params and r.swept_params[k] then keys[#keys + 1] = k end
    end
    table.sort(keys)
    for _, k in ipairs(keys) do parts[#parts + 1] = k .. "=" .. tostring(r.params[k]) end
    local okeys = {}
    for k in pairs(r.variant.overrides) do
      if not (axis.kind == "scene" and k == axis.name) and r.swept_overrides and r.swept_overrides[k] then
        okeys[#okeys + 1] = k
      end
    end
    table.sort(okeys)
    for _, k in ipairs(okeys) do parts[#parts + 1] = k .. "=" .. tostring(r.variant.overrides[k]) end
    return table.concat(parts, " ")
  end
  local usable = {}
  for _, r in ipairs(rows) do
    if type(x_value(axis, r)) == "number" then usable[#usable + 1] = r end
  end
  local groups, order = group_by(usable, rest_label)
  local series = {}
  for _, label in ipairs(order) do
    local g = groups[label]
    table.sort(g, function(a, b) return x_value(axis, a) < x_value(axis, b) end)
    if #g > 1 then series[#series + 1] = { label = label, rows = g } end
  end
  return series
end

-- Which parameters and overrides each row's configuration set on purpose
-- (the swept ones), so series labels name only those.
local function mark_swept(rows, axes)
  local swept = {}
  for _, a in ipairs(axes) do swept[a.id] = true end
  for _, r in ipairs(rows) do
    r.swept_params, r.swept_overrides = {}, {}
    for k in pairs(r.params) do r.swept_params[k] = swept["param:" .. k] end
    for k in pairs(r.variant.overrides) do r.swept_overrides[k] = swept["scene:" .. k] end
  end
end

---------------------------------------------------------------- plots

-- A row's time in ms with the spread of its timed evaluations: the frame
-- time's evaluation part is the median, so its bar runs from the frame time
-- with the fastest evaluation to that with the slowest (frame = builds +
-- set-up + median evaluation, docs/architecture.md). Records without
-- evaluate_max (older builds) get no bar.
local function time_spread(rec, field)
  local t = rec.timings_s
  local v = t[field]
  if type(v) ~= "number" then return nil end
  local lo, hi = v, v
  if type(t.evaluate_max) == "number" and type(t.evaluate_min) == "number" then
    local base = field == "evaluate_min" and t.evaluate_min or t.evaluate_median
    lo, hi = v - base + t.evaluate_min, v - base + t.evaluate_max
  end
  return 1e3 * v, 1e3 * lo, 1e3 * hi
end

local spread_note = "bars: fastest to slowest of the timed evaluations"

local function variant_text(v) return v.scene .. (v.label ~= "" and " [" .. v.label .. "]" or "") end

-- What an error plot's x axis measures: the time (ctx.time) with its
-- spread, or one of the record's work counters (records.work_counters), a
-- count with no spread. Rows without any of the work (0: a ray technique's
-- texel fetches) have no place on a log axis and are left out.
local function time_measure(ctx)
  return { file = "time", label = time_fields[ctx.time], unit = "ms", note = spread_note, front = true,
           x = function(rec) return time_spread(rec, ctx.time) end }
end

local function work_measure(counter)
  local name, label = counter[1], counter[2]
  return { file = name:gsub("_", "-"), label = label, unit = "count", front = true,
           note = "counted, not timed (core/counters.h); rows without any left out",
           x = function(rec)
             local v = records.work_value(name, { record = rec })
             if type(v) ~= "number" then return nil end
             return v, v, v
           end }
end

-- Error against a measure (time_measure, work_measure), one series per
-- technique. For one scene variant (combined = false) with its Pareto
-- front, marked on the rows and its points labelled (the time's front only:
-- it is the one the results table colours); combined, the rows of every
-- variant, a series per technique and variant, without a front (fronts
-- compare one scene).
local function error_vs(ctx, measure, rows, name, combined)
  local points, by_series, order = {}, {}, {}
  for _, r in ipairs(rows) do
    local x, lo, hi = measure.x(r.record)
    local p = { x = x, lo = lo, hi = hi, y = ctx.err(r), row = r }
    if type(p.y) == "number" and type(p.x) == "number" and p.x > 0 then
      points[#points + 1] = p
      local key = combined and r.technique .. " " .. variant_text(r.variant) or r.technique
      if not by_series[key] then
        by_series[key] = {}
        order[#order + 1] = key
      end
      table.insert(by_series[key], p)
    end
  end
  if #points == 0 then return nil end
  local series = {}
  for _, t in ipairs(order) do
    local pts = {}
    for _, p in ipairs(by_series[t]) do pts[#pts + 1] = { p.x, p.y, math.max(p.lo, 1e-9), p.hi } end
    series[#series + 1] = { title = t, points = pts, style = "points", bars = "x" }
  end
  if not combined then
    local front = pareto.front(points)
    local fpts, labels = {}, {}
    for _, p in ipairs(front) do
      if measure.file == "time" then p.row.on_front = true end
      fpts[#fpts + 1] = { p.x, p.y }
      labels[#labels + 1] = { p.x, p.y, p.row.label }
    end
    series[#series + 1] = { title = "Pareto front", points = fpts, style = "front" }
    series[#series + 1] = { title = "Pareto labels", points = labels, style = "labels" }
  end
  local noise = noise_line(ctx, rows)
  return plot.draw(ctx.dir, "error-vs-" .. measure.file .. "-" .. name, {
    title = ctx.err_label .. " against " .. measure.label .. (combined and ", every scene variant" or ""),
    rows = rows, noise = ctx.noise,
    subtitle = (noise and "dashed: reference " .. ctx.noise.label .. "; " or "") .. measure.note ..
               (combined and "" or "\nPareto front circled, its points labelled with their configuration"),
    xlabel = measure.label .. " (" .. measure.unit .. ", log scale)", ylabel = ctx.err_label, logx = true,
    series = series, hline = noise,
  })
end

local function family_of(technique)
  local ok, desc = pcall(sl.technique, technique)
  return ok and desc.family or "other"
end

-- The largest value over the smallest positive one among the series' y.
local function y_span(series)
  local lo, hi = math.huge, 0
  for _, s in ipairs(series) do
    for _, p in ipairs(s.points) do
      if p[2] > 0 then lo, hi = math.min(lo, p[2]), math.max(hi, p[2]) end
    end
  end
  return hi > 0 and hi / lo or 1
end

-- Error (what = "error") or a time (what = a time_fields name) against a
-- swept axis, one series per configuration that differs only along it;
-- times with their spread as bars and a log scale once they span a decade.
-- Returns the plots drawn: the whole, and when one family's times dwarf
-- another's (a span over 20x across families) one plot per family too.
local function along_axis(ctx, axis, scene_rows, name, what)
  local series = {}
  for _, s in ipairs(series_along(axis, scene_rows)) do
    local pts = {}
    for _, r in ipairs(s.rows) do
      if what == "error" then
        local y = ctx.err(r) -- nil for an empty region: the point is left out
        if type(y) == "number" then pts[#pts + 1] = { x_value(axis, r), y } end
      else
        local y, lo, hi = time_spread(r.record, what)
        if y then pts[#pts + 1] = { x_value(axis, r), y, lo, hi } end
      end
    end
    if #pts > 0 then
      series[#series + 1] = { title = s.label, points = pts, style = "linespoints", bars = what ~= "error" and "y" or nil,
                              family = family_of(s.rows[1].technique), technique = s.rows[1].technique }
    end
  end
  if #series == 0 then return {} end
  local lo, hi = math.huge, -math.huge
  for _, s in ipairs(series) do
    for _, p in ipairs(s.points) do lo, hi = math.min(lo, p[1]), math.max(hi, p[1]) end
  end
  local logx = lo > 0 and hi / lo >= 8
  local label = what == "error" and ctx.err_label or time_fields[what]
  local noise = what == "error" and noise_line(ctx, scene_rows) or nil
  local stem = (what == "error" and "error-vs-" or what == "frame" and "cost-vs-" or "eval-vs-") .. slug(axis.name)
  local function draw(list, suffix, title_extra)
    local logy = what ~= "error" and y_span(list) >= 10
    local notes = {}
    if noise then notes[#notes + 1] = "dashed: reference " .. ctx.noise.label end
    if what ~= "error" then notes[#notes + 1] = spread_note end
    return plot.draw(ctx.dir, stem .. "-" .. name .. suffix, {
      title = label .. " against " .. axis.name .. title_extra,
      rows = scene_rows, xlabel = axis.name .. (logx and " (log scale)" or ""),
      ylabel = what == "error" and label or label .. (logy and " (ms, log scale)" or " (ms)"),
      logx = logx, logy = logy, series = list, hline = noise, noise = what == "error" and ctx.noise or nil,
      subtitle = #notes > 0 and table.concat(notes, "; ") or nil,
    })
  end
  local files = { draw(series, "", "") }
  if what ~= "error" then
    -- by family; within one family, by technique (csm's seconds beside pcf's milliseconds)
    local groups, order = group_by(series, function(s) return s.family end)
    if #order == 1 then groups, order = group_by(series, function(s) return s.technique end) end
    if #order > 1 and y_span(series) > 20 then
      for _, g in ipairs(order) do files[#files + 1] = draw(groups[g], "-" .. slug(g), " (" .. g .. " only)") end
    end
  end
  return files
end

---------------------------------------------------------------- entry point

-- report.write(result [, opts]) for the result of experiment:run. opts:
-- title, error ("all.rmse", "penumbra.rmse", "all.mae", ...), time ("frame",
-- "evaluate_median", "evaluate_min"), work (false: no plots of error against
-- the work counters, records.work_counters, drawn beside error against time
-- by default). Returns the path of index.html (nil for a shard: merge the
-- shards, then run the script with --resume).
function report.write(result, opts)
  opts = opts or {}
  if result.sharded then
    if result.quiet then return nil end
    io.stderr:write("report: this is one shard; merge the shards (shadowlab merge), then run again with --resume\n")
    return nil
  end
  local ctx = { dir = result.out .. "/plots", time = opts.time or "frame" }
  if not time_fields[ctx.time] then
    error(string.format("report.write: unknown time '%s'; valid: %s", tostring(ctx.time), table.concat(time_order, ", ")), 2)
  end
  local default_error = result.experiment and result.experiment.error or "all.rmse" -- experiment.new{error = ...}
  ctx.err, ctx.err_label, ctx.noise, ctx.err_path = metric_getter(opts.error or default_error)
  local rows = ok_rows(result.rows)
  local axes = swept_names(rows)
  mark_swept(rows, axes)
  local plots = { time = {}, axes = {}, work = {} }
  local by_variant, variant_order = group_by(rows, function(r) return r.record.scene.hash end)
  local names_used = {}
  for _, h in ipairs(variant_order) do
    local v = by_variant[h][1].variant
    local name = slug(v.scene .. (v.label ~= "" and "-" .. v.label or ""))
    if names_used[name] then name = name .. "-" .. h:sub(1, 8) end
    names_used[name] = true
    plots.time[#plots.time + 1] = { variant = v, file = error_vs(ctx, time_measure(ctx), by_variant[h], name),
                                    rows = by_variant[h] }
    if opts.work ~= false then
      for _, counter in ipairs(records.work_counters) do
        local file = error_vs(ctx, work_measure(counter), by_variant[h], name)
        if file then plots.work[#plots.work + 1] = { variant = v, counter = counter[1], file = file } end
      end
    end
  end
  if #variant_order > 1 then plots.combined = error_vs(ctx, time_measure(ctx), rows, "all-variants", true) end
  local by_scene, scene_order = group_by(rows, function(r) return r.variant.file end)
  for _, f in ipairs(scene_order) do
    local scene_name = slug(by_scene[f][1].variant.scene)
    for _, axis in ipairs(axes) do
      -- the error, the time plotted against it, and the evaluation alone (the frame time hides it)
      local whats = { "error", ctx.time }
      if ctx.time == "frame" then whats[3] = "evaluate_median" end
      for _, what in ipairs(whats) do
        for _, file in ipairs(along_axis(ctx, axis, by_scene[f], scene_name, what)) do
          plots.axes[#plots.axes + 1] = { axis = axis, what = what, file = file }
        end
      end
    end
  end
  local index = result.out .. "/index.html"
  html.write_index(index, { result = result, rows = result.rows, ok_rows = rows, plots = plots, opts = opts,
                            err_label = ctx.err_label, err_path = ctx.err_path, time_label = time_fields[ctx.time], time = ctx.time,
                            err = ctx.err, noise = ctx.noise })
  io.stderr:write("report: " .. index .. "\n")
  return index
end

return report
