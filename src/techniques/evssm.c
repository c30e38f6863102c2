/* evssm.c -- `evssm`: PCSS on an exponential variance shadow map (EVSM,
 * course §4.2.4; Lauritzen & McCool 2008), both windows read from one
 * summed-area table of the four warped moments (course §5.2.2.2), so a
 * receiver costs two lookups at any light size:
 *   1. blocker average: on the negative warp n(u) = -e^(-c- u),
 *      Chebyshev's bound q on the lit fraction at the receiver's n(d) and
 *      Yang et al. 2010's estimate (VSSM §4) in the warped domain,
 *      n_occ = (E n - q n(d)) / (1 - q), mapped back through the warp:
 *      z_occ = -ln(-n_occ) / c- [OWN: the estimate carried to the
 *      exponential moments]. By Jensen's inequality that is at most the
 *      blockers' mean depth (a wider window), exact for one depth. On the
 *      negative warp the blockers (u < d) carry the largest |n|, so the
 *      slack of Chebyshev's bound (a receiver's tilted floor in the window)
 *      barely moves n_occ; on the positive warp e^(c+ (u - 1)) blockers are
 *      e^(-c+ gap) below the receiver's own texels and that slack drove
 *      w_occ to 0: z_occ at the near plane, the widest window, umbrae lit
 *      (contact.lua 160 x 120: umbra leak 0.51 -> 0.14 [measured]);
 *   2. the filter window from z_occ (course §5.2.2 step 2);
 *   3. EVSM over it: the smaller Chebyshev bound of the two warps
 *      (course §4.2.4, the warp pair erratum: +e^(c+ u), -e^(-c- u)).
 * A SAT's absolute rounding error is about eps times the face's moment sum
 * (prefilter.h); moments below it (e^(2 c+ (u - 1)) for deep blockers at
 * large c+) are noise, so the exponents default lower than evsm's box blur. */
#include <stdlib.h>
#include "core/nanmath.h"
#include "techniques/filtsoft.h"

enum { P_MAX_RADIUS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PRECISION, P_CPOS, P_CNEG, P_MIN_VAR, P_LIT_EPS };

static const ParamDesc evssm_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face (with cascades, split_scheme
     * and split_lambda changed no output on the parameter test's scenes) */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_DEPTH_BIAS_PARAMS, /* one reference depth against a prefiltered window */
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"exponent_pos", PARAM_FLOAT, 10, 0.1, 80, "1 / normalised depth",
     "c+ of the warp exp(c+ u); the second moment spans e^(-2 c+), and a summed-area table's rounding (about "
     "1e-16 of the face's sum in f64, 1e-7 in f32) swamps what lies below it",
     NULL},
    {"exponent_neg", PARAM_FLOAT, 10, 0.1, 80, "1 / normalised depth", "c- of the negative warp -exp(-c- u)", NULL},
    {"min_variance", PARAM_FLOAT, 1e-6, 0, 0.25, "normalised depth^2",
     "lower clamp of each window's variance, scaled by the warp's slope at the receiver as evsm's", NULL},
    FILTSOFT_LIT_THRESHOLD_PARAM("blocked fraction 1 - p"),
};
FILTER_CHECK_TABLE(evssm_params);

static const char *const evssm_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments", "sat", NULL};

typedef struct EvssmState {
    FiltSoft fs;
    const Prefiltered *sat;
    double c_pos, c_neg, min_variance, lit_eps;
} EvssmState;

static bool evssm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    EvssmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    *st = (EvssmState){.c_pos = p[P_CPOS], .c_neg = p[P_CNEG], .min_variance = p[P_MIN_VAR], .lit_eps = p[P_LIT_EPS]};
    MomentSpec spec = {.warp = WARP_EXP, .order = 4, .c_pos = st->c_pos, .c_neg = st->c_neg,
                       .f64 = (int)p[P_PRECISION] == 0};
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], false, "evssm", err) ||
        !(st->sat = filtsoft_sat(ctx, &st->fs, spec, err))) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* EVSM's bounds on the window's moments (filtered.h), as evsm's. */
static double positive_bound(const EvssmState *st, const double *m, double u)
{
    return evsm_positive_bound(m, u, st->c_pos, st->min_variance);
}

static double negative_bound(const EvssmState *st, const double *m, double u)
{
    return evsm_negative_bound(m, u, st->c_neg, st->min_variance);
}

/* course §4.2.4: p = min(p+, p-). */
static double evsm_bound(const EvssmState *st, const double *m, double u)
{
    return nan_min(positive_bound(st, m, u), negative_bound(st, m, u));
}

/* Step 1: the blockers' normalised depth from the negative warp; false: lit. */
static bool evssm_blocker(const EvssmState *st, const double *m, double u, double *z_occ)
{
    double n_occ;
    if (!filtsoft_blocker_mean(m[2], negative_bound(st, m, u), -exp(-st->c_neg * u), st->lit_eps, &n_occ))
        return false;
    /* e_occ = e^(-c- z_occ); e_occ <= 0 is rounding below the receiver's own moment: blockers at the receiver
     * (a NaN passes on) */
    double e_occ = -n_occ, z = e_occ > 0.0 ? -log(e_occ) / st->c_neg : e_occ <= 0.0 ? u : e_occ;
    *z_occ = nan_clamp(z, 0.0, u);
    return true;
}

static double evssm_visibility(const EvssmState *st, const SmapReceiver *r)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    double u = filtsoft_unit(&st->fs, r), m[4], z_occ;
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, ws.hx, ws.hy, 4, m)) return NAN; /* a NaN window */
    if (!evssm_blocker(st, m, u, &z_occ)) return 1.0;
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, z_occ), z_min);
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, wf.hx, wf.hy, 4, m)) return NAN;
    return evsm_bound(st, m, u);
}

static void evssm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const EvssmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = evssm_visibility(st, &r);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_evssm = {
    .name = "evssm",
    .family = "soft",
    .source = "course §4.2.4 (EVSM), §5.2.2.2 (SAT); blocker mean of Yang et al. 2010 §4 on the warped moments",
    .summary = "PCSS from one summed-area table of EVSM's four moments: the blocker mean from the positive "
               "warp's Chebyshev bound, then EVSM's min of two bounds over the penumbra window",
    .params = evssm_params,
    .num_params = (int)(sizeof evssm_params / sizeof evssm_params[0]),
    .resources = evssm_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "exponent_pos",
    .prepare = evssm_prepare,
    .evaluate = evssm_evaluate,
    .release = free,
};
