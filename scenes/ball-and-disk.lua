-- ball-and-disk: seed 003's Fig. 7 setting (Kirsch & Döllner): a ball high
-- above a small ground and a thin disk just above it, under a spherical
-- light. The ground is only 3 x 3 so that a map fitted to the scene spends
-- its texels on the shadows, as the paper's 64 x 64 map does: the ball's
-- shadow keeps its shape there, the disk's (blocker and receiver 4 cm apart)
-- shows the artefacts. Units: world units (metres), degrees.
return {
  name = "ball-and-disk",
  camera = {
    position = {0, 3.4, 3.6}, target = {0, 0.2, 0}, up = {0, 1, 0},
    fov = 45, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {0.6, 4.5, 0.4}, radius = 0.3, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {3, 3}, albedo = {0.8, 0.8, 0.8} },
    { name = "ball", shape = "sphere", radius = 0.4, segments = 64, translate = {-0.5, 1.4, -0.2},
      albedo = {0.75, 0.3, 0.25} },
    { name = "disk", shape = "cylinder", radius = 0.45, height = 0.03, segments = 64,
      translate = {0.55, 0.055, 0.25}, albedo = {0.3, 0.5, 0.75} },
  },
}
