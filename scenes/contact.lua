-- contact: boxes resting exactly on the ground (bottom faces at y = 0) under
-- a rectangular area light: contact shadows that harden to zero width where
-- the box meets the floor, light leaking under occluders, and self-
-- intersection (acne) on coplanar/touching faces. A thin plate (2 cm) on the
-- floor stresses leaks further. Units: world units (metres), degrees.
return {
  name = "contact",
  camera = {
    position = {0.8, 2.6, 4.6}, target = {0.5, 0.3, -0.2}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "rect", position = {-3.0, 3.0, 1.2}, target = {0, 0, 0},
      width = 1.5, height = 1.5, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- 1 x 1 x 1 box, turned -25 degrees, bottom face exactly at y = 0
    { name = "box", shape = "box", size = {1, 1, 1}, rotate = {0, -25, 0},
      translate = {0, 0.5, 0}, albedo = {0.75, 0.35, 0.3} },
    -- a 2 cm plate lying on the floor: bottom at y = 0, top at 0.02
    { name = "plate", shape = "box", size = {1.0, 0.02, 0.6}, rotate = {0, -15, 0},
      translate = {1.4, 0.01, -0.2}, albedo = {0.3, 0.5, 0.75} },
    -- a tall thin post: long contact edge
    { name = "post", shape = "box", size = {0.2, 1.4, 0.2}, translate = {-1.3, 0.7, 0.3},
      albedo = {0.6, 0.6, 0.35} },
  },
}
