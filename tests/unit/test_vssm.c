/* test_vssm.c -- `vssm`, variance soft shadow maps (Yang, Dong, Feng,
 * Seidel & Kautz 2010; src/techniques/vssm.c), against the Embree reference:
 *   - where the paper claims accuracy, one planar occluder parallel to the
 *     receiver (test_pcss.c's strip) under a square rect light and a sphere
 *     light: penumbra RMSE bounded, and no worse than pcss_prefiltered's;
 *   - split_depth 0 is pcss_prefiltered (the same estimate, one kernel);
 *   - kernel subdivision acts on non-planar receivers (teapot.lua): outputs
 *     and penumbra error change with split_depth, and the sub-kernels'
 *     receiver-plane references keep tilted receivers from shadowing
 *     themselves (contact.lua);
 *   - its failure, occluder fusion on overlap.lua (course Figs. 1.7, 5.19):
 *     signed error measured, the umbra under the overlap leaking.
 * 128 x 96 and 160 x 120 views, 256^2-1024^2 maps, 64- and 256-sample
 * stratified references; 0.6 s at -O2, 8.7 s under ASan+UBSan (load 0.3-1 on 2 cores). */
#include <math.h>
#include "fixtures.h"
#include "signed_error.h"
#include "soft_helpers.h"
#include "techniques/registry.h"
#include "test.h"

#define REF_SAMPLES 256
#define LIGHT_HEIGHT 4.0
#define STRIP_HEIGHT 2.0
/* the sphere light's radius over the strip: the same 1-unit-wide light as the square's */
#define SPHERE_RADIUS 0.5
/* A square window stands for the sphere's disk (PCSS's box over the light's
 * half-extents, filtsoft.h). Across the strip's straight edge the disk's
 * hidden fraction is the circular segment's (theta - sin theta cos theta) / pi,
 * cos theta = x / R, where the box's is linear, (R + x) / 2R: at most 0.054
 * apart (x = R / 2 [derived]), so the penumbra's RMSE lies below that plus
 * the box's 0.004 of rounding; measured 0.0336 (pcss_prefiltered the same). */
#define SPHERE_STRIP_RMSE (0.054 + 0.004)

typedef struct Run { Metrics m; RenderResult r; } Run;

static bool run(Lab *lab, const char *tech, const char *const *params, int samples, Run *out)
{
    if (!soft_render(lab, tech, params, &out->r)) return false;
    if (soft_metrics(lab, &out->r.visibility, samples, &out->m) && out->m.nonfinite == 0) return true;
    render_result_free(&out->r);
    return false;
}

/* Penumbra RMSE of vssm and pcss_prefiltered on the strip under `light`. */
static void strip_pair(const char *light, double *vssm_rmse, double *pp_rmse, double *noise, long *penumbra)
{
    Lab *lab = soft_strip(light, STRIP_HEIGHT);
    *vssm_rmse = *pp_rmse = NAN;
    if (!lab) return;
    const char *p[] = {"map_size=256", NULL};
    Run v, q;
    if (run(lab, "vssm", p, REF_SAMPLES, &v)) {
        if (run(lab, "pcss_prefiltered", p, REF_SAMPLES, &q)) {
            *vssm_rmse = v.m.region[REGION_PENUMBRA].rmse;
            *pp_rmse = q.m.region[REGION_PENUMBRA].rmse;
            *noise = v.m.region[REGION_PENUMBRA].noise_rms;
            *penumbra = v.m.region[REGION_PENUMBRA].count;
            render_result_free(&q.r);
        }
        render_result_free(&v.r);
    }
    lab_close(lab);
}

/* The strip: one planar occluder parallel to the receiver. Each window
 * holds two depths, one the receiver's: Chebyshev's bound is exact there
 * (P = 1 - f), Yang's blocker mean is the occluder's depth and no kernel
 * is split (d > z_mean wherever a blocker is in reach), so vssm is PCSS's
 * exhaustive box. Square light: the box's bound 0.5 / W + 0.004
 * (test_filtered_soft.c: half a texel of edge over the W = 15.75-texel
 * window, and rounding) + 2 noise; sphere light: SPHERE_STRIP_RMSE. */
TEST(test_vssm_parallel_planes_under_rect_and_sphere_lights)
{
    static const struct { const char *name, *light; double bound; } lights[] = {
        {"rect 1 x 1",
         "{ type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1}, width = 1, height = 1 }",
         0.5 / 15.75 + 0.004},
        {"sphere r 0.5", "{ type = 'sphere', position = {0, 4, 0}, radius = 0.5 }", SPHERE_STRIP_RMSE},
    };
    for (int k = 0; k < 2; k++) {
        double v, q, noise = 0.0;
        long pen = 0;
        strip_pair(lights[k].light, &v, &q, &noise, &pen);
        printf("    strip, %s light: penumbra RMSE vssm %.4f, pcss_prefiltered %.4f (noise %.4f, %ld samples), "
               "bound %.4f + 2 noise\n",
               lights[k].name, v, q, noise, pen, lights[k].bound);
        CHECK(pen > 300);
        CHECK_MSG(v <= lights[k].bound + 2.0 * noise, "%s: penumbra RMSE %.4f above the bound", lights[k].name, v);
        CHECK_MSG(v <= q + 1e-6, "%s: vssm %.4f worse than pcss_prefiltered %.4f", lights[k].name, v, q);
    }
}

/* split_depth 0 with the sample's one reference depth is pcss_prefiltered:
 * Yang's blocker mean and Chebyshev's filter over one window each. On
 * contact.lua's tilted floor and boxes the two agree to float rounding. */
TEST(test_vssm_without_subdivision_is_pcss_prefiltered)
{
    Lab *lab = soft_open("contact.lua", NULL);
    CHECK(lab);
    const char *p[] = {"split_depth=0", "receiver_plane=false", NULL};
    RenderResult v, q;
    CHECK(soft_render(lab, "vssm", p, &v));
    CHECK(soft_render(lab, "pcss_prefiltered", NULL, &q));
    Agreement g = soft_agreement(lab, &v.visibility, &q.visibility);
    double worst = 0.0;
    for (long s = 0; s < (long)v.visibility.width * v.visibility.height; s++)
        worst = fmax(worst, fabs((double)v.visibility.data[s] - q.visibility.data[s]));
    printf("    contact: vssm split_depth=0 against pcss_prefiltered over %ld samples: max |difference| %.3g\n",
           g.candidates, worst);
    CHECK(g.candidates > 10000);
    CHECK_MSG(worst <= 1e-6, "split_depth=0 differs from pcss_prefiltered by %.3g", worst);
    render_result_free(&v);
    render_result_free(&q);
    lab_close(lab);
}

/* Kernel subdivision on non-planar receivers. teapot.lua (curved receivers
 * resting on the ground): windows whose mean lies behind the receiver while
 * blockers sit in front are split; the outputs change, the aux channel
 * records the levels, and the penumbra's error drops (measured 0.3379 ->
 * 0.3322 against 64 stratified samples). contact.lua: with the sample's one
 * depth as every sub-kernel's reference, a sub-kernel on the near side of
 * the tilted floor sees the floor's own texels as blockers (lit region dark
 * 0.0380, pcss_prefiltered 0.0036); the receiver plane at each sub-kernel's
 * centre removes that (0.0044). */
TEST(test_vssm_subdivision_acts_on_nonplanar_receivers)
{
    /* the teapot needs its model (SHADOWLAB_MODEL_PATH); without it that part is skipped, said (the parameter
     * test still sees split_depth act) */
    Lab *lab = soft_open("teapot.lua", NULL);
    if (!lab) printf("    note: teapot.obj not on SHADOWLAB_MODEL_PATH: the teapot part skipped\n");
    if (lab) {
        const char *flat[] = {"split_depth=0", NULL}, *split[] = {"split_depth=2", NULL};
        Run a, b;
        CHECK(run(lab, "vssm", flat, 64, &a));
        CHECK(run(lab, "vssm", split, 64, &b));
        Agreement g = soft_agreement(lab, &a.r.visibility, &b.r.visibility);
        long changed = 0, split_samples = 0;
        for (long s = 0; s < (long)b.r.aux.width * b.r.aux.height; s++) {
            changed += a.r.visibility.data[s] != b.r.visibility.data[s];
            split_samples += b.r.aux.data[s] > 0.0f;
    }
    double ra = a.m.region[REGION_PENUMBRA].rmse, rb = b.m.region[REGION_PENUMBRA].rmse;
    printf("    teapot: split_depth 0 -> 2: %ld samples changed (mean |difference| %.4f), %ld split; penumbra RMSE "
           "%.4f -> %.4f, umbra signed %+.4f -> %+.4f\n",
           changed, g.mean_abs, split_samples, ra, rb, a.m.region[REGION_UMBRA].mean_signed,
           b.m.region[REGION_UMBRA].mean_signed);
    CHECK_MSG(changed > 100 && split_samples > 100, "subdivision changed %ld samples", changed);
    CHECK_MSG(rb < ra, "penumbra RMSE %.4f with subdivision, %.4f without", rb, ra);
    render_result_free(&a.r);
    render_result_free(&b.r);
    lab_close(lab);
    }

    lab = soft_open("contact.lua", NULL);
    CHECK(lab);
    const char *no_plane[] = {"receiver_plane=false", NULL};
    Run c, d, e;
    CHECK(run(lab, "vssm", no_plane, 64, &c));
    CHECK(run(lab, "vssm", NULL, 64, &d));
    CHECK(run(lab, "pcss_prefiltered", NULL, 64, &e));
    double dark_c = c.m.region[REGION_LIT].dark_mean, dark_d = d.m.region[REGION_LIT].dark_mean,
           dark_e = e.m.region[REGION_LIT].dark_mean;
    printf("    contact: lit region dark: one reference depth %.4f, receiver plane %.4f, pcss_prefiltered %.4f\n",
           dark_c, dark_d, dark_e);
    CHECK_MSG(dark_d <= dark_e + 0.005, "receiver-plane sub-kernels darken the lit floor by %.4f", dark_d);
    CHECK_MSG(dark_c > 4.0 * dark_d, "the receiver plane changed the lit region's darkening little (%.4f, %.4f)",
              dark_c, dark_d);
    render_result_free(&c.r);
    render_result_free(&d.r);
    render_result_free(&e.r);
    lab_close(lab);
}

/* Occluder fusion on overlap.lua under a 0.9 x 0.9 rect light (course
 * Figs. 1.7, 5.19; test_filtered_soft.c's case): where the two slabs share
 * a window one blocker mean stands for both and Chebyshev's bound over two
 * occluder depths and the floor is loose, so the umbra under the overlap
 * leaks (positive signed error) and the strip's bound breaks on a share of
 * the penumbra; subdivision does not help (the receiver lies behind every
 * window's mean there, the case Chebyshev handles). Measured, 512^2 map:
 * penumbra RMSE 0.0957, umbra signed +0.1615 (pcss_prefiltered: 0.0961, +0.1615). */
TEST(test_vssm_overlap_fusion_leaks_in_the_umbra)
{
    const char *light[] = {"lights[1]={type='rect', position={-1.0, 5.0, -1.5}, direction={0, -1, 0}, up={0, 0, -1}, "
                           "width=0.9, height=0.9}",
                           NULL};
    Lab *lab = soft_open("overlap.lua", light);
    CHECK(lab);
    const char *p[] = {"map_size=512", NULL};
    RenderResult r;
    Metrics m;
    Image e;
    CHECK(soft_render(lab, "vssm", p, &r));
    CHECK(signed_error(lab, &r.visibility, REF_SAMPLES, &m, &e));
    const ErrorStats *pe = &m.region[REGION_PENUMBRA], *um = &m.region[REGION_UMBRA];
    double bound = 0.5 / 15.75 + 0.004 + 4.0 * pe->noise_rms;
    long over = signed_error_count(&e, -bound, bound);
    printf("    overlap: penumbra RMSE %.4f signed %+.4f (leak %.4f, dark %.4f); umbra signed %+.4f over %ld samples; "
           "|e| > %.3f: %ld samples (penumbra %ld)\n",
           pe->rmse, pe->mean_signed, pe->leak_mean, pe->dark_mean, um->mean_signed, um->count, bound, over,
           pe->count);
    CHECK(m.nonfinite == 0 && outside_unit_range(&r.visibility) == 0);
    CHECK_MSG(um->count > 300 && um->mean_signed > 0.05, "umbra signed %+.4f: no fusion leak", um->mean_signed);
    CHECK_MSG(over > pe->count / 50, "only %ld samples break the strip's bound", over);
    image_free(&e);
    render_result_free(&r);
    lab_close(lab);
}
