return {
  camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 32, height = 24 },
  lights = { { type = "sphere", position = {0, 4, 0}, radius = 0.5 } },
  objects = { { shape = "mesh", model = "bad-index.obj" } },
}
