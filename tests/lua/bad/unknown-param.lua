-- unknown-param.lua -- a lab:compare call with a misspelt parameter name.
local sl = require "shadowlab"
local lab = sl.open("scenes/sphere-on-plane.lua", { ["camera.width"] = 32, ["camera.height"] = 24 })
lab:compare{ technique = "hard", params = { ofset_scale = 1 }, samples = 4 }
