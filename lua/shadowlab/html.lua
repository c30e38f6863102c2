-- html.lua -- the report's index.html: one file with its style inline and
-- only relative links (plots, images, results.csv, records.jsonl), so it
-- opens from disk and from any copy of the folder. A small inline script
-- checks on load that every image arrived and says so at the top of the page
-- (the browser test reads that line).
local sl = package.loaded.shadowlab or require "shadowlab"
local records = require "shadowlab.records"
local inspector = require "shadowlab.inspector"

local html = {}

local function esc(s)
  return (tostring(s):gsub("[&<>\"']", { ["&"] = "&amp;", ["<"] = "&lt;", [">"] = "&gt;", ['"'] = "&quot;",
                                         ["'"] = "&#39;" }))
end
html.escape = esc

local style = [[
body { font: 14px/1.45 sans-serif; margin: 1.5em auto; max-width: 1200px; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { margin-top: 2em; border-bottom: 1px solid #ccc; } h3 { margin-bottom: .3em; }
table { border-collapse: collapse; font-size: 12px; } td, th { border: 1px solid #ddd; padding: 2px 6px; }
th { background: #f3f3f3; } td.n { text-align: right; font-variant-numeric: tabular-nums; }
tr.front td { background: #eef7ee; } tr.err td { background: #fbeaea; } .unres { color: #a33; }
details { font-size: 11px; color: #555; } summary { cursor: pointer; }
.plots { display: grid; grid-template-columns: repeat(auto-fill, minmax(480px, 1fr)); gap: 8px; }
.plots img { width: 100%; border: 1px solid #eee; }
.grid { display: grid; grid-template-columns: repeat(3, minmax(0, 1fr)); gap: 10px; }
.grid figure { margin: 0; font-size: 11px; } .grid img { width: 100%; image-rendering: pixelated; }
.key { display: flex; gap: 8px; align-items: center; font-size: 12px; margin: .5em 0; }
.key .bar { display: inline-block; width: 240px; height: 14px; border: 1px solid #999;
            background: linear-gradient(to right, rgb(0,0,255), rgb(255,255,255), rgb(255,0,0)); }
.ref { outline: 3px solid #444; } #load-status { font-weight: bold; } .note { color: #555; }
]]

local check_script = [[
<script>
window.addEventListener("load", function () {
  var imgs = document.images, missing = [];
  for (var i = 0; i < imgs.length; i++)
    if (!imgs[i].complete || imgs[i].naturalWidth === 0) missing.push(imgs[i].getAttribute("src"));
  var s = document.getElementById("load-status");
  s.setAttribute("data-images", String(imgs.length));
  s.setAttribute("data-missing", String(missing.length));
  s.textContent = missing.length ? "images missing: " + missing.join(", ") : "all " + imgs.length + " images loaded";
});
</script>
]]

local function num(v, fmt)
  if type(v) ~= "number" then return "" end
  return string.format(fmt, v)
end

local function params_text(params, keys)
  local parts = {}
  for i, k in ipairs(keys) do parts[i] = k .. "=" .. tostring(params[k]) end
  return table.concat(parts, " ")
end

local function sorted_keys(t)
  local keys = {}
  for k in pairs(t or {}) do keys[#keys + 1] = k end
  table.sort(keys)
  return keys
end

-- The parameters of a row that differ from its technique's registry
-- defaults (the rest is folded away in the table).
local function non_default_keys(r)
  local ok, desc = pcall(sl.technique, r.technique)
  local default = {}
  if ok then
    for _, p in ipairs(desc.params) do default[p.name] = p.default end
  end
  local keys = {}
  for _, k in ipairs(sorted_keys(r.params)) do
    local d, v = default[k], r.params[k]
    local same
    if type(d) == "number" and type(v) == "number" then same = d == v else same = tostring(d) == tostring(v) end
    if d == nil or not same then keys[#keys + 1] = k end
  end
  return keys
end

-- The regions the table shows, each with its RMSE. A region's error is
-- unresolved where the reference's noise there exceeds half of it (the
-- record's resolved: RMSE above twice the noise rms); an error of exactly
-- 0 against a noiseless reference is resolved by definition.
local regions = { "umbra", "penumbra", "lit", "terminator", "all" }

local function unresolved(m)
  return type(m) == "table" and m.resolved == false and type(m.noise_rms) == "number" and m.noise_rms > 0
end

local function region_cell(m)
  if type(m) ~= "table" or type(m.rmse) ~= "number" then return '<td class="n">-</td>' end
  if unresolved(m) then
    return string.format('<td class="n unres" title="noise rms %.5f">%.5f unresolved</td>', m.noise_rms, m.rmse)
  end
  return string.format('<td class="n">%.5f</td>', m.rmse)
end

-- The error plotted, as its own column unless it is one of the region RMSEs.
local function plotted_region(doc)
  local region, field = (doc.err_path or "all.rmse"):match("^(%w+)%.([%w_]+)$")
  if field == "rmse" then return region end
  return nil
end

-- Was the machine loaded beyond its cores when the row was timed?
local function overloaded(r)
  return type(r.load) == "table" and type(r.load.loadavg_1min) == "number" and type(r.load.cores) == "number" and
         r.load.loadavg_1min > r.load.cores
end

-- The report's note on rows timed under load (nil when none was).
local function load_note(doc)
  local n, top, cores = 0, 0, nil
  for _, r in ipairs(doc.ok_rows) do
    if overloaded(r) then
      n, cores = n + 1, r.load.cores
      top = math.max(top, r.load.loadavg_1min)
    end
  end
  if n == 0 then return nil end
  return string.format('<p class="note load"><b>Load:</b> %d of %d rows were timed while the machine\'s 1-minute ' ..
                       "load average exceeded its %d cores (up to %.2f; marked \"loaded\" in the table): other " ..
                       "processes shared the cores, so their times are longer and coarser than on an idle machine " ..
                       "(evaluation medians have been seen quantised in 4 ms steps under load).</p>", n,
                       #doc.ok_rows, cores, top)
end

local function results_table(doc, out)
  -- the reference noise of the error shown (its region and statistic), else the whole image's rms
  local noise = doc.noise or { label = "noise rms", value = function(rec) return rec.metrics.all.noise_rms end }
  local shown = plotted_region(doc)
  local head = { "#", "scene", "configuration" }
  if not shown then head[#head + 1] = esc(doc.err_label) end
  for _, g in ipairs(regions) do
    head[#head + 1] = g .. " RMSE" .. (g == shown and " (plotted)" or "")
  end
  for _, h in ipairs({ "fraction |error| &gt; 0.5", esc(noise.label), "reference penumbra samples",
                       esc(doc.time_label) .. " ms", "eval median ms", "eval min ms", "build ms", "resources",
                       "reference", "parameters (non-default; all folded)" }) do
    head[#head + 1] = h
  end
  out[#out + 1] = "<table><tr><th>" .. table.concat(head, "</th><th>") .. "</th></tr>"
  for _, r in ipairs(doc.rows) do
    local where = esc(r.variant.scene .. (r.variant.label ~= "" and " [" .. r.variant.label .. "]" or ""))
    if r.status ~= "ok" then
      out[#out + 1] = string.format('<tr class="err"><td class="n">%d</td><td>%s</td><td>%s</td><td colspan="%d">%s</td></tr>',
                                    r.index, where, esc(r.label), #head - 3, esc(r.error or "failed"))
    else
      local m, t, rec = r.record.metrics, r.record.timings_s, r.record
      local cells = { string.format('<td class="n">%d</td><td>%s</td><td>%s</td>', r.index, where, esc(r.label)) }
      if not shown then cells[#cells + 1] = '<td class="n">' .. num(doc.err(r), "%.5f") .. "</td>" end
      for _, g in ipairs(regions) do cells[#cells + 1] = region_cell(m[g]) end
      local pen = m.penumbra
      local changed, all = non_default_keys(r), sorted_keys(r.params)
      cells[#cells + 1] = string.format(
        '<td class="n">%s</td><td class="n">%s</td><td class="n">%s</td><td class="n">%s</td><td class="n">%s</td>' ..
        '<td class="n">%s</td><td class="n">%s</td><td>%s</td><td>%s</td>' ..
        '<td>%s<details><summary>all %d</summary>%s</details></td>',
        num(m.all.misclassified, "%.4f"), num(noise.value(rec), "%.5f"),
        type(pen) == "table" and num(pen.count, "%d") or "",
        num(1e3 * t[doc.time], "%.3f") .. (overloaded(r) and
          string.format(' <span class="unres" title="load average %.2f on %d cores">loaded</span>',
                        r.load.loadavg_1min, r.load.cores) or ""),
        num(1e3 * t.evaluate_median, "%.3f"), num(1e3 * t.evaluate_min, "%.3f"), num(1e3 * t.technique_build, "%.3f"),
        esc(rec.resource_cache), esc(rec.reference.origin), #changed > 0 and esc(params_text(r.params, changed)) or "defaults",
        #all, esc(params_text(r.params, all)))
      out[#out + 1] = "<tr" .. (r.on_front and ' class="front"' or "") .. ">" .. table.concat(cells) .. "</tr>"
    end
  end
  out[#out + 1] = "</table>"
end

local function plot_block(p, out)
  if not p then return end
  out[#out + 1] = string.format('<p><img src="%s" alt="%s"><br><a href="%s">PNG</a> · <a href="%s">SVG</a></p>',
                                esc(p.svg), esc(p.svg), esc(p.png), esc(p.svg))
end

-- A figure; `inspect` (a row) makes its image open the pixel inspector on
-- that configuration (inspector.lua).
local function figure(src, caption, class, inspect)
  local attrs = class and ' class="' .. class .. '"' or ""
  if inspect then
    attrs = attrs .. string.format(' data-inspect="%s" data-ref="%s" data-est="%s" data-err="%s" data-label="%s"',
                                   esc(inspect.key), esc(inspect.images.reference), esc(inspect.images.visibility),
                                   esc(inspect.images.error), esc(inspect.label))
  end
  return string.format('<figure><img src="%s" alt="%s"%s><figcaption>%s</figcaption></figure>', esc(src),
                       esc(caption), attrs, caption)
end

-- The signed-error images' scales (the record's error_png_scale), sorted.
local function error_scales(rows)
  local set, list = {}, {}
  for _, r in ipairs(rows) do
    local v = r.images and r.record.metrics.error_png_scale
    if type(v) == "number" and not set[v] then set[v], list[#list + 1] = true, v end
  end
  table.sort(list)
  return list
end

-- The colour bar of the error images, the same ramp report.c's
-- error_colors writes: blue at -scale (too dark), white at 0, red at
-- +scale (leaking), clamped beyond; grey: not a lit candidate.
local function error_key(doc, out)
  local scales = error_scales(doc.ok_rows)
  if #scales == 0 then return end
  if #scales > 1 then
    out[#out + 1] = '<p class="note">The error images do not share one scale (±' .. table.concat(scales, ", ±") ..
                    "; rows from runs with another error_scale): compare them by their captions.</p>"
    return
  end
  local s = scales[1]
  out[#out + 1] = string.format('<div class="key"><span>-%g (too dark)</span><span class="bar" title="signed error: ' ..
                                'estimate - reference"></span><span>+%g (leaking)</span> <span class="note">signed ' ..
                                "error of every image below, one scale for the whole report; clamped beyond ±%g; " ..
                                "grey: not a lit sample</span></div>", s, s, s)
end

-- The images of one scene variant: the reference first (shaded and
-- visibility), then every configuration's shaded image, visibility and
-- signed error, three to a row.
local function image_grid(entry, doc, out)
  local first
  for _, r in ipairs(entry.rows) do first = first or (r.images and r) end
  if not first then return end
  out[#out + 1] = '<div class="grid">'
  out[#out + 1] = figure(first.images.reference_shaded, "reference, shaded", "ref")
  out[#out + 1] = figure(first.images.reference, "reference visibility (" ..
                         esc(first.record.reference.samples) .. " samples)", "ref")
  out[#out + 1] = '<p class="note">Each configuration below: shaded, visibility, signed error (estimate - ' ..
                  "reference; blue too dark, red leaking). Click one to inspect its pixels: reference, estimate " ..
                  "and signed error at single-pixel zoom, the values under the cursor.</p>"
  for _, r in ipairs(entry.rows) do
    if r.images then -- rows resumed from a run with --no-images have none
      local cap = esc(r.label) .. ": " .. esc(doc.err_label) .. " " .. num(doc.err(r), "%.4f")
      out[#out + 1] = figure(r.images.shaded, esc(r.label) .. ": shaded", nil, r)
      out[#out + 1] = figure(r.images.visibility, cap, nil, r)
      out[#out + 1] = figure(r.images.error, esc(r.label) .. ": signed error, ±" ..
                             num(r.record.metrics.error_png_scale, "%g") .. " (blue too dark, red leaking)", nil, r)
    end
  end
  out[#out + 1] = "</div>"
end

-- Every build the rows were measured with (one, unless --mixed-builds), with
-- its row count when there are several.
local function machine_text(doc)
  local builds = records.builds(doc.ok_rows)
  if #builds == 0 then return "no successful configuration" end
  if #builds == 1 then return esc(builds[1].text) end
  local parts = {}
  for _, b in ipairs(builds) do parts[#parts + 1] = string.format("%s (%d rows)", esc(b.text), b.rows) end
  return "<b>mixed builds</b>: " .. table.concat(parts, "; ")
end

local definitions = [[
<p class="note"><b>Frame time</b> = the build time of every resource the technique's prepare depends
on (a shadow map is re-rendered each frame in a renderer, so its logged build time counts even when this
run reused it), plus the prepare's own set-up, plus the median of the timed evaluations (after the
warm-up). It leaves out the engine's view samples (a renderer's G-buffer) and the reference.
<b>Error</b> is measured over light-facing, non-background view samples against the Embree reference;
the reference's own noise (rms of its standard errors) is shown beside it, and errors near it are not
resolved: a region's RMSE is marked <b>unresolved</b> where the reference's noise there exceeds half of it.
Resource build and evaluation times are listed separately; "cold" means this configuration
built a resource, "warm" that it reused every one.</p>
<p class="note"><b>CPU times are not GPU times.</b> Every technique runs on this machine's CPU: <code>hard</code>
(one Embree ray per pixel) is the cheapest technique here, and the prefiltered maps (vsm, evsm, msm, csm) pay
for building 64-bit moment maps and summed-area tables on the CPU, which inverts the usual GPU ranking. Compare
costs within a technique (how they grow with a parameter), not across families.</p>
]]

-- The lab's questions and notes (opts.questions, opts.notes: lists of
-- strings), at the top of the report they are answered from.
local function questions_block(opts, out)
  if opts.questions and #opts.questions > 0 then
    out[#out + 1] = '<h2>Questions</h2><ol class="questions">'
    for _, q in ipairs(opts.questions) do out[#out + 1] = "<li>" .. esc(q) .. "</li>" end
    out[#out + 1] = "</ol>"
  end
  for _, n in ipairs(opts.notes or {}) do out[#out + 1] = '<p class="note"><b>Note:</b> ' .. esc(n) .. "</p>" end
  -- a script's own sections ({title, html}: html it wrote, escaped by it), before the plots
  for _, sec in ipairs(opts.sections or {}) do
    out[#out + 1] = "<h2>" .. esc(sec.title) .. "</h2>"
    out[#out + 1] = sec.html
  end
end

function html.write_index(path, doc)
  local res, h = doc.result, doc.result.header
  local s = h.settings
  local out = { "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
                "<title>" .. esc(doc.opts.title or h.name) .. "</title>", "<style>" .. style .. "</style>",
                "</head><body>" }
  out[#out + 1] = "<h1>" .. esc(doc.opts.title or h.name) .. "</h1>"
  if res.experiment.description then out[#out + 1] = "<p>" .. esc(res.experiment.description) .. "</p>" end
  out[#out + 1] = '<p id="load-status">checking images…</p>'
  out[#out + 1] = string.format("<p>Experiment <code>%s</code> (fingerprint %s): %d configurations, %d failed. " ..
                                "Reference: %d %s light samples, seed %d, light %d. Timing: %d warm-up + %d " ..
                                "timed evaluations, the timed ones stopping after %g s. Machine: %s.</p>",
                                esc(h.name), esc(h.fingerprint), #doc.rows, #doc.rows - #doc.ok_rows, s.samples,
                                esc(s.pattern), s.seed, s.light, s.warmup, s.repeats, s.time_budget_s or 0,
                                machine_text(doc))
  out[#out + 1] = '<p>Data: <a href="results.csv">results.csv</a> · <a href="records.jsonl">records.jsonl</a> ' ..
                  "(one JSON record per configuration, with every parameter, timing and resource).</p>"
  out[#out + 1] = definitions
  out[#out + 1] = load_note(doc)
  questions_block(doc.opts, out)
  if doc.opts.reproduction then out[#out + 1] = doc.opts.reproduction.html end -- reproduce.compare's table
  out[#out + 1] = "<h2>" .. esc(doc.err_label) .. " against " .. esc(doc.time_label) .. "</h2><div class=\"plots\">"
  plot_block(doc.plots.combined, out)
  for _, p in ipairs(doc.plots.time) do plot_block(p.file, out) end
  out[#out + 1] = "</div>"
  if #doc.plots.work > 0 then
    out[#out + 1] = "<h2>" .. esc(doc.err_label) .. " against machine-independent work</h2>" ..
                    "<p class=\"note\">Counted, not timed (the record's <code>work</code> block): texel fetches, " ..
                    "rays, triangles and texels rasterised, bytes built and read, per lit candidate or per frame; " ..
                    "what a technique costs on another machine, a GPU included.</p><div class=\"plots\">"
    for _, p in ipairs(doc.plots.work) do plot_block(p.file, out) end
    out[#out + 1] = "</div>"
  end
  if #doc.plots.axes > 0 then
    out[#out + 1] = "<h2>Against the swept parameters</h2><div class=\"plots\">"
    for _, p in ipairs(doc.plots.axes) do plot_block(p.file, out) end
    out[#out + 1] = "</div>"
  end
  out[#out + 1] = "<h2>Results</h2><p class=\"note\">Green rows are on the Pareto front of their scene.</p>"
  results_table(doc, out)
  out[#out + 1] = "<h2>Images beside the reference</h2>"
  error_key(doc, out)
  for _, p in ipairs(doc.plots.time) do
    local v = p.variant
    out[#out + 1] = "<h3>" .. esc(v.scene .. (v.label ~= "" and " [" .. v.label .. "]" or "")) .. "</h3>"
    image_grid(p, doc, out)
  end
  out[#out + 1] = inspector.html
  out[#out + 1] = check_script
  out[#out + 1] = "</body></html>"
  sl.write_file(path, table.concat(out, "\n") .. "\n")
end

return html
