local sweep, experiment = require "shadowlab.sweep", require "shadowlab.experiment"
local report = require "shadowlab.report"

local exp = experiment.new{ name = "pcf-kernel", samples = 256,
                            overrides = { ["camera.width"] = 320, ["camera.height"] = 240 } }
exp:scene("scenes/sphere-on-plane.lua")
exp:add("sm", sweep.grid{ map_size = { 256, 512, 1024, 2048 } })
exp:add("pcf", sweep.grid{ K = { 1, 3, 5, 9, 15 }, map_size = { 512, 1024 } })
report.write(exp:run(arg))
