-- inspector-check.lua pick DIR | check DIR DOM -- the pixel inspector of a
-- sweep's report (tests/lua/small-sweep.lua) against the engine. `pick`
-- recomputes the first configuration and prints a penumbra pixel "X,Y"
-- (0-based) for the page's #inspect-test; `check` reads what the page
-- wrote into #inspect-result (DOM: chromium --dump-dom) after opening that
-- configuration, flipping twice and hovering the pixel, and checks the
-- layers it flipped through, the estimate, reference, standard error and
-- class it read against the recomputed run (within the u16 steps of its
-- data), and the RMSE over its data against the record's.
local sl = require "shadowlab"
local records = require "shadowlab.records"

local mode, dir, dom = arg[1], arg[2], arg[3]
local header, rows = records.read(dir .. "/records.jsonl")
local row
for _, r in ipairs(rows) do
  if r.status == "ok" and r.images and (not row or r.index < row.index) then row = r end
end
if not row then error("no configuration with images in " .. dir, 0) end

local s = header.settings
local lab <close> = sl.open(row.variant.file, row.variant.overrides)
local run = lab:compare{ technique = row.technique, params = row.params, samples = s.samples, pattern = s.pattern,
                         seed = s.seed, light = s.light, png = false, exr = false }
local est, ref, se, region = run:image("visibility"), run:image("reference"), run:image("stderr"), run:image("region")
local w, h = est:size()
local NAMES = { [0] = "not scored", "penumbra", "umbra", "lit", "terminator" }

if mode == "pick" then
  for y = 1, h do
    for x = 1, w do
      if region:get(x, y, 1) == 1 then print(string.format("%d,%d", x - 1, y - 1)); return 0 end
    end
  end
  error("no penumbra pixel in configuration " .. row.key, 0)
end

local f = assert(io.open(dom, "rb"))
local page = f:read("a")
f:close()
local tag = page:match('<p id="inspect%-result"[^>]*>') or error("the page wrote no #inspect-result", 0)
local function attr(name)
  return tag:match(' data%-' .. name .. '="([^"]*)"') or error("#inspect-result has no data-" .. name, 0)
end
local problems = {}
local function expect(ok, what) if not ok then problems[#problems + 1] = what end end
expect(attr("key") == row.key, "opened " .. attr("key") .. ", not the first configuration " .. row.key)
expect(attr("layers") == "reference,estimate,signed error", "flipped through " .. attr("layers"))
local x, y = tonumber(attr("x")) + 1, tonumber(attr("y")) + 1
local step = 1 / 65535
for _, c in ipairs({ { "est", est }, { "ref", ref }, { "se", se } }) do
  local got, want = tonumber(attr(c[1])), c[2]:get(x, y, 1)
  expect(math.abs(got - want) <= step, string.format("%s at (%d, %d): page %s, engine %.6f", c[1], x - 1, y - 1,
                                                     attr(c[1]), want))
end
expect(attr("region") == NAMES[math.tointeger(region:get(x, y, 1))],
       "class " .. attr("region") .. ", engine " .. NAMES[math.tointeger(region:get(x, y, 1))])
local rmse = row.record.metrics.all.rmse
expect(math.abs(tonumber(attr("rmse")) - rmse) <= 1e-4, "RMSE over the page's data " .. attr("rmse") ..
       ", the record's " .. rmse)
if #problems > 0 then error("pixel inspector: " .. table.concat(problems, "; "), 0) end
print(string.format("pixel inspector: read pixel (%d, %d) %s, flipped %s, RMSE %s (record %.6f)", x - 1, y - 1,
                    attr("region"), attr("layers"), attr("rmse"), rmse))
return 0
