/* test_brabec.c -- `brabec` (course §5.2.1) where Parker's model, which it
 * carries over to depth maps, is close: a long straight occluder edge
 * parallel to the receiver under a disk light. The exact profile across such
 * an edge is the disk's chord-area fraction; Parker's Bernstein interpolant
 * 3 tau^2 - 2 tau^3 differs from it by at most 0.0394 (at tau = 0.236). The
 * map puts the edge within half a texel, which moves tau by at most
 * 0.5 / (2 w) for a half-penumbra w texels wide, and the interpolant's
 * slope is at most 1.5: the bound is 0.0394 + 0.375 / w. */
#include <math.h>
#include "soft_helpers.h"
#include "test.h"

TEST(test_brabec_is_close_to_the_reference_at_a_straight_edge)
{
    Lab *lab = soft_strip("{ type = 'disk', position = {0, 4, 0}, direction = {0, -1, 0}, radius = 0.5 }", 2.0);
    CHECK(lab);
    const char *p[] = {"map_size=512", NULL};
    RenderResult r;
    Metrics m;
    CHECK(soft_render(lab, "brabec", p, &r));
    CHECK(soft_metrics(lab, &r.visibility, 1024, &m));
    const double a = 0.5, z_p = 4.0, z_b = 2.0;
    double w = a * (z_p - z_b) / (z_p * z_b) / soft_map_dx(lab, "brabec", 512);
    double bound = 0.0394 + 0.375 / w;
    const ErrorStats *pe = &m.region[REGION_PENUMBRA];
    printf("    half-penumbra %.2f texels: penumbra %ld samples, max |e| %.4f, RMSE %.4f; bound %.4f + noise %.4f\n", w,
           pe->count, pe->max_abs, pe->rmse, bound, pe->noise_rms);
    CHECK(pe->count > 1000);
    CHECK_MSG(pe->max_abs <= bound + 3 * pe->noise_rms, "max |e| %.4f above %.4f", pe->max_abs, bound);
    CHECK((m.region[REGION_UMBRA].count == 0 || m.region[REGION_UMBRA].mae < 0.01) && m.region[REGION_LIT].mae < 0.01);
    render_result_free(&r);
    lab_close(lab);
}
