-- fusion-overlap: course §1 Fig. 1.6 (middle): two slabs at different
-- heights whose projections onto the light overlap in part as seen from the
-- ground between their shadows (the product of visibilities is the
-- course's "closer to the truth" there). Camera below the slabs, looking
-- straight down, as in fusion-separate.lua. Units: world units, degrees.
return {
  name = "fusion-overlap",
  camera = { position = {0, 1.0, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 100, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 4, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 0.8, height = 0.8, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- low: x in [-0.8, 0.1] at y = 1.2; high: x in [-0.2, 0.5] at y = 1.9
    { name = "low", shape = "box", size = {0.9, 0.04, 1.2}, translate = {-0.35, 1.2, 0}, albedo = {0.6, 0.4, 0.3} },
    { name = "high", shape = "box", size = {0.7, 0.04, 1.0}, translate = {0.15, 1.9, 0.1}, albedo = {0.3, 0.4, 0.6} },
  },
}
