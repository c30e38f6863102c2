/* csm.c -- `csm`: convolution shadow maps (Annen et al. 2007; course
 * §4.2.3). The step S(d, z) = step(z - d) is expanded in M Fourier terms
 * (Eq. 4.6, c_k = pi (2k - 1): a square wave of period 2 in z - d, so
 * depths lie in [0, 1]),
 *   step(z - d) ~ 1/2 + 2 sum_k (1/c_k) [cos(c_k d) sin(c_k z) - sin(c_k d) cos(c_k z)],
 * so the filter acts on the 2M basis images sin(c_k z), cos(c_k z) and the
 * reconstruction is linear in them (Eq. 4.5). Fixes of §4.2.3 (Fig. 4.8):
 * damping of the high terms (no schedule is given; here exp(-a (k/M)^2)),
 * the offset step(z - (d - o)) (light leaking is "less objectionable"), and
 * a scale and clamp, clamp(s * step, 0, 1) (s = 2: samples no longer shade
 * themselves, since the truncated step is 1/2 at z = d). */
#include <stdlib.h>
#include "techniques/filtered.h"

#define CSM_MAX_TERMS (PREFILTER_MAX_CHANNELS / 2)

enum { P_TERMS = FILTER_NUM_PARAMS, P_OFFSET, P_SCALE, P_DAMPING };

static const ParamDesc csm_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_DEPTH_BIAS_PARAMS,
    FILTER_PARAMS(PREFILTER_SAT),
    {"terms", PARAM_INT, 16, 1, CSM_MAX_TERMS, "terms",
     "M, the Fourier terms (2M channels; course: 16 is usual, 4 rings strongly, Fig. 4.7)", NULL},
    {"offset", PARAM_FLOAT, 0, 0, 1, "normalised depth",
     "o: the step is moved towards the light, step(z - d + o), trading shadow for light leaking (Fig. 4.8 left)",
     NULL},
    {"scale", PARAM_FLOAT, 2, 1, 16, "",
     "s: the result is clamp(s x step, 0, 1), steeper and sharper (Fig. 4.8 right); 1 is no scaling", NULL},
    {"damping", PARAM_FLOAT, 1, 0, 20, "",
     "a: term k is weighted exp(-a (k/M)^2) against Gibbs ringing (the course gives no schedule); 0 is none", NULL},
};
FILTER_CHECK_TABLE(csm_params);

typedef struct CsmState {
    FilteredMaps fm;
    int terms;
    double offset, scale;
    double coef[CSM_MAX_TERMS]; /* 2 exp(-a (k/M)^2) / c_k */
} CsmState;

static bool csm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    CsmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->terms = (int)p[P_TERMS];
    st->offset = p[P_OFFSET];
    st->scale = p[P_SCALE];
    for (int k = 1; k <= st->terms; k++) {
        double x = (double)k / st->terms;
        st->coef[k - 1] = 2.0 * exp(-p[P_DAMPING] * x * x) / (M_PI * (2 * k - 1));
    }
    MomentSpec spec = {.warp = WARP_FOURIER, .order = st->terms};
    if (!filtered_acquire(ctx, spec, &st->fm, err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* Eq. 4.6 at reference d: the basis at d against the filtered basis images. */
static double csm_step(const CsmState *st, const double *m, double d)
{
    double at_d[PREFILTER_MAX_CHANNELS], sum = 0.5;
    fourier_basis(d, st->terms, at_d);
    for (int k = 0; k < st->terms; k++) sum += st->coef[k] * (at_d[2 * k + 1] * m[2 * k] - at_d[2 * k] * m[2 * k + 1]);
    return sum;
}

static void csm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const CsmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        FilteredSample fs;
        double v = 1.0;
        if (filtered_lookup(&st->fm, ctx, s, &fs)) {
            v = st->scale * csm_step(st, fs.m, fs.u - st->offset);
            v = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
        }
        tech_store(ctx, out, begin, s, (float)v);
    }
}

const Technique tech_csm = {
    .name = "csm",
    .family = "filtered",
    .source = "course §4.2.3 (Eqs. 4.4-4.6, Figs. 4.7-4.8; Annen et al. 2007)",
    .summary = "convolution shadow map: the depth test as M prefiltered Fourier terms, with offset, scale, damping",
    .params = csm_params,
    .num_params = (int)(sizeof csm_params / sizeof csm_params[0]),
    .resources = filter_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "terms",
    .prepare = csm_prepare,
    .evaluate = csm_evaluate,
    .release = free,
};
