/* test_sm.c -- `sm` and `pcf` measured against the ray-traced point-light
 * shadow `hard` (course §2.1.2's claims): a map twice the screen's
 * resolution misclassifies under 1% of light-facing pixels on the default
 * scene; with zero bias the hills and cones show acne that the slope-scaled
 * bias removes; a large constant bias leaks light at the contacts, more as
 * it grows; the depth-layer variants and receiver-plane bias cut acne; a
 * sweep over K builds one depth map. */
#include <string.h>
#include "fixtures.h"
#include "test.h"

#define SCENES "scenes/"

/* Render a technique with "name=value" parameters on the lab's light 1. */
static bool render(Lab *lab, const char *tech, const char *const *assign, int n, RenderResult *out)
{
    Error err;
    const Technique *t = tech_find(tech, &err);
    double params[TECH_MAX_PARAMS];
    if (!t) { printf("    %s\n", err.msg); return false; }
    tech_params_default(t, params);
    for (int i = 0; i < n; i++)
        if (!tech_param_parse(t, assign[i], params, &err)) { printf("    %s\n", err.msg); return false; }
    RenderRequest rq = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    if (!lab_render(lab, &rq, out, &err)) { printf("    %s: %s\n", tech, err.msg); return false; }
    return true;
}

/* Light-facing samples where `est` and `truth` disagree (threshold 0.5):
 * false shadow (truth lit) and false lit (truth shadowed). */
typedef struct Disagree { long candidates, false_shadow, false_lit; } Disagree;

static Disagree disagree(Lab *lab, const Image *est, const Image *truth)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    Disagree d = {0};
    for (long s = 0; cls && s < (long)est->width * est->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float e = est->data[s * est->channels], t = truth->data[s * truth->channels];
        d.candidates++;
        d.false_shadow += t > 0.5f && e < 0.5f;
        d.false_lit += t < 0.5f && e > 0.5f;
    }
    return d;
}

static Lab *open_scene(const char *name)
{
    Error err;
    char path[256];
    snprintf(path, sizeof path, SCENES "%s", name);
    Lab *lab = lab_open(path, NULL, 0, &err);
    if (!lab) printf("    %s\n", err.msg);
    return lab;
}

TEST(test_sm_twice_screen_resolution_misclassifies_under_one_percent)
{
    Lab *lab = open_scene("sphere-on-plane.lua");
    CHECK(lab);
    RenderResult hard, sm;
    const char *p[] = {"map_size=1024"}; /* 480 x 360 screen */
    CHECK(render(lab, "hard", NULL, 0, &hard) && render(lab, "sm", p, 1, &sm));
    Disagree d = disagree(lab, &sm.visibility, &hard.visibility);
    double frac = (double)(d.false_shadow + d.false_lit) / d.candidates;
    printf("    %ld light-facing samples: %ld false shadow, %ld false lit (%.3f%%)\n", d.candidates, d.false_shadow,
           d.false_lit, 100 * frac);
    CHECK(d.candidates > 100000);
    CHECK_MSG(frac < 0.01, "misclassified %.3f%% >= 1%%", 100 * frac);
    render_result_free(&hard);
    render_result_free(&sm);
    lab_close(lab);
}

TEST(test_sm_slope_bias_removes_the_acne_of_zero_bias)
{
    Lab *lab = open_scene("cones-and-hills.lua");
    CHECK(lab);
    RenderResult hard, zero, slope;
    const char *none[] = {"map_size=2048", "slope_bias=0"};
    const char *with[] = {"map_size=2048", "slope_bias=1"};
    CHECK(render(lab, "hard", NULL, 0, &hard) && render(lab, "sm", none, 2, &zero) && render(lab, "sm", with, 2, &slope));
    Disagree a = disagree(lab, &zero.visibility, &hard.visibility), b = disagree(lab, &slope.visibility, &hard.visibility);
    printf("    zero bias: %ld false shadow (acne), %ld false lit; slope bias 1: %ld acne, %ld false lit (of %ld)\n",
           a.false_shadow, a.false_lit, b.false_shadow, b.false_lit, a.candidates);
    CHECK_MSG(a.false_shadow > a.candidates / 20, "zero bias shows too little acne to measure (%ld)", a.false_shadow);
    CHECK_MSG(b.false_shadow * 20 < a.false_shadow, "slope bias leaves %ld of %ld acne samples", b.false_shadow,
              a.false_shadow);
    CHECK(b.false_lit <= a.false_lit + b.candidates / 200); /* and pays for it with few leaks */
    render_result_free(&hard);
    render_result_free(&zero);
    render_result_free(&slope);
    lab_close(lab);
}

TEST(test_sm_large_constant_bias_leaks_at_contacts)
{
    Lab *lab = open_scene("contact.lua");
    CHECK(lab);
    RenderResult hard;
    CHECK(render(lab, "hard", NULL, 0, &hard));
    static const char *const biases[] = {"bias=0", "bias=0.05", "bias=0.2", "bias=0.5"}; /* the box is 1 tall */
    long leaks[4];
    for (int i = 0; i < 4; i++) {
        RenderResult r;
        const char *p[] = {"map_size=2048", biases[i]};
        CHECK(render(lab, "sm", p, 2, &r));
        Disagree d = disagree(lab, &r.visibility, &hard.visibility);
        leaks[i] = d.false_lit;
        printf("    %-9s false lit (leaks) %6ld, false shadow %6ld\n", biases[i], d.false_lit, d.false_shadow);
        render_result_free(&r);
    }
    for (int i = 1; i < 4; i++) CHECK_MSG(leaks[i] > leaks[i - 1], "leaks did not grow from %s to %s", biases[i - 1], biases[i]);
    CHECK(leaks[3] > 4 * (leaks[0] + 10));
    render_result_free(&hard);
    lab_close(lab);
}

TEST(test_sm_layers_and_receiver_plane_need_no_slope_bias)
{
    Lab *lab = open_scene("cones-and-hills.lua");
    CHECK(lab);
    RenderResult hard;
    CHECK(render(lab, "hard", NULL, 0, &hard));
    static const char *const modes[][3] = {{"layers=single", "slope_bias=0", "receiver_plane=false"},
                                           {"layers=second_depth", "slope_bias=0", "receiver_plane=false"},
                                           {"layers=second_depth", "slope_bias=0", "second_layer=peeled"},
                                           {"layers=midpoint", "slope_bias=0", "receiver_plane=false"},
                                           {"layers=dual", "slope_bias=0", "receiver_plane=false"},
                                           /* 1/100 of the slope: the rasterizer snaps vertices to 1/256 texel */
                                           {"layers=single", "slope_bias=0.01", "receiver_plane=true"}};
    long acne[6];
    for (int i = 0; i < 6; i++) {
        RenderResult r;
        const char *p[] = {"map_size=2048", modes[i][0], modes[i][1], modes[i][2]};
        CHECK(render(lab, "sm", p, 4, &r));
        Disagree d = disagree(lab, &r.visibility, &hard.visibility);
        acne[i] = d.false_shadow;
        printf("    %-19s %-20s: false shadow %6ld, false lit %6ld\n", modes[i][0], modes[i][2], d.false_shadow,
               d.false_lit);
        render_result_free(&r);
    }
    for (int i = 1; i < 6; i++) CHECK_MSG(acne[i] * 5 < acne[0], "mode %d leaves %ld of %ld acne samples", i, acne[i], acne[0]);
    render_result_free(&hard);
    lab_close(lab);
}

TEST(test_pcf_kernel_sweep_builds_one_depth_map)
{
    Lab *lab = open_scene("sphere-on-plane.lua");
    CHECK(lab);
    int built = 0, reused = 0;
    for (int k = 3; k <= 31; k += 4) {
        char K[32];
        snprintf(K, sizeof K, "K=%d", k);
        const char *p[] = {K, "map_size=512"};
        RenderResult r;
        rm_log_reset(lab_resources(lab));
        CHECK(render(lab, "pcf", p, 2, &r));
        for (int i = 0; i < rm_log_count(lab_resources(lab)); i++) {
            const ResourceEvent *ev = rm_log_event(lab_resources(lab), i);
            if (strcmp(ev->kind, "shadow_map") != 0) continue;
            built += ev->built;
            reused += !ev->built;
        }
        render_result_free(&r);
    }
    printf("    8 values of K: shadow map built %d, reused %d times\n", built, reused);
    CHECK(built == 1 && reused == 7);
    lab_close(lab);
}

/* A point light in the middle of a closed room (2 triangles per wall) with
 * blockers on every side, so every cube face and seam is used, and a wide
 * plate under the light, made of 2 triangles or of a 32 x 32 grid: the
 * paraboloid maps vertices only, so the plate's straight edges should
 * become curves in the map (course §2.1.1: the scene must be finely
 * tessellated). */
static const char *room_scene(bool fine_plate)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "local objs = { { shape = 'box', size = {8, 5, 8}, translate = {0, 2.5, 0} },\n"
             "  { shape = %s, size = {2.4, 2.4}, rotate = {0, 30, 0}, translate = {0.3, 1.6, 0.2} } }\n"
             "local spots = { {2, 1, 0}, {-2, 3, 1}, {0, 1.2, 2.2}, {1, 4, -2}, {-1.5, 1, -2}, {2.2, 2.5, 2.2} }\n"
             "for i, p in ipairs(spots) do objs[#objs + 1] = { shape = 'box', size = {0.5, 0.5, 0.5},\n"
             "  rotate = {20 * i, 35 * i, 0}, translate = p } end\n"
             "return { camera = { position = {3.5, 4.2, 3.5}, target = {-1, 0.5, -1}, fov = 80, width = 240, "
             "height = 180 },\n"
             "  lights = { { type = 'point', position = {0, 2.5, 0} } }, objects = objs }\n",
             fine_plate ? "'heightfield', resolution = {32, 32}, elevation = function(x, z) return 0 end" : "'plane'");
    return text;
}

static double misclassified(Lab *lab, const RenderResult *truth, const char *tech, const char *const *p, int n)
{
    RenderResult r;
    if (!render(lab, tech, p, n, &r)) return NAN;
    Disagree d = disagree(lab, &r.visibility, &truth->visibility);
    render_result_free(&r);
    return (double)(d.false_shadow + d.false_lit) / (double)d.candidates;
}

TEST(test_sm_omnidirectional_cube_and_paraboloid_against_hard)
{
    const char *pc[] = {"projection=cube", "map_size=512"}, *pp[] = {"projection=paraboloid", "map_size=512"};
    const char *pk[] = {"projection=cube", "map_size=512", "K=7"};
    double cube[2], para[2], pcf[2];
    for (int fine = 0; fine < 2; fine++) {
        Lab *lab = fixture_lab("room.lua", room_scene(fine));
        CHECK(lab);
        RenderResult hard;
        CHECK(render(lab, "hard", NULL, 0, &hard));
        cube[fine] = misclassified(lab, &hard, "sm", pc, 2);
        para[fine] = misclassified(lab, &hard, "sm", pp, 2);
        pcf[fine] = misclassified(lab, &hard, "pcf", pk, 3);
        printf("    %s plate: misclassified: cube %.3f%%, paraboloid %.3f%%, pcf K=7 across cube seams %.3f%%\n",
               fine ? "32x32-grid" : "2-triangle", 100 * cube[fine], 100 * para[fine], 100 * pcf[fine]);
        render_result_free(&hard);
        lab_close(lab);
    }
    for (int fine = 0; fine < 2; fine++) {
        CHECK_MSG(cube[fine] < 0.01, "cube map misclassifies %.3f%%", 100 * cube[fine]);
        CHECK_MSG(pcf[fine] < 0.02, "pcf across cube seams misclassifies %.3f%%", 100 * pcf[fine]);
    }
    CHECK_MSG(para[0] > 3 * para[1] && para[0] > 3 * cube[0],
              "the paraboloid map of a 2-triangle plate should err where the tessellated one does not");
}

TEST(test_sm_fitting_to_the_visible_receivers_beats_the_scene_bounds)
{
    /* a camera close to the ground of a large scene under a directional sun */
    const char *ov[] = {"camera.width=240", "camera.height=180"};
    Error err;
    Lab *lab = lab_open(SCENES "terrain.lua", ov, 2, &err);
    CHECK_MSG(lab, "%s", err.msg);
    RenderResult hard, scene, view;
    const char *ps[] = {"fit=scene", "map_size=1024"}, *pv[] = {"fit=view", "map_size=1024"};
    CHECK(render(lab, "hard", NULL, 0, &hard) && render(lab, "sm", ps, 2, &scene) && render(lab, "sm", pv, 2, &view));
    Disagree a = disagree(lab, &scene.visibility, &hard.visibility), b = disagree(lab, &view.visibility, &hard.visibility);
    printf("    terrain, 1024^2 map: fit scene %ld, fit view %ld misclassified of %ld\n", a.false_shadow + a.false_lit,
           b.false_shadow + b.false_lit, a.candidates);
    CHECK(b.false_shadow + b.false_lit < a.false_shadow + a.false_lit);
    render_result_free(&hard);
    render_result_free(&scene);
    render_result_free(&view);
    lab_close(lab);
}

/* PCF against the Embree reference (course §4.1.2): for a tiny light it
 * anti-aliases the hard edge and stays close to the truth; for a large
 * light its fixed kernel makes the umbra too large and the penumbra too
 * small (Fig. 4.3), and the error in the penumbra grows. */
static double pcf_penumbra_rmse(Lab *lab, const char *K, double *all_rmse)
{
    Error err;
    RenderResult r;
    const char *p[] = {K, "map_size=1024"};
    RefInfo info;
    RefRequest rq = {0, {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const uint8_t *term = res_terminator(lab_resources(lab), lab_scene(lab), 0, &err);
    Metrics m;
    if (!ref || !cls || !term || !render(lab, "pcf", p, 2, &r)) return NAN;
    bool ok = metrics_compute(&r.visibility, ref, cls, term, &m, NULL, &err);
    render_result_free(&r);
    *all_rmse = ok ? m.region[REGION_ALL].rmse : NAN;
    return ok ? m.region[REGION_PENUMBRA].rmse : NAN;
}

TEST(test_pcf_against_the_reference_small_and_large_light)
{
    const char *small_ov[] = {"lights[1].radius=0.02", "camera.width=240", "camera.height=180"};
    const char *large_ov[] = {"lights[1].radius=0.8", "camera.width=240", "camera.height=180"};
    Error err;
    Lab *small = lab_open(SCENES "sphere-on-plane.lua", small_ov, 3, &err);
    Lab *large = lab_open(SCENES "sphere-on-plane.lua", large_ov, 3, &err);
    CHECK(small && large);
    double all_small, all_large;
    double pen_small = pcf_penumbra_rmse(small, "K=3", &all_small), pen_large = pcf_penumbra_rmse(large, "K=3", &all_large);
    printf("    K=3: light radius 0.02: RMSE %.4f (penumbra %.4f); radius 0.8: RMSE %.4f (penumbra %.4f)\n", all_small,
           pen_small, all_large, pen_large);
    /* Bound for the small light: a 3-texel kernel blurs the hard edge over
     * ~1 screen pixel, so only edge pixels err; RMSE over all pixels < 0.05. */
    CHECK(all_small < 0.05);
    CHECK_MSG(pen_large > 0.15 && all_large > 2 * all_small, "a fixed 3-texel kernel cannot follow a wide penumbra");
    lab_close(small);
    lab_close(large);
}

/* Two variants of a scene on one resource manager: the light's radius does
 * not change what a shadow map depends on, so the second variant reuses the
 * BVH, the view samples and the map, and builds only its own sample classes. */
TEST(test_sm_light_radius_variants_share_the_map)
{
    ResourceManager *rm = rm_create();
    const char *small[] = {"lights[1].radius=0.1"}, *large[] = {"lights[1].radius=0.7"};
    Error err;
    Lab *a = lab_open_shared(SCENES "sphere-on-plane.lua", small, 1, rm, &err);
    Lab *b = a ? lab_open_shared(SCENES "sphere-on-plane.lua", large, 1, rm, &err) : NULL;
    CHECK_MSG(rm && a && b, "%s", err.msg);
    RenderResult r;
    const char *p[] = {"map_size=512"};
    CHECK(render(a, "sm", p, 1, &r));
    render_result_free(&r);
    rm_log_reset(rm);
    CHECK(render(b, "sm", p, 1, &r));
    render_result_free(&r);
    int built = 0;
    for (int i = 0; i < rm_log_count(rm); i++) {
        const ResourceEvent *ev = rm_log_event(rm, i);
        printf("    %s %s\n", ev->built ? "built " : "reused", ev->kind);
        built += ev->built;
        CHECK_MSG(ev->built == (strcmp(ev->kind, "sample_classes") == 0), "%s %s", ev->kind,
                  ev->built ? "rebuilt" : "reused");
    }
    CHECK(built == 1);
    lab_close(a);
    lab_close(b);
    rm_destroy(rm);
}
