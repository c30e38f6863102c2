-- report-checks.lua DIR -- a sweep's report (tests/lua/small-sweep.lua)
-- shows what its records hold: every row's timed evaluations as a spread
-- (evaluate_min <= evaluate_median <= evaluate_max in the record, and the
-- error-vs-time data carry the bar's two ends around the frame time), and
-- one signed-error scale for all of its images (the experiment's
-- error_scale, 0.5 by default) with a colour bar stating it.
local json = require "shadowlab.json"
local dir = arg[1]

local function read(path)
  local f = assert(io.open(path, "rb"), "cannot open " .. path)
  local s = f:read("a")
  f:close()
  return s
end

local lines = {}
for line in read(dir .. "/records.jsonl"):gmatch("[^\n]+") do lines[#lines + 1] = json.decode(line) end
local scales = {}
for i = 2, #lines do
  local r = lines[i]
  local t = r.record.timings_s
  if type(t.evaluate_max) ~= "number" or not (t.evaluate_min <= t.evaluate_median and t.evaluate_median <= t.evaluate_max) then
    error(string.format("row %d: evaluate min/median/max %s/%s/%s out of order", r.index, tostring(t.evaluate_min),
                        tostring(t.evaluate_median), tostring(t.evaluate_max)), 0)
  end
  scales[r.record.metrics.error_png_scale] = true
end
local n = 0
for s in pairs(scales) do
  n = n + 1
  if s ~= 0.5 then error("error image scale " .. s .. ", the experiment's is 0.5", 0) end
end
if n ~= 1 then error(n .. " error image scales", 0) end
local page = read(dir .. "/index.html")
if not page:find('<div class="key"><span>-0.5 (too dark)</span>', 1, true) then error("no colour bar of ±0.5", 0) end
-- every error-vs-time point: x, y, bar low <= x <= bar high
local dat = read(dir .. "/plots/error-vs-time-sphere-on-plane-lights-1-radius-0-2.dat")
local points = 0
for line in dat:gmatch("[^\n]+") do
  local x, _, lo, hi = line:match("^(%S+) (%S+) (%S+) (%S+)$")
  if x and not line:find('"', 1, true) then
    x, lo, hi = tonumber(x), tonumber(lo), tonumber(hi)
    if not (lo <= x and x <= hi) then error("error-vs-time bar " .. line .. " does not hold its point", 0) end
    points = points + 1
  end
end
if points == 0 then error("error-vs-time data carry no timing bars", 0) end
print("report checks: " .. points .. " bars, one error scale")
