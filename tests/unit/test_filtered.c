/* test_filtered.c -- the prefiltered shadow maps of course ch.4 (vsm, lvsm,
 * evsm, msm, esm, csm) against PCF of the same width and against the
 * catalogue's derivations: every moment method equals PCF for a planar
 * occluder parallel to a planar receiver; on overlap.lua VSM leaks light
 * where PCF does not, by the closed form f(1-f)D^2 / (f(1-f)D^2 + (d-mu)^2);
 * ESM with c = 80 and 200 stays finite with f32 and f64 box blurs and SATs
 * (where a naive f32 sum overflows); EVSM in f32 at and above its exponent
 * limits (42, 44.36, 88.72, 350) stays finite; an f32 SAT loses MSM's moments where
 * an f64 one keeps them; a sweep over K builds one moment map
 * and one SAT; and nothing is NaN, Inf or outside [0, 1] on contact.lua,
 * at the defaults and at the parameters' bounds. The comparisons with the
 * Embree reference are in test_filtered_reference.c. */
#include <string.h>
#include "filtered_fixtures.h"
#include "fixtures.h"
#include "resources/maps/prefilter.h"
#include "techniques/smap.h"
#include "test.h"

/* Largest and mean |a - b| over light-facing samples, and how many of them
 * `b` puts strictly inside (0.05, 0.95): the comparison must cross a penumbra. */
typedef struct Diff { double max_abs, mean_abs; long penumbra, candidates; } Diff;

static Diff compare_images(Lab *lab, const Image *a, const Image *b)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    Diff d = {0};
    for (long s = 0; cls && s < (long)a->width * a->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        double x = a->data[s * a->channels], y = b->data[s * b->channels];
        d.max_abs = fmax(d.max_abs, fabs(x - y));
        d.mean_abs += fabs(x - y);
        d.penumbra += y > 0.05 && y < 0.95;
        d.candidates++;
    }
    if (d.candidates) d.mean_abs /= d.candidates;
    return d;
}

/* Light straight down onto a 1 x 1 square at y = 1 over the ground at y = 0:
 * in every window the depths take two values, the receiver's and the
 * occluder's (course §4.2.1: there the bound is exact). */
static const char *const parallel_planes =
    "return {\n"
    "  camera = { position = {0.9, 2.2, 1.6}, target = {0.5, 0, 0.3}, fov = 40, width = 160, height = 120 },\n"
    "  lights = { { type = 'directional', direction = {0, -1, 0} } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {4, 4} },\n"
    "    { name = 'square', shape = 'plane', size = {1, 1}, translate = {0, 1, 0} },\n"
    "  },\n"
    "}\n";

TEST(test_moment_methods_equal_pcf_for_parallel_planes)
{
    Lab *lab = fixture_lab("parallel.lua", parallel_planes);
    CHECK(lab);
    static const char *const lookups[][2] = {{"lookup=nearest", "kernel=box"}, {"lookup=bilinear", "kernel=bilinear"}};
    static const char *const methods[][2] = {{"vsm", "min_variance=0"}, {"lvsm", "min_variance=0 layers=3"},
                                             {"evsm", "min_variance=0"}, {"msm", "moment_bias=0.000001"}};
    static const char *const prefilters[] = {"prefilter=box", "prefilter=sat"};
    const char *common = "map_size=256 slope_bias=0 bias=0 K=7";
    for (int l = 0; l < 2; l++) {
        char p[256];
        snprintf(p, sizeof p, "%s %s", common, lookups[l][1]);
        RenderResult pcf;
        CHECK(filtered_render(lab, "pcf", p, &pcf));
        for (int m = 0; m < 4; m++)
            for (int f = 0; f < 2; f++) {
                /* EVSM's warped moments span e^-c+: a SAT's absolute rounding
                 * error (eps times the face's sum) swamps them (see evsm's doc). */
                if (m == 2 && f == 1) continue;
                RenderResult r;
                snprintf(p, sizeof p, "%s %s %s %s", common, lookups[l][0], methods[m][1], prefilters[f]);
                CHECK(filtered_render(lab, methods[m][0], p, &r));
                Diff d = compare_images(lab, &r.visibility, &pcf.visibility);
                printf("    %-4s %-15s %-13s: max |x - pcf| = %.2e over %ld samples (%ld in the penumbra)\n",
                       methods[m][0], lookups[l][0], prefilters[f], d.max_abs, d.candidates, d.penumbra);
                CHECK(d.penumbra > 300);
                /* The receiver is lifted by rt_ray_offset (~1e-5 of the scene) and
                 * depths are float32: the bound is exact up to that. */
                CHECK_MSG(d.max_abs < 2e-3, "%s differs from pcf by %.3g", methods[m][0], d.max_abs);
                render_result_free(&r);
            }
        render_result_free(&pcf);
    }
    lab_close(lab);
}

/* ---- light bleeding on overlap.lua ---- */

typedef struct Bleed {
    long leaking;        /* PCF 0, VSM > 0.05 */
    long compared;       /* of those, windows of two depth clusters */
    long above_limit;    /* VSM above 1 - f, the form's limit as d -> z2 (it decreases in d beyond) */
    double max_vsm, max_closed_diff, mean_vsm, mean_closed;
} Bleed;

/* The catalogue's closed form for two occluders: fraction f at z1 and 1 - f
 * at z2 = z1 + D, receiver at d: p = f(1-f)D^2 / (f(1-f)D^2 + (d - mu)^2). */
static double two_occluders(double f, double z1, double z2, double d)
{
    double var = f * (1 - f) * (z2 - z1) * (z2 - z1), mu = f * z1 + (1 - f) * z2;
    return var / (var + (d - mu) * (d - mu));
}

/* f, z1, z2 of the K x K window at the receiver (split at the midpoint of
 * its depth range); false when the window is not two clusters apart. */
static bool window_clusters(const ShadowMap *m, const SmapReceiver *r, int K, double *f, double *z1, double *z2)
{
    int i0 = (int)floor(r->mc.s - 0.5 * K + 0.5), j0 = (int)floor(r->mc.t - 0.5 * K + 0.5), face = r->mc.face;
    double lo = INFINITY, hi = -INFINITY, s1 = 0, s2 = 0;
    int n1 = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int j = j0; j < j0 + K; j++)
            for (int i = i0; i < i0 + K; i++) {
                double u = prefilter_depth_unit(m, face, shadowmap_texel(m, face, i, j));
                if (pass == 0) { lo = fmin(lo, u); hi = fmax(hi, u); continue; }
                bool near = u < 0.5 * (lo + hi);
                n1 += near;
                if (near) s1 += u; else s2 += u;
            }
    if (!(hi - lo > 0.05) || n1 == 0 || n1 == K * K) return false;
    *f = (double)n1 / (K * K);
    *z1 = s1 / n1;
    *z2 = s2 / (K * K - n1);
    return true;
}

static Bleed measure_bleeding(Lab *lab, const char *params, const Image *vsm, const Image *pcf, int K)
{
    Error err;
    Bleed b = {0};
    const Technique *t = tech_find("vsm", &err);
    double values[TECH_MAX_PARAMS];
    if (!t || !filtered_params(t, params, values)) return b;
    ShadowMapSpec spec = smap_spec(values);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    SmapBias bias = smap_bias(values, lab_scene(lab));
    for (long s = 0; m && vs && cls && s < (long)vsm->width * vsm->height; s++) {
        SmapReceiver r;
        double x = vsm->data[s], f, z1, z2;
        if (cls[s] != SAMPLE_LIT_CANDIDATE || pcf->data[s] > 0.0f || !(x > 0.05)) continue;
        b.leaking++;
        b.max_vsm = fmax(b.max_vsm, x);
        if (!smap_receiver(m, &bias, vs->p_world[s], vs->n_geom_world[s], &r) ||
            !window_clusters(m, &r, K, &f, &z1, &z2))
            continue;
        double closed = two_occluders(f, z1, z2, prefilter_depth_unit(m, r.mc.face, r.ref));
        b.compared++;
        b.above_limit += x > 1.0 - f + 1e-4;
        b.mean_vsm += x;
        b.mean_closed += closed;
        b.max_closed_diff = fmax(b.max_closed_diff, fabs(x - closed));
    }
    if (b.compared) {
        b.mean_vsm /= b.compared;
        b.mean_closed /= b.compared;
    }
    return b;
}

TEST(test_vsm_bleeds_on_overlap_as_the_closed_form_says)
{
    Lab *lab = filtered_open("scenes/overlap.lua", 240, 180);
    CHECK(lab);
    const char *common = "map_size=1024 K=15";
    char pv[256], pp[256];
    snprintf(pv, sizeof pv, "%s lookup=nearest min_variance=0 prefilter=sat", common);
    snprintf(pp, sizeof pp, "%s kernel=box", common);
    RenderResult vsm, pcf;
    CHECK(filtered_render(lab, "vsm", pv, &vsm) && filtered_render(lab, "pcf", pp, &pcf));
    Bleed b = measure_bleeding(lab, pv, &vsm.visibility, &pcf.visibility, 15);
    printf("    %ld samples PCF calls umbra and VSM lights (> 0.05), up to %.3f; of %ld two-slab windows the\n"
           "    mean leak is %.4f measured, %.4f by the closed form, max |measured - closed form| %.1e;\n"
           "    %ld above the form's limit 1 - f\n",
           b.leaking, b.max_vsm, b.compared, b.mean_vsm, b.mean_closed, b.max_closed_diff, b.above_limit);
    CHECK_MSG(b.leaking > 150, "only %ld leaking samples", b.leaking);
    CHECK(b.max_vsm > 0.2);
    CHECK(b.compared > b.leaking / 2);
    /* Each slab's depth varies a little across a window (the light is not
     * straight above), variance the two-point form leaves out. */
    CHECK_MSG(b.max_closed_diff < 0.01, "closed form off by %.3g", b.max_closed_diff);
    CHECK(b.above_limit == 0);
    render_result_free(&vsm);
    render_result_free(&pcf);
    lab_close(lab);
}

/* ---- precision: an f32 SAT ---- */

TEST(test_f32_sat_loses_the_moments_an_f64_sat_keeps)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", 160, 120);
    CHECK(lab);
    const char *common = "map_size=1024 K=9";
    char p[256];
    snprintf(p, sizeof p, "%s kernel=bilinear", common);
    RenderResult pcf;
    CHECK(filtered_render(lab, "pcf", p, &pcf));
    double err[2][2]; /* [vsm, msm][f64, f32] */
    static const char *const techs[] = {"vsm", "msm"}, *const precisions[] = {"f64", "f32"};
    for (int t = 0; t < 2; t++)
        for (int q = 0; q < 2; q++) {
            RenderResult r;
            snprintf(p, sizeof p, "%s lookup=bilinear prefilter=sat precision=%s", common, precisions[q]);
            CHECK(filtered_render(lab, techs[t], p, &r));
            err[t][q] = compare_images(lab, &r.visibility, &pcf.visibility).mean_abs;
            printf("    %s, %s SAT: mean |x - pcf| = %.5f\n", techs[t], precisions[q], err[t][q]);
            render_result_free(&r);
        }
    /* The catalogue: an fp32 SAT over 1024^2 texels reaches ~1e6 (ulp 0.06).
     * Subtracting the face mean keeps VSM's two moments usable here; MSM's
     * fourth powers are lost (measured f64 / f32: 0.0006 / 0.0006 for VSM,
     * 0.0006 / 0.31 for MSM). */
    CHECK(err[0][0] < 0.005 && err[1][0] < 0.005);
    CHECK_MSG(err[1][1] > 20 * err[1][0], "msm: f32 SAT %.4f, f64 %.4f", err[1][1], err[1][0]);
    render_result_free(&pcf);
    lab_close(lab);
}

/* ---- ESM: large exponents ---- */

/* Sum of expf(c u) over the map in float, as a naive fp32 ESM SAT would. */
static float naive_f32_sum(const ShadowMap *m, float c)
{
    float sum = 0.0f;
    for (int j = 0; j < m->res; j++)
        for (int i = 0; i < m->res; i++) sum += expf(c * (float)prefilter_depth_unit(m, 0, shadowmap_texel(m, 0, i, j)));
    return sum;
}

static long bad_samples(Lab *lab, const Image *im)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    long bad = 0;
    for (long s = 0; cls && s < (long)im->width * im->height * im->channels; s++) {
        float v = im->data[s];
        bad += cls[s / im->channels] == SAMPLE_LIT_CANDIDATE && !(v >= 0.0f && v <= 1.0f);
    }
    return bad;
}

TEST(test_esm_large_exponents_stay_finite_in_f32_and_f64)
{
    Error err;
    Lab *lab = filtered_open("scenes/contact.lua", 160, 120);
    CHECK(lab);
    ShadowMapSpec spec = shadowmap_spec_default();
    spec.res = 512;
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    CHECK(m);
    CHECK_MSG(isinf(naive_f32_sum(m, 80.0f)), "a naive f32 sum of exp(80 u) should overflow");
    static const char *const cases[] = {"prefilter=box precision=f64", "prefilter=box precision=f32",
                                        "prefilter=sat precision=f64", "prefilter=sat precision=f32"};
    static const char *const classifiers[] = {"classifier=none", "classifier=value", "classifier=minmax",
                                              "classifier=nbuffer"};
    for (int c = 0; c < 2; c++)
        for (int k = 0; k < 4; k++)
            for (int q = 0; q < 4; q++) {
                char p[256];
                snprintf(p, sizeof p, "map_size=512 K=9 exponent=%d %s %s", c ? 200 : 80, cases[k], classifiers[q]);
                RenderResult r;
                CHECK(filtered_render(lab, "esm", p, &r));
                long bad = bad_samples(lab, &r.visibility);
                CHECK_MSG(bad == 0, "esm %s: %ld samples NaN, Inf or outside [0, 1]", p, bad);
                render_result_free(&r);
            }
    printf("    naive f32 sum of exp(80 u): inf; esm c = 80, 200 x box/sat x f64/f32 x 4 classifiers: all finite\n");
    lab_close(lab);
}

/* ---- EVSM in float32 at and above its exponent limits ---- */

/* EVSM with precision=f32 (the stability probes' defaults keep f64) at the
 * catalogue's fp32 limit c = 42 (course §4.2.4), at ln(FLT_MAX) / 2 = 44.36
 * where exp(2 c u) of an unscaled second moment overflows, at ln(FLT_MAX) =
 * 88.72 and at the range's maximum 350, on either warp, with box blurs and
 * SATs: the moments are stored scaled by exp(-c) (evsm's doc), so every
 * value the range accepts stays finite and in [0, 1]. Below the limit f32
 * must also agree with f64 (nothing has underflowed there yet). */
TEST(test_evsm_f32_at_and_above_its_exponent_limits_stays_finite)
{
    Lab *lab = filtered_open("scenes/contact.lua", 160, 120);
    CHECK(lab);
    static const char *const exponents[] = {"42", "44.36", "88.72", "350"};
    static const char *const prefilters[] = {"box", "sat"};
    static const char *const warps[] = {"positive", "both"};
    int runs = 0;
    for (int e = 0; e < 4; e++)
        for (int f = 0; f < 2; f++)
            for (int w = 0; w < 2; w++)
                for (int which = 0; which < 2; which++) {
                    char p[256];
                    snprintf(p, sizeof p, "map_size=512 K=9 precision=f32 prefilter=%s warps=%s %s=%s", prefilters[f],
                             warps[w], which ? "exponent_neg" : "exponent_pos", exponents[e]);
                    RenderResult r;
                    CHECK(filtered_render(lab, "evsm", p, &r));
                    long bad = bad_samples(lab, &r.visibility);
                    CHECK_MSG(bad == 0, "evsm %s: %ld samples NaN, Inf or outside [0, 1]", p, bad);
                    if (e == 0 && f == 0 && which == 0) {
                        RenderResult r64;
                        snprintf(p, sizeof p, "map_size=512 K=9 precision=f64 prefilter=box warps=%s exponent_pos=42",
                                 warps[w]);
                        CHECK(filtered_render(lab, "evsm", p, &r64));
                        Diff d = compare_images(lab, &r.visibility, &r64.visibility);
                        printf("    evsm c+ = 42, warps=%s, box: mean |f32 - f64| = %.2g, max %.2g over %ld samples\n",
                               warps[w], d.mean_abs, d.max_abs, d.candidates);
                        CHECK_MSG(d.candidates > 0 && d.mean_abs < 1e-3, "f32 and f64 differ by %.3g at c = 42",
                                  d.mean_abs);
                        render_result_free(&r64);
                    }
                    render_result_free(&r);
                    runs++;
                }
    printf("    evsm precision=f32, c = 42, 44.36, 88.72, 350 x box/sat x positive/both x c+/c-: %d runs, all "
           "finite in [0, 1]\n", runs);
    lab_close(lab);
}

/* ---- ESM's classifiers: window bounds ---- */

TEST(test_minmax_pyramid_bounds_and_nbuffer_equals_every_window)
{
    Error err;
    Lab *lab = filtered_open("scenes/cones-and-hills.lua", 64, 48);
    CHECK(lab);
    ShadowMapSpec spec = shadowmap_spec_default();
    spec.res = 200; /* not a power of two: partial nodes and clamped blocks */
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const MinMaxPyramid *pyr = m ? res_minmax_pyramid(lab_resources(lab), m, &err) : NULL;
    CHECK(pyr);
    long windows = 0, loose = 0;
    uint32_t h = 12345u;
    for (int K = 1; K <= PREFILTER_MAX_K; K += 6) {
        const MinMaxBuffer *nb = res_minmax_buffer(lab_resources(lab), m, minmax_buffer_level(K), &err);
        CHECK(nb);
        for (int n = 0; n < 300; n++, windows++) {
            h = h * 1664525u + 1013904223u;
            int i0 = (int)(h >> 8) % (m->res + K) - K / 2, j0 = (int)((h >> 3) % (uint32_t)(m->res + K)) - K / 2;
            float lo = INFINITY, hi = -INFINITY, plo, phi, blo, bhi;
            for (int j = j0; j < j0 + K; j++)
                for (int i = i0; i < i0 + K; i++) {
                    lo = fminf(lo, shadowmap_texel(m, 0, i, j));
                    hi = fmaxf(hi, shadowmap_texel(m, 0, i, j));
                }
            minmax_query(pyr, 0, i0, j0, i0 + K - 1, j0 + K - 1, &plo, &phi);
            minmax_buffer_query(nb, 0, i0, j0, i0 + K - 1, j0 + K - 1, &blo, &bhi);
            CHECK_MSG(plo <= lo && phi >= hi, "pyramid [%g, %g] misses [%g, %g]", plo, phi, lo, hi);
            CHECK_MSG(blo == lo && bhi == hi, "K = %d at (%d, %d): n-buffer [%g, %g], window [%g, %g]", K, i0, j0, blo,
                      bhi, lo, hi);
            loose += plo < lo || phi > hi;
        }
    }
    printf("    %ld windows, K = 1..61: n-buffer exact in all, pyramid conservative, looser in %ld\n", windows, loose);
    CHECK(loose > 0);
    lab_close(lab);
}

/* ---- resource reuse ---- */

static void count_kind(Lab *lab, const char *kind, int *built, int *reused)
{
    for (int i = 0; i < rm_log_count(lab_resources(lab)); i++) {
        const ResourceEvent *ev = rm_log_event(lab_resources(lab), i);
        if (strcmp(ev->kind, kind) != 0) continue;
        *built += ev->built;
        *reused += !ev->built;
    }
}

TEST(test_vsm_kernel_sweep_builds_one_moment_map_and_one_sat)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", 160, 120);
    CHECK(lab);
    int mb = 0, mr = 0, sb = 0, sr = 0, bb = 0, br = 0;
    for (int k = 3; k <= 31; k += 4)
        for (int f = 0; f < 2; f++) {
            char p[128];
            snprintf(p, sizeof p, "map_size=256 K=%d prefilter=%s", k, f ? "box" : "sat");
            RenderResult r;
            rm_log_reset(lab_resources(lab));
            CHECK(filtered_render(lab, "vsm", p, &r));
            count_kind(lab, "moments", &mb, &mr);
            count_kind(lab, "sat", &sb, &sr);
            count_kind(lab, "box_blur", &bb, &br);
            render_result_free(&r);
        }
    printf("    8 values of K, sat and box: moments built %d reused %d; sat built %d reused %d; box blurs built %d\n",
           mb, mr, sb, sr, bb);
    CHECK(mb == 1 && mr == 15);
    CHECK(sb == 1 && sr == 7);
    CHECK(bb == 8 && br == 0);
    lab_close(lab);
}

/* ---- finite output on contacts, at the defaults and at the bounds ---- */

TEST(test_filtered_techniques_are_finite_on_contacts)
{
    Lab *lab = filtered_open("scenes/contact.lua", 120, 90);
    CHECK(lab);
    int techniques = 0, runs = 0;
    for (int ti = 0; ti < tech_count(); ti++) {
        const Technique *t = tech_at(ti);
        if (!filtered_acquires_moments(t)) continue;
        techniques++;
        /* The defaults, then each of the technique's own parameters at its
         * bounds (the stability suite covers every parameter). */
        for (int pi = SMAP_NUM_PARAMS - 1; pi < t->num_params; pi++)
            for (int end = 0; end < 2; end++) {
                const ParamDesc *d = &t->params[pi];
                char p[256];
                if (pi < SMAP_NUM_PARAMS) snprintf(p, sizeof p, "map_size=256");
                else if (d->type == PARAM_ENUM || d->type == PARAM_BOOL)
                    snprintf(p, sizeof p, "map_size=256 %s=%s", d->name,
                             d->type == PARAM_BOOL ? (end ? "true" : "false") : d->choices[end ? (int)d->max : 0]);
                else snprintf(p, sizeof p, "map_size=256 %s=%.17g", d->name, end ? d->max : d->min);
                if (pi < SMAP_NUM_PARAMS && end) continue;
                RenderResult r;
                CHECK(filtered_render(lab, t->name, p, &r));
                long bad = bad_samples(lab, &r.visibility);
                CHECK_MSG(bad == 0, "%s %s: %ld samples NaN, Inf or outside [0, 1]", t->name, p, bad);
                render_result_free(&r);
                runs++;
            }
    }
    printf("    %d prefiltered techniques, %d runs on contact.lua: all finite in [0, 1]\n", techniques, runs);
    CHECK(techniques >= 6);
    lab_close(lab);
}

/* A moment map over PREFILTER_MAX_BYTES is refused before anything is read
 * or allocated, and the refusal suggests precision=f32 only where halving
 * the bytes brings it under the cap: cssm's 33 channels on a 2048^2 cube map
 * need 6.19 GiB in f64 and 3.09 GiB in f32, so neither may suggest it. */
TEST(test_moment_map_refusal_suggests_only_what_fits)
{
    ResourceManager *rm = rm_create();
    CHECK(rm);
    static const struct {
        int res, faces, order;
        bool f64, suggests_f32;
    } cases[] = {
        {2048, 6, 8, true, false},  /* 6.19 GiB: f32's 3.09 GiB is over the cap too */
        {2048, 6, 8, false, false}, /* 3.09 GiB, already f32 */
        {8192, 1, 1, true, true},   /* 5 channels: 2.50 GiB, f32 1.25 GiB fits */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ShadowMap map = {.res = cases[k].res, .num_faces = cases[k].faces};
        MomentSpec spec = {.warp = WARP_FOURIER_DEPTH, .order = cases[k].order, .f64 = cases[k].f64};
        Error err = {{0}};
        CHECK(!res_moment_map(rm, &map, &spec, &err));
        bool suggests = strstr(err.msg, "precision=f32") != NULL;
        CHECK_MSG(strstr(err.msg, "above the 2 GiB cap") && suggests == cases[k].suggests_f32, "case %zu: %s", k,
                  err.msg);
        printf("    %s\n", err.msg);
    }
    rm_destroy(rm);
}
