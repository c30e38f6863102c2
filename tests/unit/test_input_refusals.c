/* test_input_refusals.c -- regression tests for the engine bugs the stability
 * suite found (issue 7): raw parameter values handed to lab_render, light
 * images with NaN/Inf/negative texels, and procedural geometry past the
 * scene's triangle budget are refused with a message naming what is wrong,
 * before any computation. */
#include <math.h>
#include <string.h>
#include "fixtures.h"
#include "io/exr.h"
#include "test.h"

static const char *const scene_text =
    "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 8, height = 6 },\n"
    "  lights = { { type = 'sphere', position = {0, 4, 0}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane' }, { shape = 'box', translate = {0, 0.5, 0} } } }\n";

TEST(test_lab_render_refuses_raw_nonfinite_and_out_of_range_params)
{
    Lab *lab = fixture_lab("s.lua", scene_text);
    CHECK(lab);
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        for (int k = 0; k < t->num_params; k++) {
            const double bad[] = {NAN, INFINITY, t->params[k].max + 1.0};
            for (int b = 0; b < 3; b++) {
                double v[TECH_MAX_PARAMS];
                tech_params_default(t, v);
                v[k] = bad[b];
                RenderRequest req = {t, v, 0, 1};
                RenderResult out;
                Error err = {{0}};
                bool ok = lab_render(lab, &req, &out, &err);
                if (ok) render_result_free(&out);
                CHECK_MSG(!ok, "%s: lab_render accepted %s = %g", t->name, t->params[k].name, bad[b]);
                CHECK_MSG(strstr(err.msg, t->params[k].name), "%s", err.msg);
            }
        }
    }
    lab_close(lab);
}

/* A 2 x 2 RGB light image with one texel set to `texel`. */
static void write_light(const char *name, float texel)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", test_tmpdir(), name);
    float r[4] = {1, 1, texel, 1}, g[4] = {1, 1, 1, 1}, b[4] = {1, 1, 1, 1};
    const ExrChannel ch[3] = {{"R", r, 1}, {"G", g, 1}, {"B", b, 1}};
    Error err;
    if (!exr_write(path, 2, 2, ch, 3, NULL, 0, &err)) test_fail(__FILE__, __LINE__, "%s", err.msg);
}

TEST(test_scene_refuses_light_images_with_nonfinite_or_negative_texels)
{
    const float bad[] = {NAN, INFINITY, -0.5f};
    for (int i = 0; i < 3; i++) {
        write_light("light.exr", bad[i]);
        const char *path = fixture_file(
            "s.lua", "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 8, height = 6 },\n"
                     "  lights = { { type = 'textured_rect', position = {0, 4, 0}, direction = {0, -1, 0},\n"
                     "               width = 1, height = 1, image = 'light.exr' } },\n"
                     "  objects = { { shape = 'plane' } } }\n");
        Scene sc;
        Error err;
        bool ok = scene_load(path, NULL, 0, &sc, &err);
        if (ok) scene_free(&sc);
        CHECK_MSG(!ok, "accepted a light image with texel %g", bad[i]);
        CHECK_MSG(strstr(err.msg, "light.exr") && strstr(err.msg, "texel (0, 1)") && strstr(err.msg, "lights[1].image"),
                  "%s", err.msg);
    }
    write_light("light.exr", 0.0f); /* zero is a valid (black) texel */
    Lab *lab = fixture_lab("ok.lua",
                           "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 8, height = 6 },\n"
                           "  lights = { { type = 'textured_rect', position = {0, 4, 0}, direction = {0, -1, 0},\n"
                           "               width = 1, height = 1, image = 'light.exr' } },\n"
                           "  objects = { { shape = 'plane' } } }\n");
    CHECK(lab);
    lab_close(lab);
}

TEST(test_scene_refuses_geometry_past_the_triangle_budget)
{
    /* Four 2048-segment spheres are 16.8M triangles: the fourth passes the
     * budget of 2^24 and is named in the refusal. */
    const char *four =
        "local o = { { shape = 'plane' } }\n"
        "for i = 1, 4 do o[#o + 1] = { shape = 'sphere', segments = 2048 } end\n"
        "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 4, height = 4 },\n"
        "  lights = { { type = 'point', position = {0, 4, 0} } }, objects = o }\n";
    Scene sc;
    Error err;
    bool ok = scene_load(fixture_file("s.lua", four), NULL, 0, &sc, &err);
    if (ok) scene_free(&sc);
    CHECK_MSG(!ok, "accepted 16.8M triangles");
    CHECK_MSG(strstr(err.msg, "objects[5]") && strstr(err.msg, "16777216"), "%s", err.msg);
}
