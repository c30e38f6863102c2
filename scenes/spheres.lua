-- spheres: the setting of seed 002's Fig. 4 (Parker, Shirley & Smits, "Single
-- Sample Soft Shadows"): one large ball and five small ones above a floor
-- under a spherical light. The large ball's shadow keeps an umbra as the
-- light grows; the small balls' true shadows lose theirs once the light's
-- angular size exceeds theirs (radius about 0.1 here), the case the paper
-- names as its weakness ("errors are highest for small objects whose real
-- shadows would have no umbra"). Units: world units (metres), degrees.
return {
  name = "spheres",
  camera = {
    position = {0.4, 3.4, 5.6}, target = {0.1, 0.3, -0.2}, up = {0, 1, 0},
    fov = 45, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {1.2, 5, 1.0}, radius = 0.2, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {10, 10}, albedo = {0.8, 0.8, 0.8} },
    { name = "big", shape = "sphere", radius = 0.6, segments = 96, translate = {-0.9, 0.9, -0.4},
      albedo = {0.75, 0.3, 0.25} },
    { name = "small1", shape = "sphere", radius = 0.07, segments = 32, translate = {0.5, 0.8, -0.6} },
    { name = "small2", shape = "sphere", radius = 0.07, segments = 32, translate = {0.9, 0.5, 0.1} },
    { name = "small3", shape = "sphere", radius = 0.07, segments = 32, translate = {0.2, 0.6, 0.5} },
    { name = "small4", shape = "sphere", radius = 0.07, segments = 32, translate = {1.4, 0.9, -0.5} },
    { name = "small5", shape = "sphere", radius = 0.07, segments = 32, translate = {-0.3, 0.4, 0.9} },
  },
}
