/* esm.c -- `esm`: exponential shadow maps (Annen et al. 2008b, Salvi 2008;
 * course §4.2.4 with its sign erratum): S = exp(c (z_q - d)), so
 * pcf(p) = exp(-c d) sum_q w exp(c z_q), one prefiltered channel. The map
 * stores c u and is filtered in log space (a box blur by log-sum-exp, or a
 * SAT of e^(c u - max)), so no c overflows. Where the assumption z_q <= d
 * fails, a classifier sends the sample to PCF with clamped terms,
 * sum_q w min(1, exp(c (z_q - d_q))): the filtered value above 1 (fast,
 * approximate), or the window's depth bounds on both sides of the receiver,
 * from a min-max pyramid (conservative) or exact from an N-buffer level. */
#include <stdlib.h>
#include "techniques/filtered.h"

enum { CLASSIFY_NONE, CLASSIFY_VALUE, CLASSIFY_MINMAX, CLASSIFY_NBUFFER };
static const char *const classifier_names[] = {"none", "value", "minmax", "nbuffer", NULL};
enum { OUTPUT_VISIBILITY, OUTPUT_FALLBACK };
static const char *const output_names[] = {"visibility", "fallback", NULL};

enum { P_EXPONENT = FILTER_NUM_PARAMS, P_CLASSIFIER, P_OUTPUT, P_RECEIVER_PLANE };

static const ParamDesc esm_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_DEPTH_BIAS_PARAMS,
    FILTER_PARAMS(PREFILTER_BOX),
    {"exponent", PARAM_FLOAT, 80, 0.1, 1000, "1 / normalised depth",
     "c of exp(c z) (course: 80); filtered in log space, so values past fp32's 88.7 and double's 709 stay "
     "finite; a SAT's window sums lose precision as c grows and fall back to PCF",
     NULL},
    {"classifier", PARAM_ENUM, CLASSIFY_NBUFFER, 0, 3, "",
     "where to fall back to PCF (course §4.2.4): none; value (the filtered value exceeds 1); minmax (the "
     "window holds depths on both sides of the receiver, bounded by a min-max mip pyramid's aligned nodes: "
     "conservative, up to 4x the window); nbuffer (the same test with the window's exact bounds, from one "
     "N-buffer level)",
     classifier_names},
    {"output", PARAM_ENUM, OUTPUT_VISIBILITY, 0, 1, "",
     "visibility, or fallback: 1 where the sample was filtered by PCF, 0 elsewhere (the fallback share)",
     output_names},
    SMAP_RECEIVER_PLANE_PARAM(0),
};
FILTER_CHECK_TABLE(esm_params);

/* The receiver plane acts in the PCF fallback only: where a classifier
 * flags a window, or where a SAT's window is below its rounding bound. */
static const ParamCondition esm_conditions[] = {
    {"receiver_plane", "classifier!=none or prefilter=sat"},
    {NULL, NULL},
};

static const char *const esm_resources[] = {"shadow_map", "view_samples", "moments", "box_blur", "sat",
                                            "minmax_pyramid", "minmax_buffer", NULL};

typedef struct EsmState {
    FilteredMaps fm;
    const MinMaxPyramid *pyramid; /* minmax classifier only */
    const MinMaxBuffer *nbuffer;  /* nbuffer classifier only */
    double c;
    int classifier, output;
} EsmState;

static bool esm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    EsmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->c = p[P_EXPONENT];
    st->classifier = (int)p[P_CLASSIFIER];
    st->output = (int)p[P_OUTPUT];
    MomentSpec spec = {.warp = WARP_LOG_EXP, .order = 1, .c_pos = st->c};
    bool ok = filtered_acquire(ctx, spec, &st->fm, err);
    st->fm.bias.receiver_plane = p[P_RECEIVER_PLANE] != 0.0;
    if (ok && st->classifier == CLASSIFY_MINMAX) ok = (st->pyramid = res_minmax_pyramid(ctx->rm, st->fm.map, err));
    if (ok && st->classifier == CLASSIFY_NBUFFER)
        ok = (st->nbuffer = res_minmax_buffer(ctx->rm, st->fm.map, minmax_buffer_level(st->fm.K), err));
    if (!ok) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* The fallback: the same footprint's texels, each term clamped to 1 before
 * the sum (course §4.2.4), each against its own (receiver-plane) depth. */
static double esm_pcf(const EsmState *st, const FilteredSample *fs)
{
    const ShadowMap *m = st->fm.map;
    const PfFootprint *fp = &fs->fp;
    int n = fp->K + fp->bilinear, face = fs->r.mc.face;
    double lit = 0.0;
    for (int b = 0; b < n; b++) {
        double wy = pf_weight(fp, b, fp->ay);
        for (int a = 0; a < n; a++) {
            int i = fp->i0 + a, j = fp->j0 + b;
            double u_q = prefilter_depth_unit(m, face, shadowmap_texel(m, face, i, j));
            double d_q = prefilter_depth_unit(m, face, smap_ref_at(&fs->r, i, j));
            lit += wy * pf_weight(fp, a, fp->ax) * nan_min(1.0, exp(st->c * (u_q - d_q)));
        }
    }
    return lit / ((double)fp->K * fp->K);
}

typedef enum Verdict { VERDICT_LIT, VERDICT_ESM, VERDICT_PCF } Verdict;

/* The bounds classifiers compare the window with the sample's own
 * reference depth; per-texel receiver-plane depths apply in the fallback. */
static Verdict classify(const EsmState *st, const FilteredSample *fs, double esm)
{
    if (!fs->reliable) return VERDICT_PCF;
    if (st->classifier == CLASSIFY_VALUE) return esm > 1.0 ? VERDICT_PCF : VERDICT_ESM;
    if (st->classifier == CLASSIFY_NONE) return VERDICT_ESM;
    const PfFootprint *fp = &fs->fp;
    int last = fp->K - 1 + fp->bilinear;
    float zmin, zmax;
    if (st->pyramid) minmax_query(st->pyramid, fs->r.mc.face, fp->i0, fp->j0, fp->i0 + last, fp->j0 + last, &zmin, &zmax);
    else minmax_buffer_query(st->nbuffer, fs->r.mc.face, fp->i0, fp->j0, fp->i0 + last, fp->j0 + last, &zmin, &zmax);
    if (isnan(zmin) || isnan(zmax)) return VERDICT_PCF; /* a NaN texel: the per-texel terms carry it */
    if (zmin >= fs->r.ref) return VERDICT_LIT;  /* nothing in front: every test passes */
    return zmax > fs->r.ref ? VERDICT_PCF : VERDICT_ESM;
}

static void esm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const EsmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        FilteredSample fs;
        double v = 1.0, fallback = 0.0;
        if (filtered_lookup(&st->fm, ctx, s, &fs)) {
            /* m[0] = ln of the window's mean of exp(c z); the quotient by exp(c d) in log space. */
            double esm = exp(fs.m[0] - st->c * fs.u);
            switch (classify(st, &fs, esm)) {
            case VERDICT_LIT: v = 1.0; break;
            case VERDICT_ESM: v = nan_min(1.0, esm); break;
            case VERDICT_PCF: v = esm_pcf(st, &fs); fallback = 1.0; break;
            }
        }
        tech_store(ctx, out, begin, s, (float)(st->output == OUTPUT_FALLBACK ? fallback : v));
    }
}

const Technique tech_esm = {
    .name = "esm",
    .family = "filtered",
    .source = "course §4.2.4 (Annen et al. 2008b, Salvi 2008; sign erratum), log-space filtering",
    .summary = "exponential shadow map: exp(-c d) times the filtered exp(c z), PCF where a classifier flags it",
    .params = esm_params,
    .num_params = (int)(sizeof esm_params / sizeof esm_params[0]),
    .resources = esm_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "K",
    .conditions = esm_conditions,
    .prepare = esm_prepare,
    .evaluate = esm_evaluate,
    .release = free,
};
