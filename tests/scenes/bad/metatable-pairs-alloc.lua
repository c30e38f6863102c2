-- nested deep in an object: __pairs and __index that allocate without bound
local greedy = {__pairs = function(t) local s = 'x'; while true do s = s .. s end end,
                __index = function(t, k) local s = 'x'; while true do s = s .. s end end}
return { camera = { position = {0, 3, 6}, target = {0, 0, 0} },
         lights = { { type = 'point', position = {0, 4, 0} } },
         objects = { { shape = 'sphere', translate = setmetatable({0, 1, 0}, greedy) } } }
