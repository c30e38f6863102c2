-- million: a procedural torus of 1,002,000 triangles (1000 segments) over a
-- ground plane under a rectangular light: the "scene complexity" end of seed
-- 003's Table 1 claim that building the shadow-width map costs the same
-- whatever the scene (bunny and teapot are the other two). It needs no model
-- files. Units: world units, degrees.
return {
  name = "million",
  camera = {
    position = {0.6, 3.2, 4.8}, target = {0, 0.5, 0}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "rect", position = {-2.4, 4.0, 1.2}, target = {0, 0.5, 0}, up = {0, 0, -1},
      width = 1.2, height = 0.8, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    { name = "torus", shape = "torus", major = 0.9, minor = 0.3, segments = 1000,
      rotate = {60, 0, 20}, translate = {0, 1.3, 0}, albedo = {0.75, 0.4, 0.3} },
  },
}
