-- figure.lua CSV COLUMN LO HI [COL~TEXT ...] [--hold] -- does an experiment's
-- written table hold a computed figure in its expected range? Every row of
-- CSV (those whose column COL contains TEXT, for each filter given) must have
-- a finite COLUMN in [LO, HI], and at least one row must; with --hold their
-- verdict column (reproduce.lua's tables) must also be no failed comparison,
-- and for any reproduction table the verdicts must not all be failures (unless
-- --may-all-differ: a reproduction whose claims all differ at full size too,
-- said where it is used). So a computation that breaks (NaN, a zero, a
-- swapped ratio) fails tests/lua/run.sh.
-- Prints "figures checked: N rows"; returns 1 with the offending row otherwise.
local reproduce = require "shadowlab.reproduce"

local path, column, lo, hi = arg[1], arg[2], tonumber(arg[3] or ""), tonumber(arg[4] or "")
if not (path and column and lo and hi) then
  io.stderr:write("usage: figure.lua CSV COLUMN LO HI [COL~TEXT ...] [--hold | --may-all-differ]\n")
  return 2
end
local filters, hold, may_all_differ = {}, false, false
for i = 5, #arg do
  if arg[i] == "--hold" then hold = true
  elseif arg[i] == "--may-all-differ" then may_all_differ = true
  else
    local col, text = arg[i]:match("^([^~]+)~(.*)$")
    if not col then io.stderr:write("figure.lua: a filter is COL~TEXT, got '" .. arg[i] .. "'\n"); return 2 end
    filters[#filters + 1] = { col = col, text = text }
  end
end

-- One CSV line into fields (RFC 4180 quotes: "a, b" and "" inside them).
local function fields(line)
  local out, i = {}, 1
  while i <= #line + 1 do
    if line:sub(i, i) == '"' then
      local value, j = {}, i + 1
      while true do
        local q = line:find('"', j, true)
        if not q then error("unterminated quote in: " .. line, 0) end
        value[#value + 1] = line:sub(j, q - 1)
        if line:sub(q + 1, q + 1) == '"' then value[#value + 1] = '"'; j = q + 2 else i = q + 2; break end
      end
      out[#out + 1] = table.concat(value)
    else
      local c = line:find(",", i, true) or #line + 1
      out[#out + 1] = line:sub(i, c - 1)
      i = c + 1
    end
  end
  return out
end

local f = io.open(path)
if not f then io.stderr:write("figure.lua: cannot open " .. path .. "\n"); return 1 end
local header, rows = nil, {}
for line in f:lines() do
  if not header then header = {}; for c, name in ipairs(fields(line)) do header[name] = c end
  else rows[#rows + 1] = fields(line) end
end
f:close()
local function need(name)
  if not (header and header[name]) then error(string.format("%s has no column '%s'", path, name), 0) end
  return header[name]
end
local col, verdict = need(column), header and header.verdict
for _, flt in ipairs(filters) do flt.c = need(flt.col) end
if hold then need("verdict") end

local checked, failed_verdicts = 0, 0
for _, r in ipairs(rows) do
  if verdict and reproduce.failed(r[verdict]) then failed_verdicts = failed_verdicts + 1 end
  local mine = true
  for _, flt in ipairs(filters) do mine = mine and r[flt.c]:find(flt.text, 1, true) ~= nil end
  if mine then
    local v = tonumber(r[col])
    local line = table.concat(r, ",")
    if not v or v ~= v or v < lo or v > hi then
      io.stderr:write(string.format("figure.lua: %s: %s = %s, expected a finite value in [%g, %g]: %s\n", path,
                                    column, r[col], lo, hi, line))
      return 1
    end
    if hold and reproduce.failed(r[verdict]) then
      io.stderr:write(string.format("figure.lua: %s: verdict '%s': %s\n", path, r[verdict], line))
      return 1
    end
    checked = checked + 1
  end
end
if checked == 0 then io.stderr:write("figure.lua: " .. path .. ": no row matched\n"); return 1 end
if verdict and failed_verdicts == #rows and not may_all_differ then
  io.stderr:write("figure.lua: " .. path .. ": every verdict is a failure\n")
  return 1
end
print(string.format("figures checked: %d rows of %s", checked, path))
return 0
