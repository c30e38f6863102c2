-- fusion-separate: course §1 Fig. 1.6 (left), Eq. 1.5's upper bound: two
-- slabs side by side at one height under a square rect light, 0.2 apart, so
-- a ground point between their shadows sees them cover disjoint parts of the
-- light and their occlusions add (the sum is the truth there). The camera
-- hangs below the slabs looking straight down, so it sees only the ground
-- (uniform footprint) and every variant with a slab removed
-- (objects[i].caster = false) has the same view samples.
-- Units: world units, degrees; y up, light 4 above the ground.
return {
  name = "fusion-separate",
  camera = { position = {0, 1.3, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 90, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 4, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 0.8, height = 0.8, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- 0.6 x 0.04 x 1.2 slabs, centres 0.4 either side of x = 0 (gap 0.2), at y = 1.6
    { name = "left", shape = "box", size = {0.6, 0.04, 1.2}, translate = {-0.4, 1.6, 0}, albedo = {0.6, 0.4, 0.3} },
    { name = "right", shape = "box", size = {0.6, 0.04, 1.2}, translate = {0.4, 1.6, 0}, albedo = {0.3, 0.4, 0.6} },
  },
}
