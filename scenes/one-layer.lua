-- one-layer: course §1 Fig. 1.8 (one depth layer against the complete
-- geometry): a small box hidden from the light's centre under a large slab
-- (it lies inside the slab's cone from the light's centre), yet seen from
-- the light's edges, so it darkens the slab's penumbra on the ground. A
-- single shadow map from the centre stores only the slab. Camera below the
-- box, looking straight down. Units: world units, degrees.
return {
  name = "one-layer",
  camera = { position = {0, 0.9, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 100, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 4, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 0.8, height = 0.8, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- slab: 1.0 x 1.0 at y = 2.2 (d = 1.8 from the light: its cone from the centre has tan 0.278)
    { name = "slab", shape = "box", size = {1.0, 0.04, 1.0}, translate = {0, 2.2, 0}, albedo = {0.6, 0.4, 0.3} },
    -- box: x in [0.35, 0.65] at y in [1.0, 1.3] (tan 0.65 / 2.7 = 0.24 < 0.278: hidden from the centre)
    { name = "box", shape = "box", size = {0.3, 0.3, 0.4}, translate = {0.5, 1.15, 0}, albedo = {0.3, 0.4, 0.6} },
  },
}
