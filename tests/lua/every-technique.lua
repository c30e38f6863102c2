-- every-technique.lua DIR -- does each error-against-time plot of the report
-- in DIR show every registered technique that handles the scene's light? It
-- reads the plots' data (plots/error-vs-time-*.dat: one "# NAME" block per
-- technique) and the registry. Prints the plots checked; returns 1 on a gap.
local sl = require "shadowlab"
local records = require "shadowlab.records"

local dir = assert(arg[1], "usage: every-technique.lua REPORT-DIR")
local _, rows = records.read(dir .. "/records.jsonl")
local light_of = {}
for _, r in ipairs(rows) do
  if r.record then light_of[r.record.scene.name] = r.record.scene.light_type end
end
local plots, missing, checked = 0, {}, {}
for _, name in ipairs(sl.dir(dir .. "/plots") or {}) do
  local scene = name:match("^error%-vs%-time%-(.+)%.dat$")
  if scene then
    plots = plots + 1
    local shown = {}
    for line in io.lines(dir .. "/plots/" .. name) do
      local t = line:match("^# (.+)$")
      if t then shown[t] = true end
    end
    for _, t in ipairs(sl.techniques()) do
      local handles = false
      for _, l in ipairs(t.lights) do handles = handles or l == light_of[scene] end
      if handles and not shown[t.name] then missing[#missing + 1] = t.name .. " in " .. name end
      if handles then checked[#checked + 1] = t.name end
    end
  end
end
if plots == 0 then print("no error-vs-time plot in " .. dir) return 1 end
if #missing > 0 then print("missing: " .. table.concat(missing, ", ")) return 1 end
print(string.format("%d plots show every registered technique that handles their light (%d checks of %d " ..
                    "techniques)", plots, #checked, #sl.techniques()))
return 0
