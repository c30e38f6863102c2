-- an unknown key whose __tostring raises (the reader names unknown keys by their text)
local k = setmetatable({}, {__tostring = function() error("tostring raised") end})
return { [k] = 1, camera = { position = {0, 3, 6}, target = {0, 0, 0} },
         lights = { { type = 'point', position = {0, 4, 0} } }, objects = { { shape = 'sphere' } } }
