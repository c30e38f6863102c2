-- figures.lua -- what the course-figure experiments (experiments/course-fig*.lua,
-- filtered-error-vs-time.lua) add to the standard report: curve plots of
-- quantities the report does not plot (acne and leak fractions, umbra areas,
-- 1-D step approximations), tables, and one figure.html per experiment
-- beside the report's index.html. A plot's spec takes the rows it shows
-- (spec.rows: plot.lua states their scene, resolution, reference samples and
-- noise) or, for closed-form curves, spec.analytic. Loaded with
--   local figures = dofile(sl.root .. "/experiments/lib/figures.lua")
local sl = require "shadowlab"
local plot = require "shadowlab.plot"

local figures = {}

local function esc(s)
  return (tostring(s):gsub("&", "&amp;"):gsub("<", "&lt;"):gsub(">", "&gt;"))
end

-- A page under construction: page:text(html), page:plot(name, spec),
-- page:table(header, rows), page:write() -> OUT/figure.html.
function figures.page(out, title, intro)
  local self = { out = out, parts = { "<h1>" .. esc(title) .. "</h1>", "<p>" .. esc(intro) .. "</p>",
                                      '<p>The sweep itself: <a href="index.html">index.html</a> (every configuration, ' ..
                                      'its record and images beside the reference).</p>' } }
  function self:text(html) self.parts[#self.parts + 1] = html end
  function self:heading(t) self.parts[#self.parts + 1] = "<h2>" .. esc(t) .. "</h2>" end
  function self:note(t) self.parts[#self.parts + 1] = "<p>" .. esc(t) .. "</p>" end
  function self:plot(name, spec)
    local files = plot.draw(out .. "/plots", name, spec)
    self.parts[#self.parts + 1] = string.format('<figure><img src="%s" alt="%s"><figcaption>%s (<a href="%s">svg</a>, ' ..
                                                'data and gnuplot script beside it)</figcaption></figure>',
                                                files.png, esc(spec.title), esc(spec.title), files.svg)
  end
  function self:table(header, rows)
    local t = { "<table><tr>" }
    for _, h in ipairs(header) do t[#t + 1] = "<th>" .. esc(h) .. "</th>" end
    t[#t + 1] = "</tr>"
    for _, r in ipairs(rows) do
      t[#t + 1] = "<tr>"
      for _, c in ipairs(r) do t[#t + 1] = "<td>" .. esc(c) .. "</td>" end
      t[#t + 1] = "</tr>"
    end
    t[#t + 1] = "</table>"
    self.parts[#self.parts + 1] = table.concat(t)
  end
  function self:write()
    local style = "body{font-family:sans-serif;max-width:1000px;margin:2em auto}img{max-width:100%}" ..
                  "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
    local html = '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>' .. esc(title) ..
                 "</title><style>" .. style .. "</style></head><body>\n" .. table.concat(self.parts, "\n") ..
                 "\n</body></html>\n"
    sl.write_file(out .. "/figure.html", html)
    io.stderr:write("figure: " .. out .. "/figure.html\n")
  end
  return self
end

-- Rows of an experiment result that ran (each configuration once), grouped by a key function, each
-- group sorted by x(row); returns { {key = k, rows = {...}}, ... } in first-seen order.
function figures.group(result, key_of, x_of)
  local groups, order, seen = {}, {}, {}
  for _, r in ipairs(result.rows) do
    if r.status == "ok" and not seen[r.key] then
      seen[r.key] = true
      local k = key_of(r)
      if not groups[k] then groups[k] = {}; order[#order + 1] = k end
      table.insert(groups[k], r)
    end
  end
  local out = {}
  for _, k in ipairs(order) do
    table.sort(groups[k], function(a, b) return x_of(a) < x_of(b) end)
    out[#out + 1] = { key = k, rows = groups[k] }
  end
  return out
end

-- Fraction of the light-facing samples the record counts as acne / leaks.
function figures.acne(r)
  local m = r.record.metrics
  return m.false_shadow / m.samples.lit_candidate
end
function figures.leaks(r)
  local m = r.record.metrics
  return m.false_lit / m.samples.lit_candidate
end

-- Umbra (V <= 0.01) and penumbra (0.01 < V < 0.99) fractions of the light-
-- facing samples (the lit candidates, class 1) in a run's visibility and in
-- its reference.
function figures.areas(run)
  local vis, ref, cls = run:image("visibility"), run:image("reference"), run:image("class")
  local w, h = vis:size()
  local n, a = 0, { umbra = 0, penumbra = 0, ref_umbra = 0, ref_penumbra = 0 }
  for y = 1, h do
    for x = 1, w do
      if cls:get(x, y) == 1 then
        n = n + 1
        local v, r = vis:get(x, y), ref:get(x, y)
        if v <= 0.01 then a.umbra = a.umbra + 1 elseif v < 0.99 then a.penumbra = a.penumbra + 1 end
        if r <= 0.01 then a.ref_umbra = a.ref_umbra + 1 elseif r < 0.99 then a.ref_penumbra = a.ref_penumbra + 1 end
      end
    end
  end
  for k, v in pairs(a) do a[k] = v / math.max(n, 1) end
  a.candidates = n
  return a
end

-- Bits per texel of a configuration's moment map (its bytes in the record's
-- resource log over the depth map's texels, times 8); 32 for a bare depth map.
function figures.bits_per_texel(r)
  local map, moments
  for _, ev in ipairs(r.record.technique_resources or {}) do
    if ev.kind == "shadow_map" and not map then map = ev.bytes end
    if ev.kind == "moments" then moments = ev.bytes end
  end
  if not map then return nil end
  return moments and 32 * moments / map or 32
end

return figures
