/* test_input_refusals.c -- regression tests for the engine bugs the stability
 * suite found (issue 7): raw parameter values handed to lab_render, light
 * images with NaN/Inf/negative texels, and procedural geometry past the
 * scene's triangle budget are refused with a message naming what is wrong,
 * before any computation; in-range parameter values work alone (cascades
 * at the default fit), and a declared range is what the technique accepts. */
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

/* cascades = 2 with every other parameter at its default (fit = scene) was
 * refused; each slice is now fitted to its part of the intersection body B,
 * the same maps as fit = body. */
TEST(test_cascades_work_at_the_default_fit)
{
    Lab *lab = fixture_lab("c.lua", "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 32, height = 24 },\n"
                                    "  lights = { { type = 'directional', direction = {0.3, -1, 0.2} } },\n"
                                    "  objects = { { shape = 'plane' }, { shape = 'box', translate = {0, 0.5, 0} } } }\n");
    CHECK(lab);
    Error err;
    const Technique *t = tech_find("sm", &err);
    CHECK(t);
    Image img[2];
    const char *fits[2] = {"fit=scene", "fit=body"};
    for (int k = 0; k < 2; k++) {
        double v[TECH_MAX_PARAMS];
        tech_params_default(t, v);
        CHECK(tech_param_parse(t, "cascades=2", v, &err) && tech_param_parse(t, "map_size=128", v, &err));
        CHECK(tech_param_parse(t, fits[k], v, &err));
        RenderRequest req = {t, v, 0, 1};
        RenderResult out;
        CHECK_MSG(lab_render(lab, &req, &out, &err), "cascades=2 %s refused: %s", fits[k], err.msg);
        img[k] = out.visibility;
        out.visibility = (Image){0};
        render_result_free(&out);
    }
    CHECK(image_count(&img[0]) == image_count(&img[1]));
    CHECK_MSG(!memcmp(img[0].data, img[1].data, sizeof(float) * image_count(&img[0])),
              "fit=scene and fit=body differ with cascades");
    image_free(&img[0]);
    image_free(&img[1]);
    lab_close(lab);
}

/* adaptive_area needs plain perspective maps along the light's normal: its
 * declared ranges of the shared map parameters say so (projection auto, the
 * perspective map of its rect lights; no face split), so the refusal comes when the value is set,
 * naming the parameter and what it accepts, not from inside a render. */
TEST(test_adaptive_area_declares_the_maps_it_accepts)
{
    Error err;
    const Technique *t = tech_find("adaptive_area", &err);
    CHECK(t);
    double v[TECH_MAX_PARAMS];
    tech_params_default(t, v);
    /* assignment, what the refusal must say, what it must not list */
    static const char *const refused[][3] = {
        {"projection=ortho", "projection = ortho is invalid: expected enum one of: auto", "auto, perspective"},
        {"split_scheme=faces", "split_scheme = faces is invalid: expected enum one of: practical, log, uniform",
         "uniform, faces"}};
    for (int i = 0; i < 2; i++) {
        CHECK_MSG(!tech_param_parse(t, refused[i][0], v, &err), "%s accepted", refused[i][0]);
        CHECK_MSG(strstr(err.msg, refused[i][1]) && !strstr(err.msg, refused[i][2]), "%s", err.msg);
    }
    CHECK(tech_param_parse(t, "projection=auto", v, &err) && tech_param_parse(t, "split_scheme=uniform", v, &err));
}
