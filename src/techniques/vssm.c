/* vssm.c -- `vssm`, variance soft shadow maps (Baoguang Yang, Zhao Dong,
 * Jieqing Feng, Hans-Peter Seidel and Jan Kautz, "Variance Soft Shadow
 * Mapping", Computer Graphics Forum 29(7), Pacific Graphics 2010,
 * pp. 2127-2134): PCSS (course §5.2.2) with both of its windows read from
 * one summed-area table of u and u^2 (course §5.2.2.2, §4.2.1), so a
 * receiver costs a bounded number of lookups at any light size:
 *   1. blocker search over filtsoft_search's window: Chebyshev's one-tailed
 *      bound (course Eq. 4.2) P = P(z >= d) at the receiver's normalised
 *      depth d, and the paper's average blocker depth: the window's mean is
 *      z_mean = P d + (1 - P) z_avg, the non-blockers taken at the
 *      receiver's depth, so
 *          z_avg = (z_mean - P d) / (1 - P)
 *      (Yang et al. 2010, the blocker-depth estimate, as filtsoft.h's
 *      filtsoft_blocker_mean; here blocker_depth, summed over sub-kernels);
 *   2. the penumbra window from z_avg by PCSS's similar triangles
 *      (course §5.2.2 step 2, filtsoft_filter_window);
 *   3. the visibility: Chebyshev's bound over that window (VSM).
 * Kernel subdivision (the paper's remedy for non-planar receivers, its
 * abstract: "we avoid incorrectly lit pixels commonly encountered in
 * VSM-based methods by appropriately subdividing the filter kernel"): the
 * one-tailed bound says something only for d > z_mean. Where the receiver
 * is not behind the window's mean (d <= z_mean: a tilted or curved receiver
 * puts texels behind d, which pull the mean past it) Chebyshev returns 1,
 * "lit", whatever blockers the window holds. Such a kernel is split into
 * 2 x 2 sub-kernels of half the half-widths, recursively to `split_depth`
 * levels, and each sub-kernel k is estimated on its own, against its own
 * reference d_k. Three guards are the lab's [OWN]: a kernel is split only
 * where the min-max pyramid finds a depth in front of the receiver
 * (softmap_may_block, exact: a kernel without one is lit, as Chebyshev
 * said); only while the sub-kernels stay at least FILTSOFT_MIN_HALF texels
 * wide (narrower ones are below the map's resolution, and a SAT window's
 * rounding grows as its area shrinks); and d_k is the receiver plane's
 * depth at k's centre (receiver_plane; the sample's one depth otherwise),
 * without which a sub-kernel on the near side of a tilted floor takes the
 * floor's own texels for blockers (contact.lua, lit region: mean darkening
 * 0.0380 with one depth, 0.0044 with the plane; test_vssm.c).
 * Combination (equal-area sub-kernels, area weights w_k = 4^-level):
 *   filter:  V = sum_k w_k P_k, the visibility of the union;
 *   search:  z_avg = sum_k w_k (1 - P_k) z_k / sum_k w_k (1 - P_k), the
 *            blockers' mean over the union with z_k each blocking
 *            sub-kernel's estimate, (1 - P_k) z_k = z_mean_k - P_k d_k
 *            [derived: Yang's formula per sub-kernel, weighted by its
 *            blocked fraction]; a sub-kernel with d_k <= z_mean_k adds no
 *            blockers (P_k = 1). One recursion (kernel_estimate) serves both.
 * With split_depth 0 this is pcss_prefiltered (which calls
 * chebsoft_visibility, filtsoft.h, with split_depth 0); a leaf still at d <= z_mean with
 * blockers in front keeps Chebyshev's 1: what subdivision cannot resolve.
 * The paper's text beyond its abstract was not at hand: the criterion
 * d <= z_mean, the 2 x 2 split and the combinations above follow issue 16's
 * description and are derived here, not checked against its equations.
 * Cost: at most 1 + 4 + ... + 4^D SAT lookups and min-max queries per
 * window, whatever its size; how many are taken depends on the scene (the
 * bunny, 2048^2: 1% of the samples split at light radius 0.05, 58% at 0.8,
 * where the windows are wide enough to split and hold the floor).
 *
 * Precision: the SAT holds u and u^2 less their face means (|values| <= 1),
 * so a corner of a stride x stride face (stride = map_size + 2 PAD) sums at
 * most stride^2 terms through at most 2 stride roundings each (row, then
 * column sums): |error| <= 2 stride^3 eps per corner, and a window of area
 * A texels^2 (four corners) errs by at most 8 stride^3 eps / A in each
 * moment (first-order, Higham §4.2; the bound prefilter.c states for log
 * SATs, here absolute), and the variance M2 - M1^2 by at most 3 times that.
 * f64 (unit roundoff 1.1e-16): 8.4e-6 / A per moment at 2048^2, 6.4e-5 / A
 * at 4096^2; the variance's bound is below min_variance (1e-6) for windows
 * of more than 25 and 190 texels^2 (5 x 5, 14 x 14): smaller sub-kernels at
 * 4096^2 may carry worst-case rounding above the clamp (the typical error,
 * a random walk, is about the square root of the worst case's share).
 * f32 (eps 6e-8) bounds nothing useful at these sizes (catalogue: an fp32
 * SAT destroys moment differences). */
#include <stdlib.h>
#include "techniques/filtsoft.h"

enum { P_MAX_RADIUS = SMAP_NUM_PARAMS, P_PRECISION, P_MIN_VAR, P_LIT_EPS, P_SPLIT_DEPTH };

#define VSSM_MAX_SPLIT_DEPTH 4 /* 4^4 = 256 sub-kernels at most per window */

static const ParamDesc vssm_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face, as pcss_prefiltered */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    /* the receiver plane acts in the sub-kernels' references and the min-max pyramid's lit test */
    SMAP_BIAS_PARAMS_PLANE(1),
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"min_variance", PARAM_FLOAT, 1e-6, 0, 0.25, "normalised depth^2",
     "lower clamp of each (sub-)kernel's variance (vsm's: M2 - M1^2 cancels to noise; 0.25 is the largest "
     "variance depths in [0, 1] can have)",
     NULL},
    FILTSOFT_LIT_THRESHOLD_PARAM("blocked fraction 1 - P"),
    {"split_depth", PARAM_INT, 2, 0, VSSM_MAX_SPLIT_DEPTH, "levels",
     "Yang et al. 2010's kernel subdivision: a window whose mean lies at or behind the receiver (Chebyshev's "
     "bound then says 'lit') while the min-max pyramid finds a blocker in it is split into 2 x 2 sub-kernels, "
     "recursively up to this many levels (sub-kernels at least 1/2 texel wide), in the blocker search and the "
     "filter; 0: no subdivision (pcss_prefiltered)",
     NULL},
};
FILTER_CHECK_TABLE(vssm_params);

static const char *const vssm_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments", "sat", NULL};
/* the deepest subdivision level either window reached (0: none) */
static const char *const vssm_aux[] = {"split_level", NULL};

bool chebsoft_init(ChebSoft *cs, const TechContext *ctx, double max_radius, bool receiver_plane, bool f64,
                   double min_variance, double lit_eps, int split_depth, const char *tech, Error *err)
{
    *cs = (ChebSoft){.min_variance = min_variance, .lit_eps = lit_eps, .split_depth = split_depth};
    MomentSpec spec = {.warp = WARP_POWERS, .order = 2, .f64 = f64};
    return filtsoft_init(&cs->fs, ctx, max_radius, receiver_plane, tech, err) &&
           (cs->sat = filtsoft_sat(ctx, &cs->fs, spec, err));
}

static bool vssm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    ChebSoft *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    if (!chebsoft_init(st, ctx, p[P_MAX_RADIUS], true, (int)p[P_PRECISION] == 0, p[P_MIN_VAR], p[P_LIT_EPS],
                       (int)p[P_SPLIT_DEPTH], "vssm", err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* A kernel: centre (s, t) and half-widths, in map texels of the receiver's face. */
typedef struct Kernel { double s, t, hx, hy; } Kernel;

/* One receiver's query, and the deepest level split for it. */
typedef struct VssmQuery {
    const ChebSoft *st;
    const SmapReceiver *r;
    int deepest;
} VssmQuery;

/* A kernel's estimate, area-weighted over its sub-kernels k (weights w_k):
 * lit = sum_k w_k P_k (Chebyshev's bound, 1 where d_k <= z_mean_k) and
 * blockers = sum_k w_k (z_mean_k - P_k d_k) over the sub-kernels with
 * d_k > z_mean_k, the blocked fraction times the blockers' mean depth. */
typedef struct KernelEstimate { double lit, blockers; } KernelEstimate;

/* The normalised reference depth for kernel k: the receiver plane's at its
 * centre (receiver_plane: a tilted receiver's own texels then lie about it
 * in every sub-kernel), else the sample's one depth. */
static double kernel_reference(const VssmQuery *q, Kernel k)
{
    return prefilter_depth_unit(q->st->fs.sm.map, q->r->mc.face, smap_ref_at_point(q->r, k.s, k.t));
}

/* Sub-kernel c (0..3) of k: the quadrant (c & 1: +s, c & 2: +t). */
static Kernel sub_kernel(Kernel k, int c)
{
    double hx = 0.5 * k.hx, hy = 0.5 * k.hy;
    return (Kernel){k.s + (c & 1 ? hx : -hx), k.t + (c & 2 ? hy : -hy), hx, hy};
}

/* Split k at `level`? Only where Chebyshev is blind (d <= z_mean; false for
 * a NaN), levels and resolution remain, and the min-max pyramid finds a
 * depth in front of the receiver over k's texels (else k is lit). */
static bool should_split(const VssmQuery *q, Kernel k, int level, double d, double z_mean)
{
    if (!(d <= z_mean) || level >= q->st->split_depth) return false;
    if (0.5 * k.hx < FILTSOFT_MIN_HALF || 0.5 * k.hy < FILTSOFT_MIN_HALF) return false;
    return softmap_may_block(&q->st->fs.sm, q->r, (int)floor(k.s - k.hx), (int)floor(k.t - k.hy),
                             (int)floor(k.s + k.hx), (int)floor(k.t + k.hy), NULL);
}

/* The estimate of kernel k at subdivision `level`. A refused window (NaN
 * half-widths) or a NaN moment or depth gives NaN in both fields. */
static KernelEstimate kernel_estimate(VssmQuery *q, Kernel k, int level)
{
    double m[2], d = kernel_reference(q, k);
    if (!pf_fetch_box(q->st->sat, q->r->mc.face, k.s, k.t, k.hx, k.hy, 2, m)) return (KernelEstimate){NAN, NAN};
    if (should_split(q, k, level, d, m[0])) {
        if (level + 1 > q->deepest) q->deepest = level + 1;
        KernelEstimate sum = {0.0, 0.0};
        for (int c = 0; c < 4; c++) {
            KernelEstimate e = kernel_estimate(q, sub_kernel(k, c), level + 1);
            sum.lit += 0.25 * e.lit; /* equal areas */
            sum.blockers += 0.25 * e.blockers;
        }
        return sum;
    }
    double p = chebyshev_upper(m[0], m[1], d, q->st->min_variance); /* NaN for a NaN moment or depth */
    /* the numerator of Yang's z_avg; d <= z_mean: no blockers (P = 1); NaN stays NaN */
    return (KernelEstimate){p, d <= m[0] ? 0.0 : m[0] - p * d};
}

/* Yang et al. 2010's average blocker depth over the search window,
 * z_avg = (z_mean - P d) / (1 - P), summed over sub-kernels (header);
 * false when the blocked fraction 1 - P is below lit_threshold (the caller's
 * "lit"; a NaN passes on into *z_avg). */
static bool blocker_depth(const ChebSoft *st, KernelEstimate e, double *z_avg)
{
    double blocked = 1.0 - e.lit;
    if (blocked < st->lit_eps) return false;
    *z_avg = filtsoft_unit_clamp(e.blockers / blocked); /* z_mean and d lie in [0, 1]: rounding only */
    return true;
}

double chebsoft_visibility(const ChebSoft *st, const SmapReceiver *r, int *deepest)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    VssmQuery q = {st, r, 0};
    double z_avg; /* normalised */
    bool blocked = blocker_depth(st, kernel_estimate(&q, (Kernel){r->mc.s, r->mc.t, ws.hx, ws.hy}, 0), &z_avg);
    *deepest = q.deepest;
    if (!blocked) return 1.0;
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, z_avg), z_min);
    double v = kernel_estimate(&q, (Kernel){r->mc.s, r->mc.t, wf.hx, wf.hy}, 0).lit;
    *deepest = q.deepest;
    return v;
}

static void vssm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const ChebSoft *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        int deepest = 0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = chebsoft_visibility(st, &r, &deepest);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
        if (ctx->aux) ctx->aux[s] = (float)deepest;
    }
}

const Technique tech_vssm = {
    .name = "vssm",
    .family = "soft",
    .source = "Yang, Dong, Feng, Seidel & Kautz 2010 (Variance Soft Shadow Mapping, PG 2010); course §5.2.2.2 (SAT)",
    .summary = "PCSS from one summed-area table of u, u^2: Yang's blocker mean from Chebyshev's bound, Chebyshev "
               "over the penumbra window; windows whose mean lies at or behind the receiver split 2 x 2 up to "
               "split_depth",
    .params = vssm_params,
    .num_params = (int)(sizeof vssm_params / sizeof vssm_params[0]),
    .resources = vssm_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "split_depth",
    .prepare = vssm_prepare,
    .evaluate = vssm_evaluate,
    .release = free,
    .aux = vssm_aux,
};
