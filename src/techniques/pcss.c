/* pcss.c -- `pcss`: percentage-closer soft shadows (Fernando 2005; course
 * §5.2.2). In the face's tangent frame (softmap.h), for a receiver at depth
 * z_p and a light of half-extent a along each map axis (w_light = 2a; sphere
 * and disk: a = R; rect: its bounding box in the map's axes, exact when it is
 * aligned with them):
 *   1. blocker search over the region the light-receiver pyramid cuts on the
 *      near plane z_n, half-width a (z_p - z_n) / (z_p z_n) in tangent units;
 *      blockers are texels closer than the receiver (course §2.1's test with
 *      the biases), their linear depths averaged to z_avg; none: lit;
 *   2. penumbra width w_penumbra = (z_p - z_avg) / z_avg * w_light at the
 *      receiver, i.e. a filter half-width a (z_p - z_avg) / (z_avg z_p) in
 *      tangent units (the course's w_f = w_penumbra z_near / z_p on the near plane);
 *   3. PCF over that window.
 * Windows are read exhaustively (every texel; the filter a box with
 * fractional edge weights, which for a planar occluder and receiver parallel
 * to a square light is the exact box convolution, catalogue §5.2.2), by a
 * regular grid of taps, or by a Poisson disk rotated per pixel. */
#include <stdlib.h>
#include "resources/standard.h"
#include "techniques/softmap.h"

enum { SAMPLING_POISSON, SAMPLING_REGULAR, SAMPLING_EXHAUSTIVE };
static const char *const sampling_names[] = {"poisson", "regular", "exhaustive", NULL};

enum { P_SAMPLING = SMAP_NUM_PARAMS, P_BLOCKER_TAPS, P_FILTER_TAPS, P_ROTATE, P_MAX_RADIUS };

#define PCSS_MIN_HALF 0.5 /* texels: the filter is at least one texel wide (sub-texel kernels alias) */

/* Plain perspective faces only (softmap.h): no warps or frustum-face splits. */
static const ParamDesc pcss_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    {"sampling", PARAM_ENUM, SAMPLING_POISSON, 0, 2, "",
     "how both windows are read: poisson (disk taps, rotated per pixel), regular (an n x n grid of taps) or "
     "exhaustive (every texel; the filter a box with fractional edge weights)",
     sampling_names},
    {"blocker_taps", PARAM_INT, 16, 1, SOFTMAP_MAX_POISSON, "taps",
     "blocker-search taps (regular: the n x n grid with n = round(sqrt(taps))); 16 in NVIDIA's 2008 PCSS sample",
     NULL},
    {"filter_taps", PARAM_INT, 16, 1, SOFTMAP_MAX_POISSON, "taps",
     "PCF taps (regular: n x n with n = round(sqrt(taps))); 16 in NVIDIA's 2008 PCSS sample", NULL},
    {"rotate", PARAM_BOOL, 1, 0, 1, "", "poisson: rotate the disk per pixel (banding becomes noise)", NULL},
    {"max_radius", PARAM_FLOAT, 32, 0.5, 256, "texels",
     "bound on the search and filter half-widths: wider windows (a huge light, a receiver near the light or a "
     "blocker depth near 0, course §5.2.2.1) are clamped to it",
     NULL},
};

/* Exhaustive windows read every texel: no taps, no disk to rotate. */
static const ParamCondition pcss_conditions[] = {
    {"blocker_taps", "sampling=poisson|regular"},
    {"filter_taps", "sampling=poisson|regular"},
    {"rotate", "sampling=poisson"},
    {NULL, NULL},
};

static const char *const pcss_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "point_table", NULL};

/* A tap pattern on [-1, 1]^2: a regular side x side grid or a Poisson disk. */
typedef struct Pattern {
    int taps, side;
    const PointTable *disk; /* Poisson sampling: a set-up table; NULL otherwise */
} Pattern;

typedef struct PcssState {
    SoftMap sm;
    SmapBias bias;
    int sampling;
    bool rotate;
    double max_radius;
    Pattern search, filter;
} PcssState;

static bool pattern_init(Pattern *p, ResourceManager *rm, int sampling, int taps, Error *err)
{
    p->side = (int)lround(sqrt((double)taps));
    p->taps = sampling == SAMPLING_REGULAR ? p->side * p->side : taps;
    p->disk = sampling == SAMPLING_POISSON ? res_point_table(rm, "softmap poisson disk", softmap_poisson, taps, err) : NULL;
    return sampling != SAMPLING_POISSON || p->disk;
}

static bool pcss_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    PcssState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&st->sm, ctx->rm, map, ctx->light, "pcss", err)) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->sampling = (int)p[P_SAMPLING];
    st->rotate = p[P_ROTATE] != 0.0 && st->sampling == SAMPLING_POISSON;
    st->max_radius = p[P_MAX_RADIUS];
    if (!pattern_init(&st->search, ctx->rm, st->sampling, (int)p[P_BLOCKER_TAPS], err) ||
        !pattern_init(&st->filter, ctx->rm, st->sampling, (int)p[P_FILTER_TAPS], err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* Tap k of a pattern, rotated by (cs, sn) when it is a disk. */
static void tap(const Pattern *p, bool regular, int k, double cs, double sn, double *x, double *y)
{
    if (regular) {
        *x = -1.0 + (2.0 * (k % p->side) + 1.0) / p->side;
        *y = -1.0 + (2.0 * (k / p->side) + 1.0) / p->side;
        return;
    }
    double px = p->disk->pts[k][0], py = p->disk->pts[k][1];
    *x = cs * px - sn * py;
    *y = sn * px + cs * py;
}

/* A window about the receiver: half-widths in texels. */
typedef struct Window { double hx, hy; } Window;

/* Tangent half-width h -> texels, clamped to [PCSS_MIN_HALF, max_radius]. */
static Window window(const PcssState *st, const SoftFace *f, double hx_tangent, double hy_tangent)
{
    Window w = {hx_tangent / f->dx, hy_tangent / f->dy};
    w.hx = nan_clamp(w.hx, PCSS_MIN_HALF, st->max_radius);
    w.hy = nan_clamp(w.hy, PCSS_MIN_HALF, st->max_radius);
    return w;
}

typedef struct Blockers { int count; double depth_sum; } Blockers;

/* A blocker adds its linear depth; a NaN depth (or reference) adds NaN:
 * the average is then unknown, not the average of the others. */
static void blocker_add(const PcssState *st, const SmapReceiver *r, int i, int j, Blockers *b)
{
    float stored = shadowmap_texel(st->sm.map, r->mc.face, i, j), lit = smap_test(smap_ref_at(r, i, j), stored);
    if (lit == 1.0f) return;
    b->count++;
    b->depth_sum += isnan(lit) ? NAN : smap_linear_depth(st->sm.map, r->mc.face, stored);
}

/* Step 1: the average linear depth of the blockers in the window (NaN if
 * one read NaN); false if none. */
static bool blocker_depth(const PcssState *st, const SmapReceiver *r, Window w, double cs, double sn, double *z_avg)
{
    Blockers b = {0, 0.0};
    if (!softmap_may_block(&st->sm, r, (int)floor(r->mc.s - w.hx), (int)floor(r->mc.t - w.hy),
                           (int)floor(r->mc.s + w.hx), (int)floor(r->mc.t + w.hy), NULL))
        return false;
    if (st->sampling == SAMPLING_EXHAUSTIVE) { /* every texel whose centre lies in the window */
        int i0 = (int)ceil(r->mc.s - w.hx - 0.5), i1 = (int)floor(r->mc.s + w.hx - 0.5);
        int j0 = (int)ceil(r->mc.t - w.hy - 0.5), j1 = (int)floor(r->mc.t + w.hy - 0.5);
        for (int j = j0; j <= j1; j++)
            for (int i = i0; i <= i1; i++) blocker_add(st, r, i, j, &b);
    } else {
        for (int k = 0; k < st->search.taps; k++) {
            double x, y;
            tap(&st->search, st->sampling == SAMPLING_REGULAR, k, cs, sn, &x, &y);
            blocker_add(st, r, (int)floor(r->mc.s + w.hx * x), (int)floor(r->mc.t + w.hy * y), &b);
        }
    }
    if (b.count == 0) return false;
    *z_avg = b.depth_sum / b.count;
    return true;
}

/* Overlap of texel [i, i + 1] with [c - h, c + h]. */
static double overlap(int i, double c, double h) { return fmax(0.0, fmin(i + 1.0, c + h) - fmax((double)i, c - h)); }

/* Step 3, exhaustive: the box average of the lit texels over the window. */
static double filter_box(const PcssState *st, const SmapReceiver *r, Window w)
{
    int i0 = (int)floor(r->mc.s - w.hx), i1 = (int)floor(r->mc.s + w.hx);
    int j0 = (int)floor(r->mc.t - w.hy), j1 = (int)floor(r->mc.t + w.hy);
    double lit = 0.0;
    for (int j = j0; j <= j1; j++) {
        double wy = overlap(j, r->mc.t, w.hy);
        for (int i = i0; i <= i1; i++) lit += wy * overlap(i, r->mc.s, w.hx) * smap_lit(st->sm.map, r, i, j);
    }
    return lit / (4.0 * w.hx * w.hy);
}

static double filter_taps(const PcssState *st, const SmapReceiver *r, Window w, double cs, double sn)
{
    double lit = 0.0;
    for (int k = 0; k < st->filter.taps; k++) {
        double x, y;
        tap(&st->filter, st->sampling == SAMPLING_REGULAR, k, cs, sn, &x, &y);
        lit += smap_lit(st->sm.map, r, (int)floor(r->mc.s + w.hx * x), (int)floor(r->mc.t + w.hy * y));
    }
    return lit / st->filter.taps;
}

static float visibility(const PcssState *st, const SmapReceiver *r, uint32_t sample)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    const SoftLight *L = &f->light;
    double z_p = r->mc.depth_linear, z_n = f->near_world, cs, sn;
    softmap_rotation(st->rotate, sample, &cs, &sn);
    double k_search = (z_p - z_n) / (z_p * z_n); /* the pyramid on the near plane, per unit of light half-extent */
    double z_avg;
    if (!blocker_depth(st, r, window(st, f, L->half_x * k_search, L->half_y * k_search), cs, sn, &z_avg)) return 1.0f;
    if (isnan(z_avg)) return NAN; /* no window to filter over: the sample's visibility is unknown */
    /* d_blocker -> 0: blockers lie beyond the near plane (quantised depths may read slightly before it) */
    z_avg = nan_clamp(z_avg, z_n, z_p);
    double k_filter = (z_p - z_avg) / (z_avg * z_p);
    Window w = window(st, f, L->half_x * k_filter, L->half_y * k_filter);
    return (float)(st->sampling == SAMPLING_EXHAUSTIVE ? filter_box(st, r, w) : filter_taps(st, r, w, cs, sn));
}

static void pcss_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const PcssState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f;
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r, (uint32_t)s);
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_pcss = {
    .name = "pcss",
    .family = "soft",
    .source = "course §5.2.2 (Fernando 2005, percentage-closer soft shadows)",
    .summary = "blocker search in the light's pyramid on the near plane, penumbra width from the average "
               "blocker depth, PCF over it",
    .params = pcss_params,
    .num_params = (int)(sizeof pcss_params / sizeof pcss_params[0]),
    .resources = pcss_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "filter_taps",
    .conditions = pcss_conditions,
    .prepare = pcss_prepare,
    .evaluate = pcss_evaluate,
    .release = free,
};
