-- bunny-textured: seed 001's setting (Chun & Oh, Fig. 5 and Table 2): the
-- 69,451-triangle Stanford bunny on a ground plane at 800 x 800 under a
-- textured rectangular light, the three coloured discs of
-- lights/rgb-discs.exr (scenes/README.md), placed where bunny.lua has its
-- sphere light. Units: world units (the scan scaled x10, ~1.5 tall), degrees.
-- Needs stanford-bunny.obj on the model search path; glmark2's bunny.obj is
-- the fallback, mapped onto the same frame (see bunny.lua).
return {
  name = "bunny-textured",
  camera = {
    position = {2.2, 2.3, 5.2}, target = {1.5, 0.3, -0.4}, up = {0, 1, 0},
    fov = 45, near = 0.05, far = 100, width = 800, height = 800,
  },
  lights = {
    -- 1.2 x 0.6 (the image's 2:1), facing the bunny; the discs' row runs horizontally
    { type = "textured_rect", position = {-3.2, 3.4, 1.2}, target = {0.2, 0.5, 0}, up = {0, 1, 0},
      width = 1.2, height = 0.6, image = "lights/rgb-discs.exr", color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    { name = "bunny", shape = "mesh",
      model = { "stanford-bunny.obj",
                { file = "bunny.obj", scale = 0.0778495, translate = {-0.0168405, 0.110154, -0.001537} } },
      scale = 10, translate = {0.1684, -0.3299, 0.0154}, albedo = {0.85, 0.78, 0.65} },
  },
}
