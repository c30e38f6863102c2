/* vsm.c -- the moment family of filtered shadow maps, one filtering path
 * (filtered.h) and four reconstructions: `vsm` (Donnelly & Lauritzen 2006,
 * course §4.2.1: Chebyshev's bound on z, z^2), `lvsm` (Lauritzen & McCool
 * 2008, §4.2.2: the bound per uniform depth layer), `evsm` (§4.2.4,
 * "exponential LVSM without layers": the bound on exp-warped depths, the
 * smaller of two), and `msm` (Peters & Klein 2015, not in the course: the
 * Hamburger four-moment lower bound on the shadow with moment bias). */
#include <stdlib.h>
#include "techniques/filtered.h"

typedef enum MomentMethod { METHOD_VSM, METHOD_LVSM, METHOD_EVSM, METHOD_MSM } MomentMethod;

#define MIN_VARIANCE_PARAM                                                                                          \
    {"min_variance", PARAM_FLOAT, 1e-6, 0, 0.25, "normalised depth^2",                                             \
     "lower clamp of the window's variance (M2 - M1^2 cancels to noise, and d ~ mean gives 0/0; 0.25 is the "      \
     "largest variance depths in [0, 1] can have)",                                                                \
     NULL}
#define BLEED_PARAM                                                                                                 \
    {"bleed_reduction", PARAM_FLOAT, 0, 0, 0.99, "",                                                                \
     "light-bleeding reduction (course §4.2.2): bounds below this become 0, the rest is smoothstep-remapped "      \
     "(darker, narrower penumbrae); 0 is off",                                                                     \
     NULL}

/* ---- parameters ---- */

enum { VSM_P_MIN_VAR = FILTER_NUM_PARAMS, VSM_P_BLEED, VSM_P_SLOPE };
static const ParamDesc vsm_params[] = {
    SMAP_MAP_PARAMS, SMAP_DEPTH_BIAS_PARAMS, FILTER_PARAMS(PREFILTER_SAT), MIN_VARIANCE_PARAM, BLEED_PARAM,
    {"slope_moment", PARAM_BOOL, 0, 0, 1, "",
     "Lauritzen 2007 (course §4.2.1 box): add (ddx^2 + ddy^2) / 4 of the depth to M2, the variance of a plane "
     "over the texel (less acne on slopes)",
     NULL},
};
FILTER_CHECK_TABLE(vsm_params);

enum { LVSM_P_LAYERS = FILTER_NUM_PARAMS, LVSM_P_MIN_VAR, LVSM_P_BLEED };
#define LVSM_MAX_LAYERS 16
static const ParamDesc lvsm_params[] = {
    SMAP_MAP_PARAMS, SMAP_DEPTH_BIAS_PARAMS, FILTER_PARAMS(PREFILTER_SAT),
    {"layers", PARAM_INT, 4, 1, LVSM_MAX_LAYERS, "layers",
     "uniform depth layers over the map's depth range, two moments each (1 is plain VSM)", NULL},
    MIN_VARIANCE_PARAM, BLEED_PARAM,
};
FILTER_CHECK_TABLE(lvsm_params);

static const char *const warp_names[] = {"positive", "both", NULL};
enum { EVSM_P_WARPS = FILTER_NUM_PARAMS, EVSM_P_CPOS, EVSM_P_CNEG, EVSM_P_MIN_VAR, EVSM_P_BLEED };
/* Box by default: a SAT's window sums carry an absolute error of about eps
 * times the face's total, while e^(c+ (u - 1)) spans e^-c+ (see prefilter.h). */
static const ParamDesc evsm_params[] = {
    SMAP_MAP_PARAMS, SMAP_DEPTH_BIAS_PARAMS, FILTER_PARAMS(PREFILTER_BOX),
    {"warps", PARAM_ENUM, 1, 0, 1, "",
     "positive: exp(c+ u) and its square (2 components); both: also -exp(-c- u) and its square (4 components), "
     "the result the smaller bound",
     warp_names},
    {"exponent_pos", PARAM_FLOAT, 40, 0.1, 350, "1 / normalised depth",
     "c+ of the warp exp(c+ u); stored scaled by exp(-c+), so any value is finite; fp32 moments underflow where "
     "c+ (1 - u) > 44 (the catalogue's fp32 limit is c < 44), double ones up to 350; a SAT's rounding swamps "
     "moments below ~1e-12 of the face's, so prefilter=box",
     NULL},
    {"exponent_neg", PARAM_FLOAT, 10, 0.1, 350, "1 / normalised depth", "c- of the negative warp -exp(-c- u)",
     NULL},
    MIN_VARIANCE_PARAM, BLEED_PARAM,
};
FILTER_CHECK_TABLE(evsm_params);

enum { MSM_P_BIAS = FILTER_NUM_PARAMS };
static const ParamDesc msm_params[] = {
    SMAP_MAP_PARAMS, SMAP_DEPTH_BIAS_PARAMS, FILTER_PARAMS(PREFILTER_SAT),
    {"moment_bias", PARAM_FLOAT, 3e-5, 0, 1, "",
     "alpha of b' = (1 - alpha) b + alpha (0, 0.63, 0, 0.63): keeps the Hankel matrix positive definite against "
     "rounding (Peters & Klein 2015); more bias, more light leaking; 1 ignores the map",
     NULL},
};
FILTER_CHECK_TABLE(msm_params);

/* ---- state ---- */

typedef struct MomentState {
    FilteredMaps fm;
    MomentMethod method;
    int layers;             /* LVSM */
    bool negative;          /* EVSM: the second warp */
    double c_pos, c_neg;    /* EVSM */
    double min_variance, bleed, moment_bias;
} MomentState;

static bool moment_prepare(const TechContext *ctx, MomentMethod method, MomentSpec spec, MomentState *init,
                           void **state, Error *err)
{
    MomentState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    *st = *init;
    st->method = method;
    if (!filtered_acquire(ctx, spec, &st->fm, err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

static bool vsm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    MomentSpec spec = {.warp = WARP_POWERS, .order = 2, .slope_moment = p[VSM_P_SLOPE] != 0.0};
    MomentState init = {.min_variance = p[VSM_P_MIN_VAR], .bleed = p[VSM_P_BLEED]};
    return moment_prepare(ctx, METHOD_VSM, spec, &init, state, err);
}

static bool lvsm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    MomentSpec spec = {.warp = WARP_LAYERS, .order = (int)p[LVSM_P_LAYERS]};
    MomentState init = {.layers = spec.order, .min_variance = p[LVSM_P_MIN_VAR], .bleed = p[LVSM_P_BLEED]};
    return moment_prepare(ctx, METHOD_LVSM, spec, &init, state, err);
}

static bool evsm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    bool negative = (int)p[EVSM_P_WARPS] == 1;
    MomentSpec spec = {.warp = WARP_EXP, .order = negative ? 4 : 2, .c_pos = p[EVSM_P_CPOS], .c_neg = p[EVSM_P_CNEG]};
    MomentState init = {.negative = negative, .c_pos = spec.c_pos, .c_neg = spec.c_neg,
                        .min_variance = p[EVSM_P_MIN_VAR], .bleed = p[EVSM_P_BLEED]};
    return moment_prepare(ctx, METHOD_EVSM, spec, &init, state, err);
}

static bool msm_prepare(const TechContext *ctx, void **state, Error *err)
{
    MomentSpec spec = {.warp = WARP_POWERS, .order = 4, .signed_depth = true};
    MomentState init = {.moment_bias = ctx->params[MSM_P_BIAS]};
    return moment_prepare(ctx, METHOD_MSM, spec, &init, state, err);
}

/* ---- reconstructions ---- */

/* course §4.2.2: the receiver tests only its own layer i, against
 * phi_i(u); the warp stretches depth by L, so the variance clamp by L^2. */
static double lvsm_lit(const MomentState *st, const double *m, double u)
{
    if (isnan(u)) return NAN; /* no layer to pick */
    int L = st->layers, i = (int)(u * L);
    i = i < 0 ? 0 : i >= L ? L - 1 : i;
    double phi = (u - (double)i / L) * L;
    phi = phi < 0.0 ? 0.0 : phi > 1.0 ? 1.0 : phi;
    return chebyshev_upper(m[2 * i], m[2 * i + 1], phi, st->min_variance * L * L);
}

/* EVSM: Chebyshev on each warp, the clamp scaled by the warp's slope at
 * the receiver (w' = c w), p = min(p+, p-) (course §4.2.4). */
static double evsm_lit(const MomentState *st, const double *m, double u)
{
    double p = evsm_positive_bound(m, u, st->c_pos, st->min_variance);
    return st->negative ? nan_min(p, evsm_negative_bound(m, u, st->c_neg, st->min_variance)) : p;
}

static double moment_lit(const MomentState *st, const FilteredSample *fs)
{
    switch (st->method) {
    case METHOD_VSM: return bleed_reduce(chebyshev_upper(fs->m[0], fs->m[1], fs->u, st->min_variance), st->bleed);
    case METHOD_LVSM: return bleed_reduce(lvsm_lit(st, fs->m, fs->u), st->bleed);
    case METHOD_EVSM: return bleed_reduce(evsm_lit(st, fs->m, fs->u), st->bleed);
    case METHOD_MSM: return msm_lit(fs->m, 2.0 * fs->u - 1.0, st->moment_bias);
    }
    return 1.0;
}

static void moment_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const MomentState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        FilteredSample fs;
        double v = filtered_lookup(&st->fm, ctx, s, &fs) ? moment_lit(st, &fs) : 1.0;
        tech_store(ctx, out, begin, s, (float)(v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v));
    }
}

#define MOMENT_TECHNIQUE(var, tname, tsource, tsummary, table, prep, tmain, tconditions)                           \
    const Technique var = {.name = tname, .family = "filtered", .source = tsource, .summary = tsummary,           \
                           .params = table, .num_params = (int)(sizeof table / sizeof table[0]),                \
                           .resources = filter_resources, .rgb = false, .lights = LIGHTS_ALL, .main_param = tmain, \
                           .conditions = tconditions, .prepare = prep, .evaluate = moment_evaluate, .release = free}

/* The negative warp exists only with both warps. */
static const ParamCondition evsm_conditions[] = {{"exponent_neg", "warps=both"}, {NULL, NULL}};

MOMENT_TECHNIQUE(tech_vsm, "vsm", "course §4.2.1 (Eq. 4.2; Donnelly & Lauritzen 2006), §4.2.2 bleeding reduction",
                 "variance shadow map: Chebyshev's upper bound from the prefiltered z and z^2", vsm_params,
                 vsm_prepare, "K", NULL);
MOMENT_TECHNIQUE(tech_lvsm, "lvsm", "course §4.2.2 (Lauritzen & McCool 2008)",
                 "layered variance shadow map: the Chebyshev bound within the receiver's depth layer", lvsm_params,
                 lvsm_prepare, "layers", NULL);
MOMENT_TECHNIQUE(tech_evsm, "evsm", "course §4.2.4 'EVSM' (Lauritzen & McCool 2008; warp pair erratum)",
                 "exponential variance shadow map: Chebyshev on exp(c+ z) and -exp(-c- z), the smaller bound",
                 evsm_params, evsm_prepare, "K", evsm_conditions);
MOMENT_TECHNIQUE(tech_msm, "msm", "Peters & Klein 2015, Algorithm 2 (Hamburger 4MSM); not in the course",
                 "moment shadow map: the sharpest lower bound on the shadow from four prefiltered moments",
                 msm_params, msm_prepare, "K", NULL);
