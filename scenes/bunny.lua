-- bunny: the 69,451-triangle Stanford bunny (seed 001, Chun & Oh) on a ground
-- plane under a spherical light: fine self-shadowing detail (ears, haunch) and
-- soft ear shadows on the floor. Units: world units (the scan is ~0.15 units,
-- scaled x10 here to ~1.5 tall), degrees. Needs the model search path for
-- stanford-bunny.obj; glmark2's bunny.obj is the fallback (see below).
return {
  name = "bunny",
  camera = {
    position = {0.9, 2.0, 4.4}, target = {0.6, 0.5, 0}, up = {0, 1, 0},
    fov = 40, near = 0.05, far = 100, width = 480, height = 360,
  },
  lights = {
    { type = "sphere", position = {-3.2, 3.4, 1.2}, radius = 0.35, color = {1, 1, 1}, intensity = 10 },
  },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    -- stanford-bunny.obj spans x [-0.0947, 0.0610], y [0.0330, 0.1873],
    -- z [-0.0619, 0.0588] (Y up): scaled x10, centred in x and z, feet at y = 0.
    -- glmark2-data's bunny.obj (a fresh machine's fallback, holes filled, 69,666
    -- triangles) is the same scan normalised to x [-1, 1] and centred on its
    -- bounding box, 12.845x larger: its own scale and translate map it onto the
    -- Stanford file's frame first, so both give the same scene.
    { name = "bunny", shape = "mesh",
      model = { "stanford-bunny.obj",
                { file = "bunny.obj", scale = 0.0778495, translate = {-0.0168405, 0.110154, -0.001537} } },
      scale = 10, translate = {0.1684, -0.3299, 0.0154}, albedo = {0.85, 0.78, 0.65} },
  },
}
