-- nonfinite-params.lua -- NaN and infinities handed in from Lua (0/0,
-- math.huge, -math.huge, and the strings "nan", "inf", "-inf") are refused
-- naming the parameter and its range, for every parameter of every
-- registered technique, by sl.params, lab:render, lab:compare and
-- experiment:add, before anything renders; so are non-finite scene
-- overrides, naming the key. Run by tests/lua/run.sh through `shadowlab run`;
-- prints one line per refusal path and a summary, and fails (exit 1) listing
-- every value that was accepted or refused without the words.
local sl = require "shadowlab"
local experiment = require "shadowlab.experiment"

local values = { { "0/0", 0 / 0 }, { "math.huge", math.huge }, { "-math.huge", -math.huge },
                 { "'nan'", "nan" }, { "'inf'", "inf" }, { "'-inf'", "-inf" } }
local failures, checked = {}, 0

-- fn() must raise an error containing every word.
local function refused(what, fn, ...)
  checked = checked + 1
  local ok, msg = pcall(fn)
  if ok then
    failures[#failures + 1] = what .. " was accepted"
    return
  end
  msg = tostring(msg)
  for _, word in ipairs({ ... }) do
    if not msg:find(word, 1, true) then
      failures[#failures + 1] = string.format("%s: refusal lacks '%s': %s", what, word, msg)
      return
    end
  end
end

local function numeric(p) return p.type == "int" or p.type == "float" end

-- Every technique and numeric parameter through sl.params; the first
-- numeric parameter of each through the lab's methods and an experiment.
local lab = sl.open("scenes/sphere-on-plane.lua", { ["camera.width"] = 8, ["camera.height"] = 6 })
local techniques, params = 0, 0
for _, t in ipairs(sl.techniques()) do
  techniques = techniques + 1
  local first
  for _, p in ipairs(t.params) do
    if numeric(p) then
      params = params + 1
      first = first or p
      for _, v in ipairs(values) do
        refused(string.format("sl.params('%s', {%s = %s})", t.name, p.name, v[1]),
                function() sl.params(t.name, { [p.name] = v[2] }) end, p.name, p.range)
      end
    end
  end
  if first then
    for _, v in ipairs(values) do
      local what = string.format("%s %s = %s", t.name, first.name, v[1])
      local opts = { technique = t.name, params = { [first.name] = v[2] } }
      refused("lab:render " .. what, function() lab:render(opts) end, first.name, first.range)
      refused("lab:compare " .. what, function() lab:compare(opts) end, first.name, first.range)
      refused("experiment:add " .. what, function()
        experiment.new{ name = "nonfinite" }:add(t.name, { [first.name] = v[2] })
      end, first.name, first.range)
    end
  end
end
lab:close()

-- Scene overrides: the key path in the refusal.
for _, key in ipairs({ "lights[1].radius", "lights[1].position", "camera.fov", "camera.near" }) do
  for _, v in ipairs({ { "0/0", 0 / 0 }, { "math.huge", math.huge }, { "-math.huge", -math.huge } }) do
    local value = key == "lights[1].position" and { 0, v[2], 0 } or v[2]
    refused(string.format("sl.open override %s = %s", key, v[1]),
            function() sl.open("scenes/sphere-on-plane.lua", { [key] = value }) end, key)
  end
end

if #failures > 0 then
  for _, f in ipairs(failures) do print("FAIL " .. f) end
  error(string.format("%d of %d non-finite inputs not refused as they should be", #failures, checked))
end
print(string.format("%d techniques, %d numeric parameters x %d non-finite values: refused by sl.params, "
                    .. "lab:render, lab:compare and experiment:add naming the parameter and range; "
                    .. "scene overrides naming the key (%d refusals checked)", techniques, params, #values, checked))
