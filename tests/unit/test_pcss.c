/* test_pcss.c -- `pcss` (course §5.2.2) where its assumptions hold exactly:
 * a planar occluder parallel to the receiver and to a square light aligned
 * with the map. There the blocker search finds the occluder's one depth, so
 * the window is the exact penumbra, and the soft shadow is the box
 * convolution of the occluder (Soler & Sillion; catalogue §5.2.2): exhaustive
 * PCSS with its box filter reproduces it up to the map's point sampling of
 * the occluder's edges. That sampling moves an edge by at most half a texel,
 * which in a window W texels wide changes the box average by at most 0.5 / W
 * (the strip's edges are straight and run the length of the view, so no
 * window meets two of them): the bound. */
#include <math.h>
#include "soft_helpers.h"
#include "test.h"

#define LIGHT_HEIGHT 4.0
#define STRIP_HEIGHT 2.0
#define STRIP_HALF 0.75
#define LIGHT_WIDTH 1.0

/* Exact visibility at ground point x under the square light: light point a
 * (|a| < w/2, at height 4) is hidden iff its ray crosses the strip's height
 * inside |X| < 0.75, X = x + (a - x) h / 4. */
static double strip_exact(double x)
{
    double k = STRIP_HEIGHT / LIGHT_HEIGHT, w = LIGHT_WIDTH;
    double a0 = (-STRIP_HALF - x * (1.0 - k)) / k, a1 = (STRIP_HALF - x * (1.0 - k)) / k;
    double hidden = fmax(0.0, fmin(0.5 * w, a1) - fmax(-0.5 * w, a0));
    return 1.0 - hidden / w;
}

/* The window width in texels: 2 a (z_p - z_b) / (z_p z_b) / dx. */
static double window_texels(Lab *lab, int map_size)
{
    double z_p = LIGHT_HEIGHT, z_b = LIGHT_HEIGHT - STRIP_HEIGHT;
    return LIGHT_WIDTH * (z_p - z_b) / (z_p * z_b) / soft_map_dx(lab, "pcss", map_size);
}

/* The strip under a 1 x 1 square light aligned with the map's axes. */
static Lab *square_light_strip(void)
{
    return soft_strip("{ type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1}, "
                      "width = 1, height = 1 }",
                      STRIP_HEIGHT);
}

TEST(test_pcss_exhaustive_box_is_the_box_convolution_on_parallel_planes)
{
    Lab *lab = square_light_strip();
    CHECK(lab);
    const char *p[] = {"sampling=exhaustive", "map_size=256", NULL};
    RenderResult r;
    Metrics m;
    CHECK(soft_render(lab, "pcss", p, &r));
    CHECK(soft_metrics(lab, &r.visibility, 1024, &m));
    Error err;
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    double W = window_texels(lab, 256), bound = 0.5 / W, worst = 0;
    int penumbra = 0;
    for (int s = 0; s < vs->count; s++) {
        double e = strip_exact(vs->p_world[s].x);
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        worst = fmax(worst, fabs(r.visibility.data[s] - e));
        penumbra += e > 0.0 && e < 1.0;
    }
    const ErrorStats *pe = &m.region[REGION_PENUMBRA];
    printf("    window %.2f texels, bound 0.5/W = %.4f; against the exact box convolution: max |e| %.4f over %d "
           "penumbra samples; against Embree (1024 stratified): penumbra RMSE %.4f, net of noise %.4f\n",
           W, bound, worst, penumbra, pe->rmse, pe->rmse_debiased);
    CHECK_MSG(penumbra > 1000, "the scene lost its penumbra (%d samples)", penumbra);
    CHECK_MSG(worst <= bound + 1e-3, "max |e| %.4f above the sampling bound %.4f", worst, bound);
    CHECK_MSG(pe->rmse <= bound + pe->noise_rms, "Embree penumbra RMSE %.4f above %.4f + noise %.4f", pe->rmse, bound,
              pe->noise_rms);
    CHECK((m.region[REGION_UMBRA].count == 0 || m.region[REGION_UMBRA].max_abs <= bound + 1e-3) && m.nonfinite == 0);
    render_result_free(&r);
    lab_close(lab);
}

/* The sampled variants approach the exhaustive answer as their taps grow:
 * a regular grid denser than the window's texels nearly is the box. */
TEST(test_pcss_regular_taps_converge_to_the_exhaustive_box)
{
    Lab *lab = square_light_strip();
    CHECK(lab);
    const char *ex[] = {"sampling=exhaustive", "map_size=256", NULL};
    RenderResult box;
    CHECK(soft_render(lab, "pcss", ex, &box));
    double prev = INFINITY;
    static const char *const taps[] = {"filter_taps=4", "filter_taps=36", "filter_taps=400"};
    for (int k = 0; k < 3; k++) {
        const char *p[] = {"sampling=regular", "map_size=256", "blocker_taps=400", taps[k], NULL};
        RenderResult r;
        CHECK(soft_render(lab, "pcss", p, &r));
        Agreement g = soft_agreement(lab, &r.visibility, &box.visibility);
        printf("    regular %s: mean |v - exhaustive| %.5f\n", taps[k], g.mean_abs);
        CHECK_MSG(g.mean_abs < prev, "%s did not get closer (%.5f >= %.5f)", taps[k], g.mean_abs, prev);
        prev = g.mean_abs;
        render_result_free(&r);
    }
    CHECK(prev < 0.01);
    render_result_free(&box);
    lab_close(lab);
}
