/* pcss_prefiltered.c -- `pcss_prefiltered`: PCSS with both windows read
 * from one prefiltered variance map (course §5.2.2.2, variable-size
 * prefiltering: a summed-area table of u and u^2, course §4.2.1), so a
 * receiver costs two SAT lookups at any light size:
 *   1. blocker search window (filtsoft.h): mean mu_s and variance of the
 *      window; Chebyshev's bound (course Eq. 4.2) p_s on the lit fraction
 *      at the receiver's u; the blockers' mean depth from the moment-based
 *      estimate of Yang et al. 2010 (VSSM §4): mu_s = p_s u + (1 - p_s) z_occ,
 *      the lit texels taken at the receiver's depth; no blocker (p_s = 1,
 *      u <= mu_s): lit;
 *   2. the filter window from z_occ (course §5.2.2 step 2);
 *   3. Chebyshev's bound over the filter window (VSM), the PCF stand-in.
 * For one planar occluder and a receiver parallel to it the window holds two
 * depths, one at the receiver's, and Chebyshev's bound is then exact: p =
 * 1 - f for a blocked fraction f, and z_occ the occluder's depth, so the
 * result is the exhaustive PCSS box (pcss.c) up to rounding. VSSM's kernel
 * subdivision for u <= mu_s with blockers present (non-planar receivers) is
 * not done here: those receivers are called lit (vssm.c splits them). The
 * estimate is vssm's at split_depth 0: one function, chebsoft_visibility
 * (filtsoft.h, written out in vssm.c). */
#include <stdlib.h>
#include "techniques/filtsoft.h"

enum { P_MAX_RADIUS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PRECISION, P_MIN_VAR, P_LIT_EPS };

static const ParamDesc pcss_prefiltered_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face (with cascades, split_scheme
     * and split_lambda changed no output on the parameter test's scenes) */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_DEPTH_BIAS_PARAMS, /* one reference depth against a prefiltered window */
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"min_variance", PARAM_FLOAT, 1e-6, 0, 0.25, "normalised depth^2",
     "lower clamp of each window's variance (vsm's: M2 - M1^2 cancels to noise; 0.25 is the largest variance "
     "depths in [0, 1] can have)",
     NULL},
    FILTSOFT_LIT_THRESHOLD_PARAM("blocked fraction 1 - p"),
};
FILTER_CHECK_TABLE(pcss_prefiltered_params);

static const char *const pcss_prefiltered_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments",
                                                         "sat", NULL};

static bool pp_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    ChebSoft *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    if (!chebsoft_init(st, ctx, p[P_MAX_RADIUS], false, (int)p[P_PRECISION] == 0, p[P_MIN_VAR], p[P_LIT_EPS], 0,
                       "pcss_prefiltered", err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

static void pp_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const ChebSoft *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = chebsoft_visibility(st, &r, &(int){0});
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_pcss_prefiltered = {
    .name = "pcss_prefiltered",
    .family = "soft",
    .source = "course §5.2.2.2 (variable-size prefiltering, SAT); blocker mean of Yang et al. 2010 §4",
    .summary = "PCSS from one summed-area table of u, u^2: the blocker mean from Chebyshev's bound over the "
               "search window, then Chebyshev over the penumbra window; two lookups at any light size",
    .params = pcss_prefiltered_params,
    .num_params = (int)(sizeof pcss_prefiltered_params / sizeof pcss_prefiltered_params[0]),
    .resources = pcss_prefiltered_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "max_radius",
    .prepare = pp_prepare,
    .evaluate = pp_evaluate,
    .release = free,
};
