-- frustum-box: the view frustum of the error analysis (z_n = 1, z_f = 100,
-- 60 degrees, view along -z) wholly inside the scene's bounds, so the
-- intersection body B is the frustum itself and Lloyd et al.'s measure over
-- the view frustum (storage factor, course Fig. 3.13) covers all of it. Two
-- small boxes at opposite corners only set the bounds; a directional light
-- (overhead here; override lights[1].direction for the light behind).
return {
  name = "frustum-box",
  camera = {
    position = {0, 0, 0}, target = {0, 0, -1}, up = {0, 1, 0},
    fov = 60, near = 1, far = 100, width = 320, height = 240,
  },
  lights = {
    { type = "directional", direction = {0, -1, 0}, color = {1, 1, 1}, intensity = 3 },
  },
  objects = {
    { name = "low", shape = "box", size = {1, 1, 1}, translate = {-90, -70, 5}, albedo = {0.5, 0.5, 0.5} },
    { name = "high", shape = "box", size = {1, 1, 1}, translate = {90, 70, -110}, albedo = {0.5, 0.5, 0.5} },
  },
}
