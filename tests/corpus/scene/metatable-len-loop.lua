-- a light list whose length operator never returns
return { camera = { position = {0, 3, 6}, target = {0, 0, 0} },
         lights = setmetatable({ { type = 'point', position = {0, 4, 0} } }, {__len = function() while true do end end}),
         objects = { { shape = 'sphere' } } }
