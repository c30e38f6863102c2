-- overlap: two occluders at very different heights that overlap as seen from
-- a spherical light: a small slab high up straddles the edge of a large slab
-- near the ground. Where they overlap a shadow map stores only the nearer
-- (high) blocker, so single-layer methods (seed 000 PCSS blocker search, seed
-- 003) misjudge the low slab's penumbra there. Units: world units, degrees.
return {
  name = "overlap",
  camera = {
    position = {1.2, 4.0, 6.2}, target = {0.1, 0.9, 0}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {-1.0, 5.0, -1.5}, radius = 0.45, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- low, large: 1.6 x 1.6 slab whose underside is 0.6 above the ground
    { name = "low", shape = "box", size = {1.6, 0.08, 1.6}, translate = {-0.3, 0.64, 0.2},
      albedo = {0.35, 0.55, 0.8} },
    -- high, small: 0.7 x 0.7 slab at y = 2.8 over the low slab's +x edge
    { name = "high", shape = "box", size = {0.7, 0.06, 0.7}, translate = {-0.3, 2.8, -0.7},
      albedo = {0.85, 0.5, 0.3} },
  },
}
