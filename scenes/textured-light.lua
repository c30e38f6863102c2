-- textured-light: a 2 x 1 textured rectangular light whose emission is three
-- coloured discs (red, green, blue) on black (lights/rgb-discs.exr), above a
-- sphere and a post: each disc casts its own shadow, so the penumbrae split
-- into coloured bands. Seed 001's coloured and shaped area lights. Units:
-- world units, degrees. The image is described in scenes/README.md.
return {
  name = "textured-light",
  camera = {
    position = {0.4, 3.4, 5.0}, target = {0.1, 0.3, 0}, up = {0, 1, 0},
    fov = 42, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    -- facing straight down; the image's width (the discs' row) runs along x
    { type = "textured_rect", position = {0, 3.2, -0.3}, direction = {0, -1, 0}, up = {0, 0, -1},
      width = 2.0, height = 1.0, image = "lights/rgb-discs.exr", color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.85, 0.85, 0.85} },
    { name = "ball", shape = "sphere", radius = 0.45, segments = 64, translate = {-0.7, 0.9, 0.3},
      albedo = {0.8, 0.8, 0.8} },
    { name = "post", shape = "cylinder", radius = 0.12, height = 1.6, segments = 32,
      translate = {0.8, 0.8, 0.2}, albedo = {0.8, 0.8, 0.8} },
  },
}
