-- terrain: 1 km x 1 km of gentle procedural hills (128 x 128 heightfield)
-- with a few hundred buildings (boxes) and trees (cylinder trunks, cone
-- crowns), lit by a low sun; the camera stands 2 m above the ground looking
-- toward the horizon with near = 0.1, far = 1500 (far/near = 1.5e4): the
-- perspective-aliasing case for warping (LiSPSM/TSM) and z-partitioning
-- (cascaded/parallel-split shadow maps). Units: metres, degrees.

-- Ground height (metres) at (x, z); used for the heightfield and to seat
-- every object and the camera on the ground.
local function elevation(x, z)
  return 7 * math.sin(x / 110 + 0.4) * math.cos(z / 140 - 0.3)
       + 3 * math.sin((x + 2 * z) / 80 + 1.3)
end

-- lowest ground under a footprint of half-extent r around (x, z)
local function base(x, z, r)
  local h = elevation(x, z)
  for _, d in ipairs({{r, r}, {r, -r}, {-r, r}, {-r, -r}}) do
    h = math.min(h, elevation(x + d[1], z + d[2]))
  end
  return h - 0.3 -- sink slightly so nothing floats between grid vertices
end

local cam_x, cam_z = 3, 440
local objects = {
  { name = "ground", shape = "heightfield", size = {1000, 1000}, resolution = {128, 128},
    elevation = elevation, albedo = {0.55, 0.62, 0.42} },
}

local function add(o) objects[#objects + 1] = o end

-- buildings: 160 boxes, 8-24 m wide, 5-30 m tall, none within 110 m of the camera
local n = 0
while n < 160 do
  local x, z = math.random() * 900 - 450, math.random() * 900 - 450
  if (x - cam_x) ^ 2 + (z - cam_z) ^ 2 > 110 ^ 2 then
    n = n + 1
    local w, d, h = 8 + 16 * math.random(), 8 + 16 * math.random(), 5 + 25 * math.random()
    local y0 = base(x, z, 0.5 * math.max(w, d))
    add({ name = "building" .. n, shape = "box", size = {w, h + 1, d}, rotate = {0, 90 * math.random(), 0},
          translate = {x, y0 + 0.5 * (h + 1), z}, albedo = {0.7, 0.66, 0.6} })
  end
end

-- trees: 180 trunks + crowns, 24 of them beside the camera's view path (3-63 m ahead)
for i = 1, 180 do
  local x, z
  if i <= 24 then -- beside the view path, mostly on the sun's side
    local side = (i % 3 == 0) and 1 or -1
    x, z = cam_x + side * (5 + 20 * math.random()), cam_z - 3 - 60 * math.random() ^ 1.5
  else
    x, z = math.random() * 980 - 490, math.random() * 980 - 490
  end
  local s = 0.7 + 0.6 * math.random()
  local y0 = base(x, z, 0.3 * s)
  add({ name = "trunk" .. i, shape = "cylinder", radius = 0.25 * s, height = 3 * s + 0.3, segments = 8,
        translate = {x, y0 + 0.5 * (3 * s + 0.3), z}, albedo = {0.4, 0.3, 0.2} })
  add({ name = "crown" .. i, shape = "cone", radius = 1.8 * s, height = 6 * s, segments = 12,
        translate = {x, y0 + 0.3 + 2 * s + 3 * s, z}, albedo = {0.2, 0.45, 0.2} })
end

return {
  name = "terrain",
  camera = {
    position = {cam_x, elevation(cam_x, cam_z) + 2, cam_z},
    target = {cam_x - 40, elevation(cam_x, cam_z) + 0.5, cam_z - 400}, up = {0, 1, 0},
    fov = 55, near = 0.1, far = 1500, width = 512, height = 384,
  },
  lights = {
    -- sun 24 degrees above the horizon, from the left and a little behind
    -- the camera: long shadows falling across the view path
    { type = "directional",
      direction = {math.cos(math.rad(24)) * 0.94, -math.sin(math.rad(24)), -math.cos(math.rad(24)) * 0.34},
      color = {1, 0.95, 0.85}, intensity = 3 },
  },
  objects = objects,
}
