/* dpcf.c -- `dpcf`: distance-based PCF as Filament ships it
 * (surface_shadowing.fs, ShadowSample_DPCF, after Myers, "Shadows of Cold
 * War: a scalable approach to shadowing"): one set of Poisson taps serves
 * both the blocker search and the filter.
 *   1. taps over PCSS's search window (filtsoft.h; Filament's radius is the
 *      light's size in light space): occluded count n and depth sum, with
 *      the receiver-plane bias; none occluded: lit;
 *   2. the penumbra ratio r = saturate(scale (z_p - z_avg) / z_avg) (PCSS's
 *      w_penumbra / w_light, course §5.2.2 step 2; Filament's
 *      getPenumbraRatio with shadowPenumbraRatioScale);
 *   3. occluded fraction o = n / taps, hardened toward contact:
 *      o' = mix(hardened(o), o, r), hardened(x) the "stronger smoothstep"
 *      0.5 + 0.5 s (1 - (1 - s (2x - 1))^3), s = sign(2x - 1);
 *      visibility 1 - o'.
 * The kernel does not shrink with the blocker distance (PCSS's second
 * window); only the transition sharpens, so penumbrae keep the search
 * window's width: the engine's trade of accuracy for a fixed cost, taps
 * per receiver, at any light size (up to max_radius). */
#include <stdlib.h>
#include "resources/standard.h"
#include "techniques/filtsoft.h"

enum { P_TAPS = SMAP_NUM_PARAMS, P_ROTATE, P_RATIO_SCALE, P_MAX_RADIUS };

static const ParamDesc dpcf_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT), /* perspective faces (softmap.h) */
    SMAP_BIAS_PARAMS_PLANE(1),
    {"taps", PARAM_INT, 16, 1, SOFTMAP_MAX_POISSON, "taps",
     "Poisson taps, shared by the blocker search and the filter (Filament: 16)", NULL},
    {"rotate", PARAM_BOOL, 1, 0, 1, "", "rotate the disk per pixel (Filament's random rotation)", NULL},
    {"penumbra_scale", PARAM_FLOAT, 1, 0, 100, "",
     "Filament's shadowPenumbraRatioScale: the penumbra ratio (z_p - z_avg) / z_avg is multiplied by it before "
     "the clamp to [0, 1]; 0 keeps the hardened kernel everywhere",
     NULL},
    {"max_radius", PARAM_FLOAT, 32, FILTSOFT_MIN_HALF, 256, "texels",
     "bound on the search window's half-width (a huge light, a receiver near the light)", NULL},
};
FILTER_CHECK_TABLE(dpcf_params);

static const char *const dpcf_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "point_table", NULL};

typedef struct DpcfState {
    FiltSoft fs;
    const PointTable *disk;
    int taps;
    bool rotate;
    double ratio_scale;
} DpcfState;

static bool dpcf_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    DpcfState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->taps = (int)p[P_TAPS];
    st->rotate = p[P_ROTATE] != 0.0;
    st->ratio_scale = p[P_RATIO_SCALE];
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], true, "dpcf", err) ||
        !(st->disk = res_point_table(ctx->rm, "softmap poisson disk", softmap_poisson, st->taps, err))) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* Filament's hardenedKernel: a steeper smoothstep about 1/2. */
static double hardened(double x)
{
    x = 2.0 * x - 1.0;
    double s = x < 0.0 ? -1.0 : 1.0, y = 1.0 - s * x;
    return 0.5 + 0.5 * (s - s * y * y * y);
}

static double dpcf_visibility(const DpcfState *st, const SmapReceiver *r, uint32_t sample)
{
    FsWindow w;
    double z_min;
    if (!filtsoft_search(&st->fs, r, &w, &z_min)) return 1.0;
    if (isnan(z_min)) return NAN; /* a NaN depth in reach: no taps to place */
    double cs, sn, depth_sum = 0.0;
    int occluded = 0;
    softmap_rotation(st->rotate, sample, &cs, &sn);
    for (int k = 0; k < st->taps; k++) {
        double px = st->disk->pts[k][0], py = st->disk->pts[k][1];
        int i = (int)floor(r->mc.s + w.hx * (cs * px - sn * py)), j = (int)floor(r->mc.t + w.hy * (sn * px + cs * py));
        float stored = shadowmap_texel(st->fs.sm.map, r->mc.face, i, j), lit = smap_test(smap_ref_at(r, i, j), stored);
        if (lit == 1.0f) continue;
        occluded++; /* a NaN depth or reference: an unknown tap, its depth NaN (as pcss's blocker_add) */
        depth_sum += isnan(lit) ? NAN : smap_linear_depth(st->fs.sm.map, r->mc.face, stored);
    }
    if (occluded == 0) return 1.0;
    double z_p = r->mc.depth_linear, z_avg = depth_sum / occluded;
    if (isnan(z_avg)) return NAN; /* the blockers' depth, hence the ratio, is unknown */
    double ratio = z_avg > 0.0 ? st->ratio_scale * (z_p - z_avg) / z_avg : 1.0; /* a blocker at the light: widest */
    ratio = ratio < 0.0 ? 0.0 : ratio > 1.0 ? 1.0 : ratio;
    double o = (double)occluded / st->taps;
    return 1.0 - ((1.0 - ratio) * hardened(o) + ratio * o);
}

static void dpcf_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const DpcfState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = dpcf_visibility(st, &r, (uint32_t)s);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_dpcf = {
    .name = "dpcf",
    .family = "soft",
    .source = "Filament surface_shadowing.fs ShadowSample_DPCF (after Myers, Shadows of Cold War); course §5.2.2",
    .summary = "one set of Poisson taps over PCSS's search window: blocker count and depth, then the PCF of the "
               "same taps hardened toward contact by the penumbra ratio",
    .params = dpcf_params,
    .num_params = (int)(sizeof dpcf_params / sizeof dpcf_params[0]),
    .resources = dpcf_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "taps",
    .prepare = dpcf_prepare,
    .evaluate = dpcf_evaluate,
    .release = free,
};
