/* moment_soft.c -- `moment_soft`: moment soft shadow mapping (Peters,
 * Münstermann, Wetzstein & Klein, "Beyond hard shadows: moment shadow maps
 * for single scattering, soft shadows and translucent occluders", I3D 2016,
 * §5; JCGT 6(1) 2017): PCSS with both windows read from one summed-area
 * table of msm's four moments of the signed depth z = 2u - 1 (course
 * §5.2.2.2), two lookups at any light size:
 *   1. blocker search (filtsoft.h's window): the Hamburger four-moment
 *      reconstruction at the receiver's z_f (msm_blockers, filtered.h: the
 *      three-point distribution on {z_f, z2, z3} that bounds the shadow
 *      below, Peters & Klein 2015 Algorithm 2); the blocked fraction G is
 *      its weight at the roots in front of z_f, the average blocker depth
 *      the mean of those roots under their weights, z_avg = sum w_i z_i / G
 *      (Peters et al. 2016 §5, as the authors' shader computes it). G below
 *      lit_threshold: lit (the paper adds a small constant to G instead, its
 *      "fully lit bias");
 *   2. the filter window from z_avg (course §5.2.2 step 2);
 *   3. msm over it (msm_lit: 1 - the sharpest lower bound).
 * For one planar occluder parallel to the receiver the window holds two
 * depths; four moments of a two-point distribution determine it, so up to
 * the moment bias the roots are the occluder's and the receiver's depths, G
 * the blocked fraction and z_avg the occluder's depth: the exhaustive PCSS
 * box. The paper's depth bias that grows with the kernel is replaced by the
 * shared bias parameters (smap.h). A degenerate quadratic falls back on the
 * first two moments (Chebyshev and Yang et al. 2010's blocker mean, as
 * pcss_prefiltered), as msm_lit does. */
#include <stdlib.h>
#include "techniques/filtsoft.h"

enum { P_MAX_RADIUS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PRECISION, P_MOMENT_BIAS, P_LIT_EPS };

static const ParamDesc moment_soft_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_DEPTH_BIAS_PARAMS, /* one reference depth against a prefiltered window */
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"moment_bias", PARAM_FLOAT, 3e-5, 0, 1, "",
     "alpha of b' = (1 - alpha) b + alpha (0, 0.63, 0, 0.63) in both windows, as msm's: keeps the Hankel matrix "
     "positive definite against rounding; more bias, more light leaking; 1 ignores the map",
     NULL},
    FILTSOFT_LIT_THRESHOLD_PARAM("blocked weight G"),
};
FILTER_CHECK_TABLE(moment_soft_params);

static const char *const moment_soft_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments", "sat",
                                                    NULL};

typedef struct MsState {
    FiltSoft fs;
    const Prefiltered *sat; /* z, z^2, z^3, z^4 of z = 2u - 1 */
    double moment_bias, lit_eps;
} MsState;

static bool ms_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    MsState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->moment_bias = p[P_MOMENT_BIAS];
    st->lit_eps = p[P_LIT_EPS];
    MomentSpec spec = {.warp = WARP_POWERS, .order = 4, .signed_depth = true, .f64 = (int)p[P_PRECISION] == 0};
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], false, "moment_soft", err) ||
        !(st->sat = filtsoft_sat(ctx, &st->fs, spec, err))) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* Step 1: the blockers' mean signed depth; false: lit; NaN carried. */
static bool ms_blocker(const MsState *st, const double *b, double zf, double *z_avg)
{
    double blocked;
    if (!msm_blockers(b, zf, st->moment_bias, &blocked, z_avg)) /* degenerate: two moments */
        return filtsoft_blocker_mean(b[0], chebyshev_upper(b[0], b[1], zf, 0.0), zf, st->lit_eps, z_avg);
    return !(blocked < st->lit_eps); /* a NaN passes on */
}

static double ms_visibility(const MsState *st, const SmapReceiver *r)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    double zf = 2.0 * filtsoft_unit(&st->fs, r) - 1.0, b[4], z_avg;
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, ws.hx, ws.hy, 4, b)) return NAN; /* a NaN window */
    if (!ms_blocker(st, b, zf, &z_avg)) return 1.0;
    double u_avg = filtsoft_unit_clamp(0.5 * (z_avg + 1.0)); /* the roots may stray outside [-1, 1] by rounding */
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, u_avg), z_min);
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, wf.hx, wf.hy, 4, b)) return NAN;
    return msm_lit(b, zf, st->moment_bias);
}

static void ms_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const MsState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = ms_visibility(st, &r);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_moment_soft = {
    .name = "moment_soft",
    .family = "soft",
    .source = "Peters, Münstermann, Wetzstein & Klein 2016 §5 (moment soft shadow mapping); Peters & Klein 2015 "
              "Algorithm 2; course §5.2.2.2 (SAT)",
    .summary = "PCSS from one summed-area table of four moments: the blocked weight and mean depth of the Hamburger "
               "reconstruction's roots in front of the receiver, then msm over the penumbra window",
    .params = moment_soft_params,
    .num_params = (int)(sizeof moment_soft_params / sizeof moment_soft_params[0]),
    .resources = moment_soft_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "moment_bias",
    .prepare = ms_prepare,
    .evaluate = ms_evaluate,
    .release = free,
};
