-- planar-occluder: course §5.2.2.1, Figs. 5.3 and 5.4: PCSS assumes one
-- planar occluder parallel to the light and counts as a blocker every map
-- texel nearer the light than the receiver, inside the light-point pyramid
-- or not. Here a board tilted 40 degrees (y from 1.39 to 2.41) hangs under a
-- square rect light beside a low slab (y = 1.3) at its high end: blockers of
-- many depths, many of them outside the pyramid of the ground points beside
-- them (the board's, for points by the slab's shadow), so lit points get shaded,
-- umbra points get lit and penumbrae grow too wide. The camera hangs below
-- the board looking straight down, so every scored sample is on the flat
-- ground (no self-shadowing receiver enters). Units: world units, degrees.
return {
  name = "planar-occluder",
  camera = { position = {0, 1.1, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 100, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "rect", position = {0, 4, 0}, target = {0, 0, 0}, up = {0, 0, -1},
               width = 1.0, height = 1.0, color = {1, 1, 1}, intensity = 10 } },
  objects = {
    { name = "ground", shape = "plane", size = {8, 8}, albedo = {0.8, 0.8, 0.8} },
    { name = "board", shape = "box", size = {1.6, 0.04, 1.2}, rotate = {0, 0, 40}, translate = {-0.2, 1.9, 0},
      albedo = {0.6, 0.4, 0.3} },
    { name = "slab", shape = "box", size = {0.7, 0.04, 1.2}, translate = {0.85, 1.3, 0}, albedo = {0.3, 0.4, 0.6} },
  },
}
