-- reproduce.lua -- the side-by-side table of a reproduction: per item the
-- paper's value, the measured value, their ratio (measured / paper) and a
-- verdict under a rule stated per item. Every reproduction experiment
-- (experiments/seed*.lua, course-fig*.lua, fig3-*.lua) reports through
--   local rep = reproduce.compare(rows, { out = DIR, title = "...", note = "..." })
-- which prints the table aligned, writes DIR/reproduction.csv and
-- DIR/reproduction.md, and returns { rows = judged rows, html = a <table> }
-- for the experiment's HTML (report.write's opts.reproduction, or a
-- figures.lua page's text). A row:
--   { item = "software, 512^2 / 256^2", quantity = "frame time ratio", unit = "",
--     paper = 1.796, measured = 2.1, rule = reproduce.trend(0.25, "why"),
--     source = "seed 003 Table 1" }
-- paper is the paper's value (cite it in source: table or figure of the
-- seed), or the bound of a claim (below/above: "closer to the reference
-- than PCSS" is an error ratio below 1). measured nil or NaN is judged
-- "not measured": it never becomes a value.
local sl = require "shadowlab"

local reproduce = {}

local function finite(x) return type(x) == "number" and x == x and x ~= math.huge and x ~= -math.huge end

-- A value as the table shows it: %.4g, NaN as "nan" (not the C library's "-nan"), nil as "missing".
local function shown(x, fmt)
  if x == nil then return "missing" end
  if x ~= x then return "nan" end
  return type(x) == "number" and string.format(fmt or "%.4g", x) or tostring(x)
end

-- measured / paper, NaN where it is undefined (a paper value of 0, a missing measurement).
local function ratio(paper, measured)
  if not (finite(paper) and finite(measured)) or paper == 0 then return 0 / 0 end
  return measured / paper
end

local function pct(tol) return string.format("%g%%", 100 * tol) end

---------------------------------------------------------------- rules

-- Each rule: text (what it checks, for the table), why (its reason), shows
-- (how the paper column reads) and judge(paper, measured) -> verdict.

-- The same quantity, expected equal within a relative tolerance:
-- |measured / paper - 1| <= tol.
function reproduce.within(tol, why)
  return { text = "within " .. pct(tol), why = why, shows = function(p) return string.format("%.4g", p) end,
           judge = function(p, m)
             local r = ratio(p, m)
             return math.abs(r - 1) <= tol and "matches within " .. pct(tol) or string.format("differs (x%.3g)", r)
           end }
end

-- The same quantity where setting or scene differ from the paper's:
-- 1/f <= measured / paper <= f.
function reproduce.factor(f, why)
  return { text = string.format("within a factor %g", f), why = why,
           shows = function(p) return string.format("%.4g", p) end,
           judge = function(p, m)
             local r = ratio(p, m)
             return (r >= 1 / f and r <= f) and string.format("matches within a factor %g", f) or
                    string.format("differs (x%.3g)", r)
           end }
end

-- A relative value (a ratio to a base row of the same series, e.g. frame
-- time at 1024^2 over 256^2): the trend matches when measured and paper lie
-- on the same side of 1 (both grow or both shrink); within tol (optional)
-- it also matches in size.
function reproduce.trend(tol, why)
  return { text = "same side of 1" .. (tol and ", size within " .. pct(tol) or ""), why = why,
           shows = function(p) return string.format("%.4g", p) end,
           judge = function(p, m)
             if (p - 1) * (m - 1) <= 0 and not (p == 1 and m == 1) then return "trend differs" end
             local r = ratio(p, m)
             return (tol and math.abs(r - 1) <= tol) and "trend matches within " .. pct(tol) or "trend matches"
           end }
end

-- A claim that the measured value lies below (above) the paper's bound.
local function claim(sign, why)
  local op = sign < 0 and "<" or ">"
  return { text = "claim: measured " .. op .. " bound", why = why,
           shows = function(p) return string.format("%s %.4g", op, p) end,
           judge = function(p, m) return (sign * (m - p) > 0) and "claim holds" or "differs" end }
end
function reproduce.below(why) return claim(-1, why) end
function reproduce.above(why) return claim(1, why) end

---------------------------------------------------------------- the table

local function judge(row)
  assert(type(row.item) == "string", "reproduce: a row needs item (text)")
  assert(finite(row.paper), "reproduce: row '" .. row.item .. "': paper must be a finite number (cite it in source)")
  assert(type(row.rule) == "table" and row.rule.judge, "reproduce: row '" .. row.item .. "': rule missing")
  assert(type(row.source) == "string", "reproduce: row '" .. row.item .. "': source (the paper's table or figure) missing")
  local j = {}
  for k, v in pairs(row) do j[k] = v end
  j.ratio = ratio(row.paper, row.measured)
  j.verdict = finite(row.measured) and row.rule.judge(row.paper, row.measured) or "not measured"
  j.paper_text = row.rule.shows(row.paper)
  j.measured_text = shown(row.measured)
  j.ratio_text = j.ratio == j.ratio and string.format("%.3g", j.ratio) or "-"
  j.quantity_text = (row.quantity or "") .. ((row.unit and row.unit ~= "") and " (" .. row.unit .. ")" or "")
  return j
end

-- Is a verdict a failed comparison? (tests/lua reads the CSV with it)
function reproduce.failed(verdict)
  return verdict:find("^differs") ~= nil or verdict:find("^trend differs") ~= nil or verdict == "not measured"
end

local COLUMNS = { { "item", "item" }, { "quantity", "quantity_text" }, { "paper", "paper_text" },
                  { "measured", "measured_text" }, { "measured / paper", "ratio_text" }, { "verdict", "verdict" },
                  { "source", "source" } }

local function aligned(rows)
  local width = {}
  for c, col in ipairs(COLUMNS) do
    width[c] = utf8.len(col[1])
    for _, r in ipairs(rows) do width[c] = math.max(width[c], utf8.len(r[col[2]])) end
  end
  local function line(cells)
    local t = {}
    for c, v in ipairs(cells) do t[c] = v .. string.rep(" ", width[c] - utf8.len(v)) end
    return (table.concat(t, "  "):gsub("%s+$", ""))
  end
  local head, out = {}, {}
  for c, col in ipairs(COLUMNS) do head[c] = col[1] end
  out[1] = line(head)
  for _, r in ipairs(rows) do
    local cells = {}
    for c, col in ipairs(COLUMNS) do cells[c] = r[col[2]] end
    out[#out + 1] = line(cells)
  end
  return out
end

local function csv_field(v)
  v = tostring(v)
  return v:find('[,"\n]') and '"' .. v:gsub('"', '""') .. '"' or v
end

local function csv_number(x) return x == nil and "" or shown(x, "%.6g") end

local function esc(s) return (tostring(s):gsub("&", "&amp;"):gsub("<", "&lt;"):gsub(">", "&gt;")) end

-- The rules in use, each once, with their reasons.
local function rule_notes(rows)
  local notes, seen = {}, {}
  for _, r in ipairs(rows) do
    local text = r.rule.text .. (r.rule.why and ": " .. r.rule.why or "")
    if not seen[text] then seen[text] = true; notes[#notes + 1] = text end
  end
  return notes
end

-- reproduce.compare(rows, opts): opts.out (folder), opts.title, opts.note
-- (the setting: sizes, samples, what differs from the paper), opts.name
-- (file stem, "reproduction"), opts.quiet (print nothing). Returns { rows, html, failed = count }.
function reproduce.compare(rows, opts)
  assert(opts and opts.out and opts.title, "reproduce.compare(rows, {out =, title =})")
  local judged, failed = {}, 0
  for i, r in ipairs(rows) do
    judged[i] = judge(r)
    if reproduce.failed(judged[i].verdict) then failed = failed + 1 end
  end
  local notes = rule_notes(judged)
  local text = { "", "== " .. opts.title .. ": paper against measured ==" }
  if opts.note then text[#text + 1] = opts.note end
  for _, l in ipairs(aligned(judged)) do text[#text + 1] = l end
  text[#text + 1] = "rules: " .. table.concat(notes, "; ")
  text[#text + 1] = string.format("%d items, %d differ or were not measured", #judged, failed)
  if not opts.quiet then io.stdout:write(table.concat(text, "\n"), "\n") end

  local csv = { "item,quantity,unit,paper,measured,ratio,rule,verdict,source" }
  local md = { "# " .. opts.title .. ": paper against measured", "" }
  if opts.note then md[#md + 1] = opts.note; md[#md + 1] = "" end
  md[#md + 1] = "| item | quantity | paper | measured | measured / paper | verdict | source |"
  md[#md + 1] = "|---|---|---:|---:|---:|---|---|"
  local html = { "<table class=\"reproduction\"><tr>" }
  for _, col in ipairs(COLUMNS) do html[#html + 1] = "<th>" .. esc(col[1]) .. "</th>" end
  html[#html + 1] = "</tr>"
  for _, r in ipairs(judged) do
    csv[#csv + 1] = table.concat({ csv_field(r.item), csv_field(r.quantity or ""), csv_field(r.unit or ""),
                                   csv_number(r.paper), csv_number(r.measured), csv_number(r.ratio),
                                   csv_field(r.rule.text), csv_field(r.verdict), csv_field(r.source) }, ",")
    md[#md + 1] = string.format("| %s | %s | %s | %s | %s | %s | %s |", r.item, r.quantity_text, r.paper_text,
                                r.measured_text, r.ratio_text, r.verdict, r.source)
    html[#html + 1] = "<tr>"
    for _, col in ipairs(COLUMNS) do html[#html + 1] = "<td>" .. esc(r[col[2]]) .. "</td>" end
    html[#html + 1] = "</tr>"
  end
  html[#html + 1] = "</table><p class=\"note\">Rules: " .. esc(table.concat(notes, "; ")) .. "</p>"
  md[#md + 1] = ""
  md[#md + 1] = "Rules: " .. table.concat(notes, "; ") .. "."
  local name = opts.name or "reproduction"
  sl.mkdir(opts.out)
  sl.write_file(opts.out .. "/" .. name .. ".csv", table.concat(csv, "\n") .. "\n")
  sl.write_file(opts.out .. "/" .. name .. ".md", table.concat(md, "\n") .. "\n")
  if not opts.quiet then io.stdout:write("reproduction: " .. opts.out .. "/" .. name .. ".csv\n") end
  return { rows = judged, html = "<h2>" .. esc(opts.title) .. ": paper against measured</h2>" ..
                                 (opts.note and "<p>" .. esc(opts.note) .. "</p>" or "") .. table.concat(html),
           failed = failed }
end

return reproduce
