/* test_shadow_width.c -- `shadow_width` (seed 003): the software propagation
 * is the exact city-block distance to the nearest unblocked texel and the
 * doubling versions approximate the Euclidean one; with the c_scale of a
 * vanishing light it is the shadow map's hard shadow; on parallel planes with
 * c_scale matched to the light its error is the inner-penumbra model's,
 * derived below, and it never over-darkens; on the overlap scene the united
 * blockers of the occlusion map over-darken (§5); the stiff case sd -> 0 at
 * contact stays finite; a c_scale sweep builds one shadow-width map. */
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "resources/maps/shadowwidth.h"
#include "signed_error.h"
#include "soft_helpers.h"
#include "test.h"

#define REF_SAMPLES 256
/* Over-darkening counted where the estimate is below the reference by more
 * than this: over 3 times the standard error of a 256-sample stratified
 * reference anywhere (at most 0.5/16 = 0.031). */
#define DARK_MARGIN 0.1

/* A ball over the ground under a directional light straight down: an
 * orthographic 64^2 map where the ball is a disc of blocked texels. */
static Lab *ball_lab(void)
{
    return fixture_lab("ball.lua",
                       "return { camera = { position = {0, 5, 3}, target = {0, 0, 0}, width = 32, height = 24 },\n"
                       "  lights = { { type = 'directional', direction = {0, -1, 0} } },\n"
                       "  objects = { { shape = 'plane', size = {4, 4} },\n"
                       "    { shape = 'sphere', radius = 1.2, segments = 64, translate = {0.3, 1.5, 0} } } }\n");
}

/* Brute-force distances from each texel to the nearest unblocked one. */
static void brute_distances(const ShadowMap *peeled, double *l1, double *l2)
{
    int n = peeled->res;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double b1 = INFINITY, b2 = INFINITY;
            for (int y = 0; y < n; y++)
                for (int x = 0; x < n; x++) {
                    if (isfinite(peeled->depth[y * n + x])) continue; /* blocked */
                    b1 = fmin(b1, abs(x - i) + abs(y - j));
                    b2 = fmin(b2, hypot(x - i, y - j));
                }
            l1[j * n + i] = b1;
            l2[j * n + i] = b2;
        }
}

TEST(test_shadow_width_propagation_measures_the_distance_to_light)
{
    Lab *lab = ball_lab();
    CHECK(lab);
    Error err;
    ShadowMapSpec spec = shadowmap_spec_default();
    spec.res = 64;
    ShadowMapSpec ps = spec;
    ps.layer = MAP_LAYER_PEELED;
    const ShadowMap *peeled = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &ps, &err);
    CHECK(peeled);
    double *l1 = malloc(sizeof(double) * 64 * 64), *l2 = malloc(sizeof(double) * 64 * 64);
    CHECK(l1 && l2);
    brute_distances(peeled, l1, l2);
    static const char *const names[] = {SW_PROPAGATION_NAMES};
    /* Ratio of the propagated width to the Euclidean distance, over blocked
     * texels at least 4 texels deep: software4 is the city-block distance
     * (1 to sqrt 2 times it); doubling6's hexagonal steps overestimate by at
     * most 1/cos 30 = 1.155, doubling3's three directions by up to 2 (two
     * steps 60 degrees off the way), and rounding the shifts to whole texels
     * lets a step of cost 1 move up to sqrt 2 texels (ratio down to 0.71). */
    static const double ratio_min[] = {0.999, 0.7, 0.7}, ratio_max[] = {1.4143, 2.1, 1.3};
    for (int p = SW_SOFTWARE4; p <= SW_DOUBLING6; p++) {
        ShadowWidthSpec ws = {(SwPropagation)p, 1.0 / 256.0};
        const ShadowWidthMap *w = res_shadow_width_map(lab_resources(lab), lab_scene(lab), 0, &spec, &ws, &err);
        CHECK(w);
        double lo = INFINITY, hi = 0, worst_l1 = 0;
        long deep = 0;
        for (int k = 0; k < 64 * 64; k++) {
            double steps = shadow_width_texels(w, 0, k % 64, k / 64);
            if (l1[k] == 0) CHECK_MSG(steps == 0, "%s: unblocked texel %d has width %g", names[p], k, steps);
            if (p == SW_SOFTWARE4) worst_l1 = fmax(worst_l1, fabs(steps - fmin(l1[k], 256.0)));
            if (l2[k] < 4) continue;
            lo = fmin(lo, steps / l2[k]);
            hi = fmax(hi, steps / l2[k]);
            deep++;
        }
        printf("    %-9s %d passes, %ld blockers: width / Euclidean distance in [%.3f, %.3f] over %ld deep texels\n",
               names[p], w->passes, w->blockers, lo, hi, deep);
        CHECK(deep > 100);
        CHECK(lo >= ratio_min[p] && hi <= ratio_max[p]);
        if (p == SW_SOFTWARE4) CHECK_MSG(worst_l1 < 1e-3, "software4 differs from the city-block distance by %g", worst_l1);
    }
    free(l1);
    free(l2);
    lab_close(lab);
}

/* The ball's light shrunk to 1e-5 wide (radius 5e-6), where the reference is
 * the hard shadow (test_reference_point_limit). */
#define VANISHING_RADIUS "lights[1].radius=5e-6"
#define VANISHING_REF_SAMPLES 16

TEST(test_shadow_width_vanishing_light_converges_to_sm_and_hard)
{
    const char *const light[] = {VANISHING_RADIUS, NULL};
    Lab *lab = soft_open("sphere-on-plane.lua", light);
    CHECK(lab);
    /* c_scale = 2 D / W for a light 1e-5 wide about 4 from the ball: 8e5. */
    const char *p[] = {"c_scale=8e5", NULL};
    RenderResult sw, sm, hard;
    CHECK(soft_render(lab, "shadow_width", p, &sw) && soft_render(lab, "sm", NULL, &sm) &&
          soft_render(lab, "hard", NULL, &hard));
    Agreement to_sm = soft_agreement(lab, &sw.visibility, &sm.visibility);
    Agreement to_hard = soft_agreement(lab, &sw.visibility, &hard.visibility);
    Metrics m;
    CHECK(soft_metrics(lab, &sw.visibility, VANISHING_REF_SAMPLES, &m));
    printf("    %ld samples: differ from sm %ld, from hard %ld; against the reference RMSE %.4f\n", to_sm.candidates,
           to_sm.differ, to_hard.differ, m.region[REGION_ALL].rmse);
    /* The light's size reaches the test through the reference alone
     * (shadow_width never reads it). Measured: RMSE 0.012 (the map's
     * aliasing), and 0.046 against the reference of the scene's own light
     * (radius 0.4): bound 0.025. */
    CHECK_MSG(m.region[REGION_ALL].rmse < 0.025, "RMSE %.4f against the reference", m.region[REGION_ALL].rmse);
    /* Inside the hard shadow sw >= 1 texel, so I = 0 once c_scale sw > sd:
     * the result is sm's test except where sm has acne on a receiver that
     * blocks nothing (sw = 0 there: lit, §3 property 1) and the last texel
     * rows where sd < c_scale x one texel fails; hard differs by the map's
     * aliasing (under 1%, test_sm). */
    CHECK(to_sm.candidates > 10000);
    CHECK_MSG(to_sm.differ < to_sm.candidates / 1000, "%ld samples differ from sm", to_sm.differ);
    CHECK_MSG(to_hard.differ < to_hard.candidates / 100, "%ld samples differ from hard", to_hard.differ);
    render_result_free(&sw);
    render_result_free(&sm);
    render_result_free(&hard);
    lab_close(lab);
}

/* Render shadow_width with `params`: its metrics and how many samples are
 * darker than the reference by more than DARK_MARGIN. */
static bool render_darker(Lab *lab, const char *const *params, Metrics *m, long *darker)
{
    RenderResult r;
    Image e;
    if (!soft_render(lab, "shadow_width", params, &r)) return false;
    bool ok = signed_error(lab, &r.visibility, REF_SAMPLES, m, &e);
    if (ok) *darker = signed_error_count(&e, -DARK_MARGIN, INFINITY);
    image_free(&e);
    render_result_free(&r);
    return ok;
}

#define STRIP_LIGHT                                                                                                 \
    "{ type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1}, width = 1, height = 1 }"

/* Parallel planes: a 1 x 1 light at height 4, the strip at height 2 (z_b =
 * 2 from the light), the ground at z_r = 4. At distance x inside the hard
 * shadow's edge sw = x and sd = z_r - z_b = 2, so with c_scale = 2 z_b / W
 * = 4, I = 1 - 2x; the truth across the penumbra of width P = W (z_r - z_b)
 * / z_b = 1 is V = 1/2 - x for |x| < 1/2. The error I - V is a tent, 1/2 at
 * the edge and 0 at x = +-1/2 (outside the hard shadow I = 1): its mean is
 * 1/4 (1/4 + 1/200 over the metrics' penumbra 0.01 < V < 0.99), and it is
 * never negative. Bounds: penumbra MAE 0.255 +- 0.03 (texel steps of sw at
 * ~8 mm, the screen's uneven sampling of x), no sample darker than the
 * truth beyond the reference's noise, lit samples exact. */
TEST(test_shadow_width_parallel_planes_inner_penumbra_model)
{
    Lab *lab = soft_strip(STRIP_LIGHT, 2.0);
    CHECK(lab);
    static const char *const props[] = {"neighbours=software4", "neighbours=doubling6"};
    for (int k = 0; k < 2; k++) {
        const char *p[] = {"c_scale=4", props[k], NULL};
        Metrics m;
        long darker;
        CHECK(render_darker(lab, p, &m, &darker));
        const ErrorStats *pe = &m.region[REGION_PENUMBRA];
        printf("    %-20s penumbra %ld: MAE %.4f (model 0.255), %ld darker by > %.2f, lit max %.4f, noise %.4f\n",
               props[k], pe->count, pe->mae, darker, DARK_MARGIN, m.region[REGION_LIT].max_abs, pe->noise_rms);
        CHECK(pe->count > 1000);
        CHECK_NEAR(pe->mae, 0.255, 0.03);
        CHECK(darker == 0);
        CHECK(m.region[REGION_LIT].max_abs < 0.02);
    }
    lab_close(lab);
}

/* Overlap: both slabs are blockers in the inverted occlusion map, so points
 * in the high slab's shadow take their width from the union of the two
 * projections, too wide: darker than the truth (§5, "shadow-width values
 * that are too high ... the shadow gets darker"). c_scale is matched to the
 * high slab (2 x 2.2 / 0.9 = 4.9), which only lightens the low slab's
 * shadow, so over-darkening comes from the union; the single-blocker strip
 * above never over-darkens. */
TEST(test_shadow_width_overlap_united_blockers_over_darken)
{
    Lab *lab = soft_open("overlap.lua", NULL);
    CHECK(lab);
    const char *p[] = {"c_scale=4.9", NULL};
    Metrics m;
    long darker;
    CHECK(render_darker(lab, p, &m, &darker));
    const ErrorStats *pe = &m.region[REGION_PENUMBRA];
    printf("    penumbra %ld: MAE %.4f, over-darkening %.4f, leaks %.4f; %ld samples darker by > %.2f (noise %.4f)\n",
           pe->count, pe->mae, pe->dark_mean, pe->leak_mean, darker, DARK_MARGIN, pe->noise_rms);
    CHECK_MSG(darker > pe->count / 50, "only %ld samples over-darkened", darker);
    lab_close(lab);
}

TEST(test_shadow_width_contact_stiff_case_is_finite)
{
    Lab *lab = soft_open("contact.lua", NULL);
    CHECK(lab);
    static const char *const sets[][4] = {
        {"c_scale=0", NULL},
        {"c_scale=1e6", "c_bias=1", NULL},
        {"neighbours=doubling3", "start_difference=1e-6", "filter=bilinear", NULL},
        {"self_shadow=backfaces", "map_size=16", "slope_bias=0", NULL},
        {"neighbours=doubling6", "start_difference=1", "depth=ndc", NULL},
    };
    for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
        RenderResult r;
        CHECK(soft_render(lab, "shadow_width", sets[k], &r));
        long bad = outside_unit_range(&r.visibility), dark = 0;
        for (size_t i = 0; i < image_count(&r.visibility); i++) dark += r.visibility.data[i] < 1.0f;
        printf("    %-22s %-22s: %ld below 1, %ld not finite in [0, 1]\n", sets[k][0], sets[k][1] ? sets[k][1] : "",
               dark, bad);
        CHECK(bad == 0);
        if (k == 0) { /* c_scale = 0: I = 1 + c_bias clamped, everything lit (the engine's 0 off the candidates) */
            const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, NULL);
            for (long s = 0; cls && s < (long)image_count(&r.visibility); s++)
                if (cls[s] == SAMPLE_LIT_CANDIDATE) CHECK(r.visibility.data[s] == 1.0f);
        }
        render_result_free(&r);
    }
    lab_close(lab);
}

TEST(test_shadow_width_c_scale_sweep_builds_one_width_map)
{
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    static const char *const scales[] = {"c_scale=2", "c_scale=8", "c_bias=0.05"};
    int built = 0, reused = 0;
    for (int k = 0; k < 3; k++) {
        const char *p[] = {scales[k], NULL};
        rm_log_reset(lab_resources(lab));
        RenderResult r;
        CHECK(soft_render(lab, "shadow_width", p, &r));
        for (int i = 0; i < r.num_tech_resources; i++)
            if (strcmp(r.tech_resources[i].kind, "shadow_width_map") == 0) r.tech_resources[i].built ? built++ : reused++;
        render_result_free(&r);
    }
    printf("    shadow_width_map built %d, reused %d\n", built, reused);
    CHECK(built == 1 && reused == 2);
    lab_close(lab);
}
