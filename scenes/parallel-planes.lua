-- parallel-planes: course §5.1, Fig. 5.1: a square light, a square occluder
-- and the receiver in three parallel planes, where the penumbra width is the
-- closed form W = w_light (d_r - d_o) / d_o (similar triangles; d_o, d_r:
-- the occluder's and the receiver's distances from the light) and the umbra
-- shrinks to nothing at W = a (a = s d_r / d_o, the occluder's side s
-- scaled onto the receiver). Light 6 above the ground, plate (s = 1, 0.01
-- thick) 3 above it: d_o = 3, d_r = 6, W = w_light, a = 2. The camera hangs
-- below the plate looking straight down: the ground is parallel to the image
-- plane, so each pixel covers the same ground area. Units: world units, degrees.
return {
  name = "parallel-planes",
  camera = { position = {0, 2.5, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 80, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 6, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 0.6, height = 0.6, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {12, 12}, albedo = {0.8, 0.8, 0.8} },
    { name = "plate", shape = "box", size = {1, 0.01, 1}, translate = {0, 3, 0}, albedo = {0.6, 0.4, 0.3} },
  },
}
