-- small-sweep.lua -- the tests' sweep: two scene variants (light radius) x
-- hard at three offsets, at 64x48 with 16 reference samples. Seconds on 2
-- cores. SHADOWLAB_TEST_ROW_DELAY (seconds) slows each row so the resume
-- test can kill it mid-way.
local sweep = require "shadowlab.sweep"
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"

local exp = experiment.new{ name = "small-sweep", samples = 16, repeats = 2, warmup = 1,
                            overrides = { ["camera.width"] = 64, ["camera.height"] = 48 } }
exp:scene("scenes/sphere-on-plane.lua", sweep.grid{ ["lights[1].radius"] = { 0.2, 0.4 } })
exp:add("hard", sweep.grid{ offset_scale = { 0.5, 1, 4 } })
local delay = tonumber(os.getenv("SHADOWLAB_TEST_ROW_DELAY") or "")
if delay then exp.on_row = function() os.execute("sleep " .. delay) end end
local result = exp:run(arg)
report.write(result, { title = "test sweep" })
