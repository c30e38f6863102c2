-- unknown-metric.lua -- report.write with an error name that is no metric
-- ("penumbra_rmse" for penumbra.rmse): refused with the valid names (exit 1).
local experiment = require "shadowlab.experiment"
local report = require "shadowlab.report"
local exp = experiment.new{ name = "unknown-metric", samples = 4, repeats = 1, warmup = 0, images = false,
                            overrides = { ["camera.width"] = 16, ["camera.height"] = 12 } }
exp:scene("scenes/sphere-on-plane.lua")
exp:add("hard")
report.write(exp:run(arg), { error = "penumbra_rmse" })
