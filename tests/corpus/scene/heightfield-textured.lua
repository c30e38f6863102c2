-- a heightfield, a textured rect light and every primitive, for the scene fuzzer's seeds
local objs = { { shape = 'heightfield', size = {4, 4}, resolution = {8, 8},
                 elevation = function(x, z) return 0.1 * math.sin(x) * math.cos(z) end } }
for i, s in ipairs({'box', 'sphere', 'cylinder', 'cone', 'torus', 'disk', 'plane'}) do
  objs[#objs + 1] = { shape = s, translate = {i - 4, 1, 0}, scale = 0.3, rotate = {10 * i, 0, 0},
                      caster = i % 2 == 0, receiver = true, albedo = {0.5, 0.5, 0.5} }
end
return { name = 'seed', camera = { position = {0, 3, 6}, target = {0, 0, 0}, fov = 50, near = 0.1, far = 100,
                                   width = 16, height = 12, supersample = 2 },
  lights = { { type = 'spot', position = {1, 4, 1}, target = {0, 0, 0}, cone_angle = 40 },
             { type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1}, width = 1, height = 0.5 },
             { type = 'disk', position = {0, 4, 0}, target = {0, 0, 0}, radius = 0.3 },
             { type = 'directional', direction = {-1, -2, -1}, color = {1, 0.9, 0.8}, intensity = 2 } },
  objects = objs }
