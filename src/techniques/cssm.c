/* cssm.c -- `cssm`: convolution soft shadow maps (Annen et al. 2008; course
 * §5.2.2.3): PCSS whose blocker search and filter are both linear in
 * prefiltered basis images, read from one summed-area table over windows of
 * any size (course §5.2.2.2), so a receiver costs O(M) at any light size.
 *   filter: CSM (course Eq. 4.6, csm.c): the lit fraction over the penumbra
 *     window is E step(z - d) ~ 1/2 + sum_k coef_k (cos(c_k d) E sin(c_k z)
 *     - sin(c_k d) E cos(c_k z)), scaled and clamped as csm's
 *     clamp(s x step, 0, 1) (s = 2: the receiver's own texels, where the
 *     truncated step is 1/2, count lit);
 *   blocker average (course §5.2.2.3):
 *     z_avg = E S̄(d, z) z / E S̄(d, z),  S̄ = 1 - step(z - d),
 *     the denominator 1 - pcf from the same basis, the numerator from the
 *     extra basis images z, z sin(c_k z), z cos(c_k z): E S̄ z = E z -
 *     E z step(z - d), the latter the same series with z as the weight.
 *     Guarded as the course asks: 1 - pcf below lit_threshold is lit, z_avg
 *     is clamped to [0, d].
 * The series runs on half depths, v = u / 2 (WARP_FOURIER_DEPTH): its period
 * is 2 ([OWN], catalogue §4.2.3: |z - d| < 1 is required, it returns 1/2 at
 * +-1), and a map fitted to its casters puts the nearest blockers at u = 0
 * and the farthest receivers at u = 1, where csm's basis on u turns them half
 * lit and, scaled by 2, lit: on the strip test (u = 0 over u = 1) penumbra
 * RMSE 0.197, on overlap.lua 0.187 (umbra +0.25); csm's other remedy, offset
 * 0.1 with scale 1, leaks at every contact within 0.1 of the depth range
 * (the bunny's umbra +0.51). On half depths: 0.052, 0.116 (+0.07), bunny
 * umbra +0.30, the price a transition twice as wide in u (about 2/M of the
 * depth range: contacts closer than that are lost, course §4.2.3 [OWN]).
 * The blocker test runs at d - blocker_offset: with the step 1/2 at z = d,
 * the receiver's own texels would count half a blocker at its own depth and
 * pull z_avg toward d. The half depths, the offset and the threshold are
 * [OWN]: the course gives none, and Annen et al. 2008 was not available to
 * check what the paper uses (their mip-mapped basis images are replaced
 * here by a SAT). Measured at 160 x 120 (strip 128 x 96), 1024^2 (strip
 * 256^2, overlap 512^2), M = 8.
 * The umbra floor (issue 16, scenes/parallel-planes.lua), the basis' limit,
 * not a defect: a window of blockers at one depth u_o filters to the basis
 * at u_o, so the visibility is the series itself at the gap,
 *   V_umbra = s step_M,a((u_o - (u_r - o)) / 2),
 * the damped Gibbs residual (course §4.2.3: damping gives "no guarantee"),
 * never exactly 0, doubled by s = 2 (Annen et al. 2007's scaling, as their
 * public shader's clamp(2 rec, 0, 1)). M = 8, a = 1: -0.009..+0.046 over
 * gaps 0.2..1 in u; damping raises it (a = 2: +0.014..+0.054, the damped
 * weights no longer sum to the step's). Parallel planes, u_o 0.010, u_r
 * 0.981: predicted 0.01823, measured 0.01822 in every deep-umbra sample,
 * above soft-failures.lua's umbra threshold 0.01: its "umbra x0.00" and
 * "penumbra x8.9 (r = 0.03)" count the floor as penumbra. The ramp above
 * the floor is 1.15 / 0.77 / 0.73 x the closed form at r = 0.03 / 0.1 /
 * 0.3 (reference 0.74 / 0.90 / 0.97): blocker_offset 0.1 is inside the
 * step's transition, the receiver's own texels count about 6% blockers and
 * pull z_avg toward d, narrowing the window (0.15: 1.07 / 0.97 x the
 * reference at r = 0.1 / 0.3). `floor` (off by default: the paper's
 * reconstruction) removes the floor at the blocker average (cssm_filter,
 * [OWN]): there the deep umbra is 0 and the umbra's area the reference's
 * (x1.000 at r = 0.1). Tested in test_filtered_soft.c. */
#include <stdlib.h>
#include "techniques/filtsoft.h"

enum {
    P_MAX_RADIUS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PRECISION, P_TERMS, P_DAMPING, P_OFFSET, P_SCALE, P_BLOCKER_OFFSET,
    P_LIT_THRESHOLD, P_FLOOR
};

/* The largest umbra floor removed (floor = 1: [OWN], below). */
#define CSSM_FLOOR_MAX 0.5

static const ParamDesc cssm_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face (with cascades, split_scheme
     * and split_lambda changed no output on the parameter test's scenes) */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_DEPTH_BIAS_PARAMS, /* one reference depth against a prefiltered window */
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"terms", PARAM_INT, 8, 1, FILTSOFT_MAX_TERMS, "terms",
     "M, the Fourier terms on half depths: 4M + 1 basis images (sin, cos, and z times each, and z) in one "
     "summed-area table; the step's transition is about 2/M of the depth range",
     NULL},
    {"damping", PARAM_FLOAT, 1, 0, 20, "",
     "a: term k weighted exp(-a (k/M)^2) against Gibbs ringing, as csm's; 0 is none", NULL},
    {"offset", PARAM_FLOAT, 0, 0, 1, "normalised depth",
     "o: the filter's step is step(z - (d - o)), as csm's (course Fig. 4.8 left): light leaks instead of shadow",
     NULL},
    {"scale", PARAM_FLOAT, 2, 1, 16, "",
     "s: the filter's lit fraction is clamp(s x step, 0, 1), as csm's (2: the receiver's own texels count lit)",
     NULL},
    {"blocker_offset", PARAM_FLOAT, 0.1, 0, 1, "normalised depth",
     "the blocker test is step(z - (d - offset)): texels within about this of the receiver's depth are not "
     "blockers (the truncated step is 1/2 at z = d); larger loses contact blockers (lit)",
     NULL},
    {"lit_threshold", PARAM_FLOAT, 0.02, 1e-6, 0.5, "fraction",
     "1 - pcf over the search window below this is lit (course §5.2.2.3: the denominator nears 0)", NULL},
    {"floor", PARAM_BOOL, 0, 0, 1, "",
     "remove the umbra floor: V' = (V - F) / (1 - F), F the filter's value for a window all at the blocker average "
     "(the series' residual, never 0; [OWN], exact for one blocker depth over the receiver; F at most 0.5); "
     "0: Annen et al.'s clamp(s x step, 0, 1)",
     NULL},
};
FILTER_CHECK_TABLE(cssm_params);

static const char *const cssm_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments", "sat", NULL};

typedef struct CssmState {
    FiltSoft fs;
    const Prefiltered *sat;     /* sin(c_k v), cos(c_k v); u; u sin(c_k v), u cos(c_k v): 4M + 1 channels, v = u/2 */
    int terms;
    double offset, scale, blocker_offset, lit_threshold;
    bool remove_floor;
    double coef[FILTSOFT_MAX_TERMS];
} CssmState;

static bool cssm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    CssmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->terms = (int)p[P_TERMS];
    st->scale = p[P_SCALE];
    st->offset = p[P_OFFSET];
    st->blocker_offset = p[P_BLOCKER_OFFSET];
    st->lit_threshold = p[P_LIT_THRESHOLD];
    st->remove_floor = p[P_FLOOR] != 0.0;
    filtsoft_fourier_coefficients(st->terms, p[P_DAMPING], st->coef);
    bool f64 = (int)p[P_PRECISION] == 0;
    MomentSpec spec = {.warp = WARP_FOURIER_DEPTH, .order = st->terms, .f64 = f64};
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], false, "cssm", err) ||
        !(st->sat = filtsoft_sat(ctx, &st->fs, spec, err))) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* The series' step at normalised depth d from a window's channels m (v = u / 2). */
static double step_at(const CssmState *st, const double *m, double d)
{
    return filtsoft_fourier_step(st->coef, st->terms, m, 1.0, 0.5 * d);
}

/* course §5.2.2.3: the average blocker depth over the search window; false: lit; NaN carried. */
static bool cssm_blocker(const CssmState *st, const SmapReceiver *r, FsWindow w, double u, double *z_avg)
{
    double m[PREFILTER_MAX_CHANNELS];
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, w.hx, w.hy, st->sat->channels, m)) {
        *z_avg = NAN; /* a NaN window: shown, not lit */
        return true;
    }
    const double *zm = m + 2 * st->terms; /* E z, then E z sin, E z cos */
    double d = 0.5 * (u - st->blocker_offset);
    double blocked = 1.0 - filtsoft_fourier_step(st->coef, st->terms, m, 1.0, d);
    if (blocked < st->lit_threshold) return false; /* a NaN passes on */
    double z_blocked = zm[0] - filtsoft_fourier_step(st->coef, st->terms, zm + 1, zm[0], d);
    double z = z_blocked / blocked;
    *z_avg = z < 0.0 ? 0.0 : z > u ? u : z;
    return true;
}

/* The filter's lit fraction s x step, and with `floor` its umbra floor F
 * removed ([OWN]): a window all at the blocker average z_avg (normalised)
 * filters to the basis at z_avg, so F = s step(z_avg - d) is what blockers
 * at that depth return (the damped Gibbs residual at the gap, -0.009..+0.046
 * for M = 8); in a window of blockers at z_avg and receiver texels (s x 1/2
 * = 1 at s = 2) the lit fraction is V = F f + (1 - f) for a blocked fraction f, so
 * (V - F) / (1 - F) = 1 - f exactly. F is capped at CSSM_FLOOR_MAX, where
 * blockers within the step's transition of d (contact, 2/M of the depth
 * range) would divide by 1 - F -> 0; a NaN F stays NaN. */
static double cssm_filter(const CssmState *st, const double *m, double z_avg, double u)
{
    double v = st->scale * step_at(st, m, u - st->offset);
    if (!st->remove_floor) return v;
    double b[PREFILTER_MAX_CHANNELS];
    fourier_basis(0.5 * z_avg, st->terms, b); /* half depths, as the SAT's channels */
    double f = st->scale * step_at(st, b, u - st->offset);
    f = f > CSSM_FLOOR_MAX ? CSSM_FLOOR_MAX : f;
    return (v - f) / (1.0 - f);
}

static double cssm_visibility(const CssmState *st, const SmapReceiver *r)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    double u = filtsoft_unit(&st->fs, r), z_avg, m[PREFILTER_MAX_CHANNELS];
    if (!cssm_blocker(st, r, ws, u, &z_avg)) return 1.0;
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, z_avg), z_min);
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, wf.hx, wf.hy, 2 * st->terms, m)) /* the basis only */
        return NAN;
    return cssm_filter(st, m, z_avg, u);
}

static void cssm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const CssmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = cssm_visibility(st, &r);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_cssm = {
    .name = "cssm",
    .family = "soft",
    .source = "course §5.2.2.3 (Annen et al. 2008, convolution soft shadow maps), Eq. 4.6",
    .summary = "PCSS on CSM's Fourier basis (half depths): blocker average from extra bases z and z times the "
               "basis over the search window, CSM's filter over the penumbra window, one summed-area table",
    .params = cssm_params,
    .num_params = (int)(sizeof cssm_params / sizeof cssm_params[0]),
    .resources = cssm_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "terms",
    .prepare = cssm_prepare,
    .evaluate = cssm_evaluate,
    .release = free,
};
