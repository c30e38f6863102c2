-- bad-param.lua -- an experiment with an out-of-range parameter: refused
-- (exit 1, the parameter and its range named) before anything runs or is written.
local experiment = require "shadowlab.experiment"
local exp = experiment.new{ name = "bad-param", samples = 4 }
exp:scene("scenes/sphere-on-plane.lua")
exp:add("hard", { { offset_scale = 2 }, { offset_scale = -1 } })
exp:run(arg)
