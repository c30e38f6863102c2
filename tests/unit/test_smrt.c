/* test_smrt.c -- `smrt` (shadow-map ray tracing, UE5 virtual shadow maps and
 * EEVEE Next) against the Embree reference: the penumbra of sphere-on-plane
 * and of one planar occluder within a stated RMSE, falling from 1 ray to 8;
 * its two measured leaks, each asserted in the direction the engines' own
 * documentation admits: behind second occluders (overlap.lua: the low slab
 * hidden under the high one, which the map does not store) and through thin
 * walls that a march with few steps steps over; and the bad inputs of issue
 * 15 (one ray of one step, receivers at the light's depth, a light wider
 * than the map's field of view), whose output stays finite in [0, 1].
 * 160 x 120 or smaller, 64-sample stratified references: about 8 s on 2
 * loaded cores (load 6-12). */
#include <math.h>
#include "fixtures.h"
#include "soft_helpers.h"
#include "test.h"

#define REF_SAMPLES 64

/* One statistic of a render of smrt on `lab` with `params`; NAN if it failed. */
static double region_stat(Lab *lab, const char *const *params, Region region, bool leak)
{
    RenderResult r;
    Metrics m;
    if (!soft_render(lab, "smrt", params, &r)) return NAN;
    bool ok = soft_metrics(lab, &r.visibility, REF_SAMPLES, &m);
    render_result_free(&r);
    if (!ok) return NAN;
    return leak ? m.region[region].leak_mean : m.region[region].rmse;
}

/* Penumbra RMSE of sphere-on-plane (a ball over a plane, sphere light) and
 * of the strip (one planar occluder halfway to a square light). Measured at
 * 160 x 120 / 128 x 96 against 64 stratified samples: 0.421 and 0.108 (1
 * and 8 rays, sphere), 0.392 and 0.113 (strip). The bound 0.13 holds both
 * at 8 rays; one ray is at least twice as far off. With the extrapolation
 * off (every sample behind a surface a hit) 8 rays read 0.197 and 0.238;
 * marched from the receiver end, 0.268 and 0.312. */
TEST(test_smrt_penumbra_matches_embree_and_falls_with_rays)
{
    const char *one[] = {"rays=1", NULL}, *eight[] = {"rays=8", NULL};
    Lab *ball = soft_open("sphere-on-plane.lua", NULL);
    Lab *strip = soft_strip("{ type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1}, "
                            "width = 1, height = 1 }",
                            2.0);
    CHECK(ball && strip);
    double b1 = region_stat(ball, one, REGION_PENUMBRA, false), b8 = region_stat(ball, eight, REGION_PENUMBRA, false);
    double s1 = region_stat(strip, one, REGION_PENUMBRA, false), s8 = region_stat(strip, eight, REGION_PENUMBRA, false);
    printf("    penumbra RMSE, 1 ray / 8 rays: sphere-on-plane %.4f / %.4f, strip %.4f / %.4f (bound 0.13)\n", b1, b8, s1,
           s8);
    CHECK_MSG(b8 < 0.13 && s8 < 0.13, "8 rays: %.4f, %.4f", b8, s8);
    CHECK_MSG(b1 > 2.0 * b8 && s1 > 2.0 * s8, "one ray is not noisier: %.4f vs %.4f, %.4f vs %.4f", b1, b8, s1, s8);
    lab_close(ball);
    lab_close(strip);
}

/* overlap.lua: where the high slab covers the low one the map stores only
 * the high slab; a ray that passes under the high slab and into the low one
 * is behind a surface whose continuation (extrapolated from the samples
 * before it) it passes in front of, so it reads lit. Epic's cvar help
 * admits the leak ("light leaks behind second occluders"). Measured at 16
 * steps: umbra leak 0.0107 with the high slab, 0.0013 with it moved off the
 * scene (objects[3] to x = z = 5): the overlap adds the leak (with the
 * extrapolation off, every sample behind a surface a hit: 0.0000 both). More
 * steps do not remove it; fewer add their own (2 steps: 0.048). */
TEST(test_smrt_overlap_leaks_behind_the_second_occluder)
{
    const char *moved[] = {"objects[3].translate={5, 2.8, 5}", NULL};
    const char *sixteen[] = {"steps=16", NULL}, *two[] = {"steps=2", NULL};
    Lab *both = soft_open("overlap.lua", NULL), *low = soft_open("overlap.lua", moved);
    CHECK(both && low);
    double with = region_stat(both, sixteen, REGION_UMBRA, true), without = region_stat(low, sixteen, REGION_UMBRA, true);
    double few = region_stat(both, two, REGION_UMBRA, true);
    printf("    overlap umbra leak at 16 steps: %.4f (high slab moved away: %.4f); at 2 steps %.4f\n", with, without, few);
    CHECK_MSG(with > 2.0 * without + 0.003, "the second occluder adds no leak: %.4f vs %.4f", with, without);
    CHECK_MSG(few > with, "fewer steps leak less: %.4f vs %.4f", few, with);
    lab_close(both);
    lab_close(low);
}

/* A wall 2 cm thick and 1 high standing on the ground, a sphere light beside
 * and above it: the wall's footprint in the map is a few texels wide, and a
 * march whose step in the map is wider steps over it (the ray is in front of
 * the ground before the wall and of the ground after it). Measured: umbra
 * leak 0.051, 0.0043 and 0.0006 at 2, 4 and 16 steps (with `steps` ignored,
 * always 16: 0.0006 each, and the test fails). */
static const char *const wall_scene =
    "return {\n"
    "  camera = { position = {1.5, 3.5, 3.5}, target = {0.8, 0, 0}, fov = 45, width = 128, height = 96 },\n"
    "  lights = { { type = 'sphere', position = {-1.2, 2.5, 0}, radius = 0.2 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {8, 8} },\n"
    "    { name = 'wall', shape = 'box', size = {0.02, 1, 3}, translate = {0, 0.5, 0} },\n"
    "  },\n"
    "}\n";

TEST(test_smrt_thin_wall_leaks_when_steps_are_few)
{
    Lab *lab = fixture_lab("wall.lua", wall_scene);
    CHECK(lab);
    const char *s2[] = {"steps=2", NULL}, *s4[] = {"steps=4", NULL}, *s16[] = {"steps=16", NULL};
    double l2 = region_stat(lab, s2, REGION_UMBRA, true), l4 = region_stat(lab, s4, REGION_UMBRA, true);
    double l16 = region_stat(lab, s16, REGION_UMBRA, true);
    printf("    thin wall umbra leak: 2 steps %.4f, 4 steps %.4f, 16 steps %.4f\n", l2, l4, l16);
    CHECK_MSG(l2 > l4 && l4 > l16, "more steps must leak less: %.4f, %.4f, %.4f", l2, l4, l16);
    CHECK_MSG(l2 > 0.02, "two steps should step over the wall: %.4f", l2);
    lab_close(lab);
}

/* Every lit candidate finite and in [0, 1]; how many were checked. */
static long unit_interval(Lab *lab, const char *const *params)
{
    RenderResult r;
    Error err;
    if (!soft_render(lab, "smrt", params, &r)) return -1;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    long n = 0, bad = 0;
    for (long s = 0; cls && s < (long)r.visibility.width * r.visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float v = r.visibility.data[s];
        n++;
        bad += !(v >= 0.0f && v <= 1.0f);
    }
    render_result_free(&r);
    return cls && bad == 0 ? n : -1;
}

/* A sphere light just above the ground (receivers below it at the light's
 * own depth in the cube's bottom face, where a ray toward a light point
 * runs parallel to the face), and a rect light 30 wide over a small scene (most of the light
 * lies outside the map's field of view, so its rays leave the map). */
static const char *const low_light_scene =
    "return {\n"
    "  camera = { position = {0, 3, 4}, target = {0, 0, 0}, fov = 50, width = 64, height = 48 },\n"
    "  lights = { { type = 'sphere', position = {0, 0.06, 0}, radius = 0.05 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
    "    { name = 'box', shape = 'box', size = {0.3, 0.3, 0.3}, translate = {0.6, 0.15, 0} },\n"
    "  },\n"
    "}\n";
/* A 1 x 1 rect light standing on the ground, facing +x: the ground beside
 * it lies in the light's own plane (depth 0 in its map), the ground in
 * front of it at every depth from there on. */
static const char *const standing_light_scene =
    "return {\n"
    "  camera = { position = {2, 3, 3}, target = {1, 0, 0}, fov = 50, width = 64, height = 48 },\n"
    "  lights = { { type = 'rect', position = {0, 0.5, 0}, direction = {1, 0, 0}, up = {0, 1, 0},\n"
    "               width = 1, height = 1 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
    "    { name = 'box', shape = 'box', size = {0.3, 0.3, 0.3}, translate = {1, 0.15, 0} },\n"
    "  },\n"
    "}\n";
static const char *const wide_light_scene =
    "return {\n"
    "  camera = { position = {0, 3, 4}, target = {0, 0, 0}, fov = 50, width = 64, height = 48 },\n"
    "  lights = { { type = 'rect', position = {0, 2, 0}, direction = {0, -1, 0}, up = {0, 0, 1},\n"
    "               width = 30, height = 30 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
    "    { name = 'box', shape = 'box', size = {0.3, 0.3, 0.3}, translate = {0, 0.5, 0} },\n"
    "  },\n"
    "}\n";

TEST(test_smrt_bad_input_stays_finite_in_the_unit_interval)
{
    const char *minimal[] = {"rays=1", "steps=1", NULL};
    Lab *ball = soft_open("sphere-on-plane.lua", (const char *[]){"camera.width=64", "camera.height=48", NULL});
    Lab *low = fixture_lab("low-light.lua", low_light_scene), *wide = fixture_lab("wide-light.lua", wide_light_scene);
    Lab *standing = fixture_lab("standing-light.lua", standing_light_scene);
    CHECK(ball && low && wide && standing);
    long a = unit_interval(ball, minimal), b = unit_interval(low, NULL), c = unit_interval(low, minimal);
    long d = unit_interval(wide, NULL), e = unit_interval(wide, minimal);
    long f = unit_interval(standing, NULL), g = unit_interval(standing, minimal);
    printf("    lit candidates in [0, 1]: rays=1 steps=1 %ld; light at the receivers' depth %ld, %ld (standing rect: "
           "%ld, %ld); light wider than the map %ld, %ld (-1: a value outside)\n",
           a, b, c, f, g, d, e);
    CHECK(a > 0 && b > 0 && c > 0 && d > 0 && e > 0 && f > 0 && g > 0);
    lab_close(ball);
    lab_close(low);
    lab_close(wide);
    lab_close(standing);
}
