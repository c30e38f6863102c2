-- twig: course §5.2.3.3, Fig. 5.8: occluders one shadow-map texel wide. A
-- comb of 21 thin bars (0.0028 wide and tall, 1.2 long, 0.03 apart) hangs
-- 1 unit above a 3 x 3 ground under a spherical light 5 units up, each bar
-- about one texel of the default 1024^2 map fitted to the scene (checked by
-- measurement: at this width backprojection's microquads lose the bars
-- entirely, their penumbra leak 0.115 at 48x36 equal to the reference's
-- whole occlusion there, while at twice the width they keep part of them).
-- The bars' penumbrae (about 0.16 wide) overlap into a grey band V ~ 0.88
-- under the comb: a micropatch per texel keeps each bar, a microquad (2 x 2
-- texel centres all in front) has none to build and lets the light through,
-- as the course says of "twigs one texel wide" (§5.2.3.3). The camera hangs
-- below the comb looking straight down, so every scored sample is on the
-- flat ground. Units: world units, degrees.
local BARS, PITCH, WIDTH = 21, 0.03, 0.0028
local objects = { { name = "ground", shape = "plane", size = {3, 3}, albedo = {0.8, 0.8, 0.8} } }
for i = 1, BARS do
  local x = (i - (BARS + 1) / 2) * PITCH
  objects[#objects + 1] = { name = "bar" .. i, shape = "box", size = {WIDTH, WIDTH, 1.2}, translate = {x, 1.0, 0},
                            albedo = {0.45, 0.35, 0.25} }
end
return {
  name = "twig",
  camera = { position = {0, 0.8, 0}, target = {0, 0, 0}, up = {0, 0, -1},
             fov = 90, near = 0.05, far = 10, width = 480, height = 360 },
  lights = { { type = "sphere", position = {0.2, 5, 0.1}, radius = 0.3, color = {1, 1, 1}, intensity = 10 } },
  objects = objects,
}
