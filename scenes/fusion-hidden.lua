-- fusion-hidden: course §1 Fig. 1.6 (right), Eq. 1.5's lower bound: a small
-- slab high up hidden, as seen from the ground below, behind a large slab
-- near the ground: the large slab covers every part of the light the small
-- one does, so the occlusion is the larger one's (the maximum is the truth).
-- A single shadow map sees the small slab first (it is nearer the light).
-- Camera below the slabs, looking straight down. Units: world units, degrees.
return {
  name = "fusion-hidden",
  camera = { position = {0, 1.0, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 100, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 4, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 0.8, height = 0.8, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- large: 1.2 x 1.2 at y = 1.2; small: 0.4 x 0.4 at y = 2.4, over the large one's +x half
    { name = "large", shape = "box", size = {1.2, 0.04, 1.2}, translate = {0, 1.2, 0}, albedo = {0.6, 0.4, 0.3} },
    { name = "small", shape = "box", size = {0.4, 0.04, 0.4}, translate = {0.15, 2.4, 0}, albedo = {0.3, 0.4, 0.6} },
  },
}
