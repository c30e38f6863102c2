-- every-technique.lua DIR -- does the error-against-time report in DIR show
-- every registered technique? Each technique must be in at least one plot
-- (the experiment gives every technique a scene whose light it handles), and
-- each plot must show every technique that handles its scene's light. It
-- reads the plots' data (plots/error-vs-time-*.dat: one "# NAME" block per
-- technique), the records and the registry. Returns 1 on a gap.
local sl = require "shadowlab"
local records = require "shadowlab.records"
local handles = require("shadowlab.experiment").handles

local dir = assert(arg[1], "usage: every-technique.lua REPORT-DIR")
local _, rows = records.read(dir .. "/records.jsonl")
local light_of = {}
for _, r in ipairs(rows) do
  if r.record then light_of[r.record.scene.name] = r.record.scene.light_type end
end

local plots, gaps, shown_anywhere = 0, {}, {}
for _, name in ipairs(sl.dir(dir .. "/plots") or {}) do
  local scene = name:match("^error%-vs%-time%-(.+)%.dat$")
  if scene then
    plots = plots + 1
    local shown = {}
    for line in io.lines(dir .. "/plots/" .. name) do
      local t = line:match("^# (.+)$")
      if t then shown[t], shown_anywhere[t] = true, true end
    end
    for _, t in ipairs(sl.techniques()) do
      if handles(t, light_of[scene]) and not shown[t.name] then gaps[#gaps + 1] = t.name .. " in " .. name end
    end
  end
end
local absent = {}
for _, t in ipairs(sl.techniques()) do
  if not shown_anywhere[t.name] then absent[#absent + 1] = t.name end
end
if plots == 0 then print("no error-vs-time plot in " .. dir) return 1 end
if #absent > 0 then print("in no plot at all: " .. table.concat(absent, ", ")) return 1 end
if #gaps > 0 then print("missing: " .. table.concat(gaps, ", ")) return 1 end
print(string.format("%d plots show every registered technique (%d), each plot every one that handles its light",
                    plots, #sl.techniques()))
return 0
