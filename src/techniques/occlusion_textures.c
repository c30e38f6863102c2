/* occlusion_textures.c -- `occlusion_textures` (Eisemann & Décoret 2006,
 * course §5.2.5). The casters' depth range in each map face is cut into S
 * slices parallel to the light's plane; slice k's occlusion texture is 1
 * where a caster lies in it (delta_O), projected onto its bottom plane (the
 * far one). The visibility of p is the product, over the slices wholly in
 * front of p, of the box-filtered 1 - delta_O,
 *     V_k = 1/|K| sum_{x in K} (1 - delta_O(x)),
 *     size(K) = dist(p, slice) / dist(p, light) x size(light)
 * (course §5.2.5 [TEXT]), K centred where the ray from p to the light's
 * centre crosses the slice: p's own texel, since the map looks from that
 * centre. In the face's tangent units K's half-width is the light's
 * footprint on the slice plane, backproject_footprint (backproject.h).
 * Filtering is one summed-area table per slice (exact box means at any K;
 * the N-buffers the paper advocates and the mipmap are not built), so the
 * cost per receiver is O(S), independent of the light's size.
 *
 * Known failures, as the course lists them: the fusion is multiplicative
 * (overlapping occluders in different slices darken too little, in one
 * slice correctly), the receiver's own slice casts nothing (no intra-slice
 * shadows: contact accuracy is one slice thick), and the textures come from
 * the map's first layer (an occluder hidden from the light's centre is in
 * no slice; the paper renders each slice's geometry).
 *
 * A NaN depth (issue 13 §1) is a caster of unknown slice, or none: one more
 * table per face counts such texels, and a receiver whose window in a slice
 * in front holds one is NaN (the counts are integers: no NaN spreads to the
 * windows after it, as it would through a float SAT). The slices' depth
 * range is the finite depths'. */
#include <stdlib.h>
#include "core/counters.h"
#include "techniques/backproject.h"

enum { P_SLICES = SMAP_NUM_PARAMS };
#define OT_MAX_SLICES 16

/* Plain perspective faces only (softmap.h): no warps or frustum-face splits. */
static const ParamDesc ot_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS,
    /* Default 6: at 160x120 (64 samples) all-region RMSE 0.023 / 0.060 / 0.067 on sphere-on-plane / overlap /
     * contact against 8 slices' 0.028 / 0.061 / 0.092, umbra leak 0.069 / 0.083 / 0.050 against 0.102 / 0.091 /
     * 0.241; 4 slices leak 0.48 under overlap.lua's two slabs (they share a slice). */
    {"slices", PARAM_INT, 6, 1, OT_MAX_SLICES, "slices",
     "S: slices of each face's caster depth range, uniform in depth (course §5.2.5: \"between 4 and 16\"); "
     "memory (S + 1) x (map_size + 1)^2 x 4 bytes per face (one more table counts NaN texels)",
     NULL},
};

static const char *const ot_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};

typedef struct OtFace {
    double z0, thick; /* slice k holds depths [z0 + k thick, z0 + (k + 1) thick), the last also z0 + S thick */
} OtFace;

typedef struct OtState {
    SoftMap sm;
    SmapBias bias;
    int slices, stride;  /* stride = map_size + 1: a SAT row */
    OtFace face[LIGHTVIEW_MAX_FACES];
    uint32_t *sat;       /* [(face * (slices + 1) + k) * stride^2 + j * stride + i]: occupied texels of slice k
                          * below (i, j); table k = slices counts the NaN texels */
} OtState;

static uint32_t *sat_of(const OtState *st, int face, int k)
{
    return st->sat + ((size_t)face * (st->slices + 1) + k) * (size_t)st->stride * st->stride;
}

/* The depth range of a face's casters (world units), [+INF, -INF] when empty. */
static void face_range(const SoftMap *sm, int face, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int j = 0; j < sm->map->res; j++)
        for (int i = 0; i < sm->map->res; i++) {
            double d = softmap_depth(sm, face, i, j);
            if (!isfinite(d)) continue;
            if (d < *lo) *lo = d;
            if (d > *hi) *hi = d;
        }
}

/* The slice of depth d: uniform slices of thickness thick from z0 (a
 * one-depth face, thick = 0: all in slice 0). */
static int slice_of(const OtFace *f, int slices, double d)
{
    if (!(f->thick > 0.0)) return 0;
    double k = floor((d - f->z0) / f->thick);
    return k >= 0.0 ? (int)fmin(k, slices - 1) : 0;
}

/* Slice k's SAT from each texel's slice (OT_EMPTY: no caster; slices: NaN), one pass per table. */
#define OT_EMPTY 255
static bool build_face(OtState *st, int face)
{
    OtFace *f = &st->face[face];
    double lo, hi;
    face_range(&st->sm, face, &lo, &hi);
    f->z0 = isfinite(lo) ? lo : 0.0;
    f->thick = isfinite(lo) ? (hi - lo) / st->slices : 0.0;
    int res = st->sm.map->res, n = st->stride;
    uint8_t *slice = malloc((size_t)res * res);
    if (!slice) return false;
    for (int j = 0; j < res; j++)
        for (int i = 0; i < res; i++) {
            double d = softmap_depth(&st->sm, face, i, j);
            slice[(size_t)j * res + i] =
                isnan(d) ? (uint8_t)st->slices : isfinite(d) ? (uint8_t)slice_of(f, st->slices, d) : OT_EMPTY;
        }
    for (int k = 0; k <= st->slices; k++) {
        uint32_t *sat = sat_of(st, face, k);
        for (int j = 0; j < res; j++) {
            uint32_t row = 0;
            for (int i = 0; i < res; i++) {
                row += slice[(size_t)j * res + i] == k;
                sat[(size_t)(j + 1) * n + i + 1] = sat[(size_t)j * n + i + 1] + row;
            }
        }
    }
    free(slice);
    return true;
}

static void ot_release(void *state)
{
    OtState *st = state;
    if (st) free(st->sat);
    free(st);
}

static bool ot_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    OtState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&st->sm, ctx->rm, map, ctx->light, "occlusion_textures", err)) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->slices = (int)p[P_SLICES];
    st->stride = map->res + 1;
    size_t entries = (size_t)map->num_faces * (st->slices + 1) * st->stride * st->stride;
    double gib = (double)entries * sizeof(uint32_t) / (1u << 30);
    if (entries * sizeof(uint32_t) > SHADOWMAP_MAX_BYTES) {
        free(st);
        return error_set(err, "occlusion_textures: slices = %d of map_size = %d (%d faces) take %.2f GiB, above the "
                              "%.0f GiB limit: lower slices or map_size",
                         (int)p[P_SLICES], map->res, map->num_faces, gib, (double)SHADOWMAP_MAX_BYTES / (1u << 30));
    }
    st->sat = calloc(entries, sizeof *st->sat);
    if (!st->sat) {
        free(st);
        return error_set(err, "occlusion_textures: out of memory for %.2f GiB of slice tables", gib);
    }
    for (int f = 0; f < map->num_faces; f++)
        if (!build_face(st, f)) {
            ot_release(st);
            return error_set(err, "occlusion_textures: out of memory for a %d^2 slice index", map->res);
        }
    *state = st;
    return true;
}

/* The mean of slice k's occupancy over texels [i0, i1] x [j0, j1], clamped to the face. */
static double box_mean(const OtState *st, int face, int k, int i0, int j0, int i1, int j1)
{
    int res = st->sm.map->res, n = st->stride;
    i0 = i0 < 0 ? 0 : i0;
    j0 = j0 < 0 ? 0 : j0;
    i1 = i1 >= res ? res - 1 : i1;
    j1 = j1 >= res ? res - 1 : j1;
    if (i0 > i1 || j0 > j1) return 0.0; /* off the face: nothing known to occlude */
    const uint32_t *s = sat_of(st, face, k);
    work_texels(4, sizeof *s); /* the SAT's four corners (core/counters.h) */
    double count = (double)s[(size_t)(j1 + 1) * n + i1 + 1] - s[(size_t)j0 * n + i1 + 1] - s[(size_t)(j1 + 1) * n + i0] +
                   s[(size_t)j0 * n + i0];
    return count / ((double)(i1 - i0 + 1) * (j1 - j0 + 1));
}

/* A window's first and last texel: K = max(1, 2 half) texels centred on c. */
static void window(double c, double half_texels, int *lo, int *hi)
{
    double width = 2.0 * half_texels;
    int K = width >= 1.0 ? (int)fmin(floor(width + 0.5), 1 << 20) : 1; /* NaN: one texel */
    *lo = softmap_window_start(c, K);
    *hi = *lo + K - 1;
}

/* Product over the slices wholly in front of the receiver's biased depth;
 * NaN when that depth is NaN or a window holds a NaN texel (issue 13 §1),
 * unless the known casters already make it 0 (a caster only lowers it). */
static float visibility(const OtState *st, const SmapReceiver *r)
{
    int face = r->mc.face, i, j;
    const OtFace *f = &st->face[face];
    const SoftFace *sf = &st->sm.face[face];
    smap_texel(r, &i, &j);
    double p_z = smap_linear_depth(st->sm.map, face, smap_ref_at(r, i, j)), r_z = r->mc.depth_linear;
    if (isnan(p_z)) return NAN; /* which slices lie in front is unknown */
    double v = 1.0;
    bool unknown = false;
    for (int k = 0; k < st->slices; k++) {
        double bottom = f->z0 + (k + 1) * f->thick; /* the plane the slice is projected onto */
        if (!(bottom < p_z)) break;                 /* NaN: no slice known to lie in front */
        int i0, i1, j0, j1;
        window(r->mc.s, backproject_footprint(sf->light.half_x, r_z, bottom) / sf->dx, &i0, &i1);
        window(r->mc.t, backproject_footprint(sf->light.half_y, r_z, bottom) / sf->dy, &j0, &j1);
        unknown = unknown || box_mean(st, face, st->slices, i0, j0, i1, j1) > 0.0; /* a caster of unknown slice */
        v *= 1.0 - box_mean(st, face, k, i0, j0, i1, j1);
    }
    return unknown && v > 0.0 ? NAN : (float)v;
}

static void ot_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const OtState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r);
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_occlusion_textures = {
    .name = "occlusion_textures",
    .family = "soft",
    .source = "course §5.2.5 (Eisemann & Décoret 2006, occlusion textures)",
    .summary = "S depth slices of the map's casters as binary textures, each box-filtered by a summed-area table "
               "over the light's footprint on its plane; V the product over the slices in front of p",
    .params = ot_params,
    .num_params = (int)(sizeof ot_params / sizeof ot_params[0]),
    .resources = ot_resources,
    .aux = NULL,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "slices",
    .prepare = ot_prepare,
    .evaluate = ot_evaluate,
    .release = ot_release,
};
