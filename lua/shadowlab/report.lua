-- report.lua -- reports/NAME/: index.html (self-contained: inline style, no
-- network, relative links, opens from disk), results.csv and records.jsonl
-- (written by the sweep), the images of every configuration beside the
-- reference, and gnuplot plots in SVG and PNG: error against time with the
-- Pareto front marked, error against each swept parameter, cost against each
-- swept parameter. Every plot names its scene, resolution, reference samples
-- and reference noise (plot.lua builds that from the rows it is given).
local json = require "shadowlab.json"
local pareto = require "shadowlab.pareto"
local plot = require "shadowlab.plot"
local html = require "shadowlab.html"

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
local region_order = { "all", "umbra", "penumbra", "lit", "terminator" }
local field_order = { "rmse", "rmse_debiased", "mae", "max_abs", "mean_signed", "leak_mean", "dark_mean",
                      "misclassified", "noise_rms", "noise_mean" }
local time_order = { "frame", "evaluate_median", "evaluate_min" }

local function member(list, v)
  for _, x in ipairs(list) do if x == v then return true end end
  return false
end

-- Every error name report.write accepts, for its refusal and the README.
function report.error_names()
  local names = {}
  for _, g in ipairs(region_order) do
    for _, f in ipairs(field_order) do names[#names + 1] = g .. "." .. f end
  end
  return names
end
report.time_names = time_order

-- The error metric: a path into the record's metrics, "all.rmse" by default;
-- the getter returns nil for an empty region (json.null), so it is not
-- plotted. An unknown region or field is refused with the valid names.
local function metric_getter(path)
  local region, field = tostring(path):match("^(%w+)%.([%w_]+)$")
  if not region then region, field = "all", path end
  if not (member(region_order, region) and member(field_order, field)) then
    error(string.format("report.write: unknown error metric '%s'; valid: REGION.FIELD with REGION one of %s and " ..
                        "FIELD one of %s (e.g. penumbra.rmse; a bare FIELD means all.FIELD); the rows are recorded: rerun with --resume", tostring(path),
                        table.concat(region_order, ", "), table.concat(field_order, ", ")), 3)
  end
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

local function error_vs_time(ctx, variant_rows, name)
  local points, by_tech = {}, {}
  local techs = {}
  for _, r in ipairs(variant_rows) do
    local p = { x = 1e3 * r.record.timings_s[ctx.time], y = ctx.err(r), row = r }
    if type(p.y) == "number" and type(p.x) == "number" and p.x > 0 then
      points[#points + 1] = p
      if not by_tech[r.technique] then
        by_tech[r.technique] = {}
        techs[#techs + 1] = r.technique
      end
      table.insert(by_tech[r.technique], p)
    end
  end
  if #points == 0 then return nil end
  local front = pareto.front(points)
  for _, p in ipairs(front) do p.row.on_front = true end
  local series = {}
  for _, t in ipairs(techs) do
    local pts = {}
    for _, p in ipairs(by_tech[t]) do pts[#pts + 1] = { p.x, p.y } end
    series[#series + 1] = { title = t, points = pts, style = "points" }
  end
  local fpts = {}
  for _, p in ipairs(front) do fpts[#fpts + 1] = { p.x, p.y } end
  series[#series + 1] = { title = "Pareto front", points = fpts, style = "front" }
  local noise = noise_line(ctx, variant_rows)
  return plot.draw(ctx.dir, "error-vs-time-" .. name, {
    title = ctx.err_label .. " against " .. time_fields[ctx.time],
    rows = variant_rows, subtitle = noise and "dashed: reference " .. ctx.noise.label or nil, noise = ctx.noise,
    xlabel = time_fields[ctx.time] .. " (ms, log scale)", ylabel = ctx.err_label, logx = true,
    series = series, hline = noise,
  })
end

local function along_axis(ctx, axis, scene_rows, name, what)
  local series = {}
  for _, s in ipairs(series_along(axis, scene_rows)) do
    local pts = {}
    for _, r in ipairs(s.rows) do
      local y -- nil for an empty region: the point is left out
      if what == "error" then y = ctx.err(r) else y = 1e3 * r.record.timings_s[ctx.time] end
      if type(y) == "number" then pts[#pts + 1] = { x_value(axis, r), y } end
    end
    if #pts > 0 then series[#series + 1] = { title = s.label, points = pts, style = "linespoints" } end
  end
  if #series == 0 then return nil end
  local lo, hi = math.huge, -math.huge
  for _, s in ipairs(series) do
    for _, p in ipairs(s.points) do lo, hi = math.min(lo, p[1]), math.max(hi, p[1]) end
  end
  local logx = lo > 0 and hi / lo >= 8
  local ylabel = what == "error" and ctx.err_label or time_fields[ctx.time] .. " (ms)"
  local noise = what == "error" and noise_line(ctx, scene_rows) or nil
  return plot.draw(ctx.dir, (what == "error" and "error-vs-" or "cost-vs-") .. slug(axis.name) .. "-" .. name, {
    title = (what == "error" and ctx.err_label or time_fields[ctx.time]) .. " against " .. axis.name,
    rows = scene_rows, xlabel = axis.name .. (logx and " (log scale)" or ""), ylabel = ylabel,
    logx = logx, series = series, hline = noise, noise = what == "error" and ctx.noise or nil,
    subtitle = noise and "dashed: reference " .. ctx.noise.label or nil,
  })
end

---------------------------------------------------------------- entry point

-- report.write(result [, opts]) for the result of experiment:run. opts:
-- title, error ("all.rmse", "penumbra.rmse", "all.mae", ...), time ("frame",
-- "evaluate_median", "evaluate_min"). Returns the path of index.html (nil for
-- a shard: merge the shards, then run the script with --resume).
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
  ctx.err, ctx.err_label, ctx.noise, ctx.err_path = metric_getter(opts.error or "all.rmse")
  local rows = ok_rows(result.rows)
  local axes = swept_names(rows)
  mark_swept(rows, axes)
  local plots = { time = {}, axes = {} }
  local by_variant, variant_order = group_by(rows, function(r) return r.record.scene.hash end)
  local names_used = {}
  for _, h in ipairs(variant_order) do
    local v = by_variant[h][1].variant
    local name = slug(v.scene .. (v.label ~= "" and "-" .. v.label or ""))
    if names_used[name] then name = name .. "-" .. h:sub(1, 8) end
    names_used[name] = true
    plots.time[#plots.time + 1] = { variant = v, file = error_vs_time(ctx, by_variant[h], name), rows = by_variant[h] }
  end
  local by_scene, scene_order = group_by(rows, function(r) return r.variant.file end)
  for _, f in ipairs(scene_order) do
    local scene_name = slug(by_scene[f][1].variant.scene)
    for _, axis in ipairs(axes) do
      for _, what in ipairs({ "error", "cost" }) do
        local file = along_axis(ctx, axis, by_scene[f], scene_name, what)
        if file then plots.axes[#plots.axes + 1] = { axis = axis, what = what, file = file } end
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
