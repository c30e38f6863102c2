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
 * not done here: those receivers are called lit (vssm.c splits them). */
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
    {"lit_threshold", PARAM_FLOAT, 1e-4, 1e-9, 0.5, "fraction",
     "the search window's blocked fraction 1 - p below which the receiver is lit: the blocker mean divides by it",
     NULL},
};
FILTER_CHECK_TABLE(pcss_prefiltered_params);

static const char *const pcss_prefiltered_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments",
                                                         "sat", NULL};

typedef struct PpState {
    FiltSoft fs;
    const Prefiltered *sat;
    double min_variance, lit_eps;
} PpState;

static bool pp_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    PpState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->min_variance = p[P_MIN_VAR];
    st->lit_eps = p[P_LIT_EPS];
    MomentSpec spec = {.warp = WARP_POWERS, .order = 2, .f64 = (int)p[P_PRECISION] == 0};
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], false, "pcss_prefiltered", err) ||
        !(st->sat = filtsoft_sat(ctx, &st->fs, spec, err))) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

static double pp_visibility(const PpState *st, const SmapReceiver *r)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    double u = filtsoft_unit(&st->fs, r), m[2], z_occ;
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, ws.hx, ws.hy, 2, m)) return NAN; /* a NaN window */
    double p_search = chebyshev_upper(m[0], m[1], u, st->min_variance);
    if (!filtsoft_blocker_mean(m[0], p_search, u, st->lit_eps, &z_occ)) return 1.0;
    z_occ = filtsoft_unit_clamp(z_occ); /* mu_s and u lie in [0, 1]: rounding only */
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, z_occ), z_min);
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, wf.hx, wf.hy, 2, m)) return NAN;
    return chebyshev_upper(m[0], m[1], u, st->min_variance);
}

static void pp_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const PpState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = pp_visibility(st, &r);
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
