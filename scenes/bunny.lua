-- bunny: the 69,451-triangle Stanford bunny standing on a ground plane under a
-- spherical light: fine, self-shadowing detail (ears, haunch) and a soft
-- contact shadow, the test model of seed 001 (Chun & Oh). Units: world units
-- (the raw scan spans ~0.15; it is scaled x10 to ~1.5 units tall), degrees.
-- Falls back to glmark2-data's bunny.obj, which needs a different transform.
return {
  name = "bunny",
  camera = {
    position = {0.9, 2.0, 4.4}, target = {0.6, 0.5, 0}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {-3.2, 3.4, 1.2}, radius = 0.35, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- Stanford bounding box: x [-0.0947, 0.0610], y [0.0330, 0.1873],
    -- z [-0.0619, 0.0588]; scaled x10, centred in x/z, feet on y = 0.
    { name = "bunny", shape = "mesh", model = {"stanford-bunny.obj", "bunny.obj"},
      scale = 10, translate = {0.168, -0.330, 0.015}, albedo = {0.85, 0.78, 0.65} },
  },
}
