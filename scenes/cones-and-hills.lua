-- cones-and-hills: the classic bias stress scene. Sharp cones (thin apexes,
-- self-shadowing flanks) planted on a heightfield of rolling hills whose
-- slopes meet a spot light at grazing angles: shadow acne and peter-panning
-- (seed 000/003 bias discussions; a constant depth bias cannot fit both the
-- steep cones and the grazing hills). Units: world units, degrees.
local function hills(x, z)
  return 1.2 * math.sin(0.45 * x + 0.3) * math.cos(0.38 * z - 0.5)
       + 0.6 * math.sin(0.23 * (x - 1.7 * z) + 2.0)
end

local objects = {
  { name = "hills", shape = "heightfield", size = {24, 24}, resolution = {128, 128},
    elevation = hills, albedo = {0.72, 0.7, 0.62} },
}

-- 70 cones on a jittered 10 x 7 grid; bases sunk 0.1 below the local ground
local n = 0
for j = 0, 6 do
  for i = 0, 9 do
    n = n + 1
    local x = -9.9 + 2.2 * i + 1.2 * (math.random() - 0.5)
    local z = -7.5 + 2.2 * j + 1.2 * (math.random() - 0.5)
    local r, h = 0.22 + 0.2 * math.random(), 1.2 + 1.6 * math.random()
    objects[#objects + 1] = { name = "cone" .. n, shape = "cone", radius = r, height = h, segments = 24,
      translate = {x, hills(x, z) - 0.1 + 0.5 * h, z}, albedo = {0.85, 0.55, 0.3} }
  end
end

return {
  name = "cones-and-hills",
  camera = {
    position = {0, 8.5, 15}, target = {0, 0, -1}, up = {0, 1, 0},
    fov = 50, near = 0.1, far = 100, width = 480, height = 360,
  },
  lights = {
    -- a spot low on the left: about 20 degrees above the hill tops at the centre
    { type = "spot", position = {-17, 6, -3}, target = {0, 0, 0}, cone_angle = 40,
      color = {1, 1, 1}, intensity = 400 },
  },
  objects = objects,
}
