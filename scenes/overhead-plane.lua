-- overhead-plane: the setting of the course's error analysis (§3.1.2,
-- Fig. 3.7): an overhead directional light and a view perpendicular to it,
-- the camera 0.5 above a large ground plane looking horizontally, near 1,
-- far 100 (z_f / z_n = 100), so the intersection body is the trapezoid from
-- z_n to z_f and the closed-form errors of uniform, PSM and LiSPSM maps hold
-- exactly. A row of posts and two boxes cast shadows along the view.
-- Units: world units, degrees.
local objects = {
  { name = "ground", shape = "plane", size = {400, 240}, translate = {0, -0.5, -60}, albedo = {0.7, 0.7, 0.7} },
  { name = "box1", shape = "box", size = {1, 1, 1}, translate = {-1.2, 0, -4}, albedo = {0.7, 0.4, 0.3} },
  { name = "box2", shape = "box", size = {4, 3, 4}, translate = {6, 1, -40}, albedo = {0.7, 0.4, 0.3} },
}
for i = 1, 12 do -- thin posts at growing distances: perspective aliasing shows on their shadows
  local z = -1.6 * 1.45 ^ i
  objects[#objects + 1] = { name = "post" .. i, shape = "cylinder", radius = 0.02 * 1.3 ^ i, height = 1.5,
                            segments = 12, translate = {0.8 - 0.05 * i, 0.25, z}, albedo = {0.3, 0.3, 0.8} }
end

return {
  name = "overhead-plane",
  camera = {
    position = {0, 0, 0}, target = {0, 0, -1}, up = {0, 1, 0},
    fov = 60, near = 1, far = 100, width = 320, height = 240,
  },
  lights = {
    { type = "directional", direction = {0, -1, 0}, color = {1, 1, 1}, intensity = 3 },
  },
  objects = objects,
}
