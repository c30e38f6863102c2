-- a light nested 100000 tables deep (the metatable walk recurses in C: refused past its depth)
local t = {}
local c = t
for i = 1, 100000 do c[1] = {}; c = c[1] end
return { camera = { position = {0, 3, 6}, target = {0, 0, 0} }, lights = { t }, objects = { { shape = 'sphere' } } }
