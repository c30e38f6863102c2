-- a heightfield's elevation function gives the next object a looping __index
-- while the scene is being read (after the metatable check): the read is protected
local objs = {}
objs[1] = { shape = 'heightfield', size = {4, 4}, resolution = {2, 2},
            elevation = function(x, z)
              setmetatable(objs[2], {__index = function() while true do end end})
              return 0
            end }
objs[2] = { shape = 'sphere' }
return { camera = { position = {0, 3, 6}, target = {0, 0, 0} },
         lights = { { type = 'point', position = {0, 4, 0} } }, objects = objs }
