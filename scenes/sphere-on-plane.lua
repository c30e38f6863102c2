-- sphere-on-plane: the default scene. A sphere floating above a ground plane
-- under a spherical light: a clean umbra with a penumbra that widens with the
-- light's radius (seed 000's setting). Units: world units (metres), degrees.
return {
  name = "sphere-on-plane",
  camera = {
    position = {0, 3.2, 5.5}, target = {0, 0.4, 0}, up = {0, 1, 0},
    fov = 45, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {1.5, 5, 1}, radius = 0.4, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {10, 10}, albedo = {0.8, 0.8, 0.8} },
    { name = "ball", shape = "sphere", radius = 0.6, segments = 96,
      translate = {0, 1.0, 0}, albedo = {0.75, 0.3, 0.25} },
  },
}
