-- teapot: the Utah teapot (6,320 triangles) on a ground plane under a
-- rectangular area light: curved self-shadowing (lid, spout, handle) and an
-- anisotropic penumbra from a 1.6 x 0.6 emitter. Units: world units, degrees.
-- teapot.obj is not in glmark2-data: this scene needs it on the model search
-- path, e.g. SHADOWLAB_MODEL_PATH=/work/shared/models (see scenes/README.md).
return {
  name = "teapot",
  camera = {
    position = {0.9, 2.8, 4.8}, target = {0.7, 0.35, -0.4}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    -- long side along x, tilted toward the teapot from the left and in front
    { type = "rect", position = {-3.2, 2.8, 1.4}, target = {0, 0.4, 0}, up = {0, 0, -1},
      width = 1.6, height = 0.6, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- teapot.obj spans x [-3, 3.43], y [0, 3.15], z [-2, 2]: scaled 0.4 and
    -- centred in x, it stands on y = 0, about 2.6 long and 1.26 tall.
    { name = "teapot", shape = "mesh", model = "teapot.obj",
      scale = 0.4, translate = {-0.087, 0, 0}, albedo = {0.7, 0.72, 0.78} },
  },
}
