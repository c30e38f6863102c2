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
 * The box filter (course §5.2.5, step 3) is one of three prefilters of each
 * slice's occupancy, each O(1) per slice, so the cost per receiver is O(S),
 * independent of the light's size:
 *   nbuffer (the paper's advocated one; Décoret 2005's N-buffers): level l
 *     holds the mean over the 2^l x 2^l texels starting at each texel
 *     (edge-clamped), l = 0 .. log2(map_size); a K-wide window reads the
 *     level with 2^l <= K < 2^(l+1) at ceil(K / 2^l) block starts per axis
 *     spread from its first texel to its last block (two per axis: the
 *     N-buffer's four overlapping lookups) and averages them [derived: the
 *     blocks overlap, so the mean weighs the window's middle up to twice;
 *     exact where K is a power of two];
 *   sat: a summed-area table of the occupied-texel counts (Crow 1984):
 *     exact box means at any K (integer counts: no SAT rounding);
 *   mipmap: a 2x2 box pyramid, read bilinearly at the window's centre at
 *     the level nearest log2(K) [derived: the course's "mipmap
 *     (artifacts)": power-of-two boxes, blocky where the level switches].
 *
 * Known failures, as the course lists them: the fusion is multiplicative
 * (overlapping occluders in different slices darken too little, in one
 * slice correctly), the receiver's own slice casts nothing (no intra-slice
 * shadows: contact accuracy is one slice thick), and the textures come from
 * the map's first layer (an occluder hidden from the light's centre is in
 * no slice; the paper renders each slice's geometry).
 *
 * A NaN depth (issue 13 §1) is a caster of unknown slice, or none: a SAT
 * per face counts such texels (whatever the filter), and a receiver whose window in a slice
 * in front holds one is NaN (the counts are integers: no NaN spreads to the
 * windows after it, as it would through a float SAT). The slices' depth
 * range is the finite depths'. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/bufpool.h"
#include "core/counters.h"
#include "core/hash.h"
#include "techniques/backproject.h"

enum { P_SLICES = SMAP_NUM_PARAMS, P_FILTER };
#define OT_MAX_SLICES 16
enum { FILTER_NBUFFER, FILTER_SAT, FILTER_MIPMAP };
static const char *const filter_names[] = {"nbuffer", "sat", "mipmap", NULL};

/* Plain perspective faces only (softmap.h): no warps or frustum-face splits. */
static const ParamDesc ot_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS,
    /* Default 6: at 160x120 (64 samples) all-region RMSE 0.023 / 0.060 / 0.067 on sphere-on-plane / overlap /
     * contact against 8 slices' 0.028 / 0.061 / 0.092, umbra leak 0.069 / 0.083 / 0.050 against 0.102 / 0.091 /
     * 0.241; 4 slices leak 0.48 under overlap.lua's two slabs (they share a slice). */
    {"slices", PARAM_INT, 6, 1, OT_MAX_SLICES, "slices",
     "S: slices of each face's caster depth range, uniform in depth (course §5.2.5: \"between 4 and 16\"); "
     "memory per face: S x (log2(map_size) + 1) x map_size^2 x 4 bytes (nbuffer), S x (map_size + 1)^2 x 4 "
     "(sat) or S x 4/3 x map_size^2 x 4 (mipmap), plus (map_size + 1)^2 x 4 counting NaN texels",
     NULL},
    {"filter", PARAM_ENUM, FILTER_NBUFFER, 0, 2, "",
     "box filter of each slice's occupancy (course §5.2.5 step 3): nbuffer (the paper's; Décoret 2005: four "
     "overlapping power-of-two blocks, exact at power-of-two windows), sat (summed-area table: exact at any "
     "window) or mipmap (bilinear at the nearest power-of-two level: blocky)",
     filter_names},
};

static const char *const ot_resources[] = {"shadow_map", "minmax_pyramid", "occlusion_tables", "view_samples", NULL};

typedef struct OtFace {
    double z0, thick; /* slice k holds depths [z0 + k thick, z0 + (k + 1) thick), the last also z0 + S thick */
} OtFace;

#define OT_MAX_LEVELS 16 /* levels of a map_size <= 16384 pyramid or N-buffer: log2(16384) + 1 = 15 */

/* The slice tables of a map's faces: a keyed resource (resources.h) of the
 * map, the slice count and the filter, so a second run that changes only
 * the bias or the light reuses them. */
typedef struct OtTables {
    uint64_t key;
    int res, num_faces, slices, filter;
    int stride;          /* map_size + 1: a SAT row */
    int tables;          /* SATs per face: table 0 counts the NaN texels, tables 1 .. S slice k - 1's (filter sat) */
    OtFace face[LIGHTVIEW_MAX_FACES];
    uint32_t *sat;       /* [(face * tables + t) * stride^2 + j * stride + i]: texels of table t below (i, j) */
    /* nbuffer and mipmap: `levels` levels of each slice's occupancy mean,
     * level l at level_at[l] floats into the slice's block of slice_floats,
     * level_res[l] texels a side (nbuffer: map_size; mipmap: ceil(map_size / 2^l)). */
    int levels, level_res[OT_MAX_LEVELS];
    size_t level_at[OT_MAX_LEVELS], slice_floats;
    float *level;        /* [(face * slices + k) * slice_floats + level_at[l] + j * level_res[l] + i] */
} OtTables;

typedef struct OtState {
    SoftMap sm;
    SmapBias bias;
    const OtTables *tab; /* owned by the resource manager */
} OtState;

static uint32_t *sat_of(const OtTables *t, int face, int table)
{
    return t->sat + ((size_t)face * t->tables + table) * (size_t)t->stride * t->stride;
}

static float *level_of(const OtTables *t, int face, int k, int l)
{
    return t->level + ((size_t)face * t->slices + k) * t->slice_floats + t->level_at[l];
}

/* The level layout of the filter: an N-buffer has a full-resolution level
 * per power of two up to map_size, a mipmap halves (rounding up) down to 1. */
static void level_layout(OtTables *tab, int res)
{
    tab->levels = 0;
    tab->slice_floats = 0;
    if (tab->filter == FILTER_SAT) return;
    for (int l = 0, n = res; l < OT_MAX_LEVELS; l++) {
        bool nbuffer = tab->filter == FILTER_NBUFFER;
        if (nbuffer ? (1 << l) > res : (l > 0 && tab->level_res[l - 1] == 1)) break;
        tab->level_res[l] = nbuffer ? res : n;
        tab->level_at[l] = tab->slice_floats;
        tab->slice_floats += (size_t)tab->level_res[l] * tab->level_res[l];
        tab->levels = l + 1;
        n = (n + 1) / 2;
    }
}

/* The tables' shape (everything but their contents) for a map, S and filter. */
static void tables_layout(OtTables *t, const ShadowMap *map, int slices, int filter)
{
    *t = (OtTables){.res = map->res, .num_faces = map->num_faces, .slices = slices, .filter = filter};
    t->stride = map->res + 1;
    t->tables = 1 + (filter == FILTER_SAT ? slices : 0);
    level_layout(t, map->res);
}

static size_t tables_sats(const OtTables *t) { return (size_t)t->num_faces * t->tables * t->stride * t->stride; }
static size_t tables_floats(const OtTables *t) { return (size_t)t->num_faces * t->slices * t->slice_floats; }

/* Bytes of the tables' arrays (a double, for the size check and its message). */
static double tables_array_bytes(const OtTables *t)
{
    return (double)tables_sats(t) * sizeof(uint32_t) + (double)tables_floats(t) * sizeof(float);
}

static size_t tables_bytes(const void *res)
{
    const OtTables *t = res;
    return sizeof *t + tables_sats(t) * sizeof(uint32_t) + tables_floats(t) * sizeof(float);
}

static void tables_destroy(void *res)
{
    OtTables *t = res;
    if (t) {
        bufpool_free(t->sat);
        bufpool_free(t->level);
    }
    free(t);
}

static const ResourceKind kind_tables = {"occlusion_tables", tables_bytes, tables_destroy, RES_FRAME};

/* Linear depth of texel (i, j) (softmap_depth without a SoftMap). */
static double map_depth(const ShadowMap *map, int face, int i, int j)
{
    return smap_linear_depth(map, face, shadowmap_texel(map, face, i, j));
}

/* The depth range of a face's casters (world units), [+INF, -INF] when empty. */
static void face_range(const ShadowMap *map, int face, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int j = 0; j < map->res; j++)
        for (int i = 0; i < map->res; i++) {
            double d = map_depth(map, face, i, j);
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

#define OT_EMPTY 255 /* a texel's slice index: no caster; `slices`: NaN */

/* The SAT of the texels whose slice index is `value`, its zero first row
 * and column included (the buffer comes from bufpool, not zeroed). */
static void build_sat(uint32_t *sat, const uint8_t *slice, int res, int value)
{
    int n = res + 1;
    memset(sat, 0, (size_t)n * sizeof *sat);
    for (int j = 0; j < res; j++) {
        uint32_t row = 0;
        sat[(size_t)(j + 1) * n] = 0;
        for (int i = 0; i < res; i++) {
            row += slice[(size_t)j * res + i] == value;
            sat[(size_t)(j + 1) * n + i + 1] = sat[(size_t)j * n + i + 1] + row;
        }
    }
}

static int clamp_index(int i, int n) { return i < n ? i : n - 1; }

/* Slice k's levels from its occupancy: N-buffer level l the mean of the four
 * level l - 1 blocks at offsets 0 and 2^(l-1) (edge-clamped, Décoret 2005);
 * mipmap level l the mean of the 2x2 children (edge-clamped). */
static void build_levels(const OtTables *tab, int face, int k, const uint8_t *slice)
{
    int res = tab->level_res[0];
    float *l0 = level_of(tab, face, k, 0);
    for (size_t t = 0; t < (size_t)res * res; t++) l0[t] = slice[t] == k ? 1.0f : 0.0f;
    for (int l = 1; l < tab->levels; l++) {
        const float *a = level_of(tab, face, k, l - 1);
        float *b = level_of(tab, face, k, l);
        int na = tab->level_res[l - 1], nb = tab->level_res[l];
        bool nbuffer = tab->filter == FILTER_NBUFFER;
        int h = nbuffer ? 1 << (l - 1) : 1;
        for (int j = 0; j < nb; j++)
            for (int i = 0; i < nb; i++) {
                int i0 = nbuffer ? i : 2 * i, j0 = nbuffer ? j : 2 * j;
                int i1 = clamp_index(i0 + h, na), j1 = clamp_index(j0 + h, na);
                i0 = clamp_index(i0, na);
                j0 = clamp_index(j0, na);
                b[(size_t)j * nb + i] = 0.25f * (a[(size_t)j0 * na + i0] + a[(size_t)j0 * na + i1] +
                                                 a[(size_t)j1 * na + i0] + a[(size_t)j1 * na + i1]);
            }
    }
}

/* Each texel's slice, then the NaN counts' SAT and the filter's tables. */
static bool build_face(OtTables *tab, const ShadowMap *map, int face)
{
    OtFace *f = &tab->face[face];
    double lo, hi;
    face_range(map, face, &lo, &hi);
    f->z0 = isfinite(lo) ? lo : 0.0;
    f->thick = isfinite(lo) ? (hi - lo) / tab->slices : 0.0;
    int res = map->res;
    uint8_t *slice = malloc((size_t)res * res);
    if (!slice) return false;
    for (int j = 0; j < res; j++)
        for (int i = 0; i < res; i++) {
            double d = map_depth(map, face, i, j);
            slice[(size_t)j * res + i] =
                isnan(d) ? (uint8_t)tab->slices : isfinite(d) ? (uint8_t)slice_of(f, tab->slices, d) : OT_EMPTY;
        }
    build_sat(sat_of(tab, face, 0), slice, res, tab->slices);
    for (int t = 1; t < tab->tables; t++) build_sat(sat_of(tab, face, t), slice, res, t - 1);
    for (int k = 0; k < tab->slices && tab->levels > 0; k++) build_levels(tab, face, k, slice);
    free(slice);
    return true;
}

typedef struct TablesArgs {
    const ShadowMap *map;
    const OtTables *shape; /* tables_layout's, size-checked */
    uint64_t key;
} TablesArgs;

static void *build_tables(const void *args, Error *err)
{
    const TablesArgs *a = args;
    OtTables *t = malloc(sizeof *t);
    if (!t) {
        error_set(err, "out of memory");
        return NULL;
    }
    *t = *a->shape;
    t->key = a->key;
    size_t floats = tables_floats(t);
    /* populated in huge pages, and kept between builds up to bufpool's limit
     * (the cube's nbuffer levels at 1024^2 take 1.6 GB: 400k page faults a
     * build otherwise; bench/README.md, step 11) */
    t->sat = bufpool_alloc(tables_sats(t) * sizeof *t->sat);
    t->level = floats ? bufpool_alloc(floats * sizeof *t->level) : NULL;
    if (!t->sat || (floats && !t->level)) {
        error_set(err, "occlusion_textures: out of memory for %.2f GiB of slice tables",
                  tables_array_bytes(t) / (1u << 30));
        tables_destroy(t);
        return NULL;
    }
    for (int f = 0; f < t->num_faces; f++)
        if (!build_face(t, a->map, f)) {
            error_set(err, "occlusion_textures: out of memory for a %d^2 slice index", t->res);
            tables_destroy(t);
            return NULL;
        }
    return t;
}

/* The slice tables of the map at S and filter: keyed by exactly those (the
 * faces' depth ranges are the map's), refused above SHADOWMAP_MAX_BYTES
 * before anything is allocated. */
static const OtTables *res_tables(ResourceManager *rm, const ShadowMap *map, int slices, int filter, Error *err)
{
    OtTables shape;
    tables_layout(&shape, map, slices, filter);
    double bytes = tables_array_bytes(&shape), gib = bytes / (1u << 30);
    if (bytes > (double)SHADOWMAP_MAX_BYTES) {
        error_set(err, "occlusion_textures: slices = %d, filter = %s of map_size = %d (%d faces) take %.2f GiB, "
                       "above the %.0f GiB limit: lower slices or map_size, or filter=sat",
                  slices, filter_names[filter], map->res, map->num_faces, gib,
                  (double)SHADOWMAP_MAX_BYTES / (1u << 30));
        return NULL;
    }
    Hasher h;
    hash_init(&h);
    hash_u64(&h, map->key);
    hash_str(&h, "occlusion tables");
    hash_u64(&h, (uint64_t)slices);
    hash_u64(&h, (uint64_t)filter);
    TablesArgs a = {map, &shape, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(map->key, mk);
    snprintf(desc, sizeof desc, "%d slices, %s, of map %s (%d x %d^2)", slices, filter_names[filter], mk,
             map->num_faces, map->res);
    return rm_acquire(rm, &kind_tables, a.key, desc, build_tables, &a, err);
}

static void ot_release(void *state) { free(state); }

static bool ot_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    OtState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&st->sm, ctx->rm, map, ctx->light, "occlusion_textures", err) ||
        !(st->tab = res_tables(ctx->rm, map, (int)p[P_SLICES], (int)p[P_FILTER], err))) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    *state = st;
    return true;
}

/* The mean of table t's texels over [i0, i1] x [j0, j1] (inside the face). */
static double sat_mean(const OtTables *tab, int face, int t, int i0, int j0, int i1, int j1)
{
    int n = tab->stride;
    const uint32_t *s = sat_of(tab, face, t);
    work_texels(4, sizeof *s); /* the SAT's four corners (core/counters.h) */
    double count = (double)s[(size_t)(j1 + 1) * n + i1 + 1] - s[(size_t)j0 * n + i1 + 1] - s[(size_t)(j1 + 1) * n + i0] +
                   s[(size_t)j0 * n + i0];
    return count / ((double)(i1 - i0 + 1) * (j1 - j0 + 1));
}

static int floor_log2(int k)
{
    int l = 0;
    while ((2 << l) <= k) l++;
    return l;
}

/* Block start a of n spread from lo to hi (n = 1: lo). */
static int spread(int lo, int hi, int a, int n) { return n == 1 ? lo : lo + (int)lround((double)a * (hi - lo) / (n - 1)); }

/* The N-buffer estimate: the mean of the level-l blocks (2^l <= the window's
 * narrower side) at ceil(K / 2^l) starts per axis. */
static double nbuffer_mean(const OtTables *tab, int face, int k, int i0, int j0, int i1, int j1)
{
    int kx = i1 - i0 + 1, ky = j1 - j0 + 1, l = floor_log2(kx < ky ? kx : ky), b = 1 << l;
    int nx = (kx + b - 1) / b, ny = (ky + b - 1) / b, res = tab->level_res[l];
    const float *lv = level_of(tab, face, k, l);
    work_texels(nx * ny, sizeof *lv); /* one read per block */
    double sum = 0.0;
    for (int y = 0; y < ny; y++)
        for (int x = 0; x < nx; x++)
            sum += lv[(size_t)spread(j0, j1 - b + 1, y, ny) * res + spread(i0, i1 - b + 1, x, nx)];
    return sum / ((double)nx * ny);
}

/* The mipmap estimate: bilinear at the window's centre on the level nearest
 * log2 of its narrower side. */
static double mipmap_mean(const OtTables *tab, int face, int k, int i0, int j0, int i1, int j1)
{
    int kx = i1 - i0 + 1, ky = j1 - j0 + 1;
    int l = (int)floor(log2((double)(kx < ky ? kx : ky)) + 0.5);
    l = l < tab->levels ? l : tab->levels - 1;
    int n = tab->level_res[l];
    double scale = ldexp(1.0, -l);
    double u = 0.5 * (i0 + i1 + 1) * scale - 0.5, v = 0.5 * (j0 + j1 + 1) * scale - 0.5; /* level-l texel centres */
    int x0 = (int)floor(u), y0 = (int)floor(v);
    double fx = u - x0, fy = v - y0;
    int xa = x0 < 0 ? 0 : clamp_index(x0, n), xb = clamp_index(x0 + 1 < 0 ? 0 : x0 + 1, n);
    int ya = y0 < 0 ? 0 : clamp_index(y0, n), yb = clamp_index(y0 + 1 < 0 ? 0 : y0 + 1, n);
    const float *lv = level_of(tab, face, k, l);
    work_texels(4, sizeof *lv); /* the bilinear footprint */
    double top = (1 - fx) * lv[(size_t)ya * n + xa] + fx * lv[(size_t)ya * n + xb];
    double bottom = (1 - fx) * lv[(size_t)yb * n + xa] + fx * lv[(size_t)yb * n + xb];
    return (1 - fy) * top + fy * bottom;
}

/* Slice k's occupancy mean (k = -1: the NaN texels') over texels
 * [i0, i1] x [j0, j1], clamped to the face, by the tables' filter. */
static double box_mean(const OtTables *tab, int face, int k, int i0, int j0, int i1, int j1)
{
    int res = tab->res;
    i0 = i0 < 0 ? 0 : i0;
    j0 = j0 < 0 ? 0 : j0;
    i1 = i1 >= res ? res - 1 : i1;
    j1 = j1 >= res ? res - 1 : j1;
    if (i0 > i1 || j0 > j1) return 0.0; /* off the face: nothing known to occlude */
    if (k < 0) return sat_mean(tab, face, 0, i0, j0, i1, j1);
    switch (tab->filter) {
    case FILTER_SAT: return sat_mean(tab, face, 1 + k, i0, j0, i1, j1);
    case FILTER_NBUFFER: return nbuffer_mean(tab, face, k, i0, j0, i1, j1);
    default: return mipmap_mean(tab, face, k, i0, j0, i1, j1);
    }
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
    const OtTables *tab = st->tab;
    int face = r->mc.face, i, j;
    const OtFace *f = &tab->face[face];
    const SoftFace *sf = &st->sm.face[face];
    smap_texel(r, &i, &j);
    double p_z = smap_linear_depth(st->sm.map, face, smap_ref_at(r, i, j)), r_z = r->mc.depth_linear;
    if (isnan(p_z)) return NAN; /* which slices lie in front is unknown */
    double v = 1.0;
    bool unknown = false;
    for (int k = 0; k < tab->slices; k++) {
        double bottom = f->z0 + (k + 1) * f->thick; /* the plane the slice is projected onto */
        if (!(bottom < p_z)) break;                 /* NaN: no slice known to lie in front */
        int i0, i1, j0, j1;
        window(r->mc.s, backproject_footprint(sf->light.half_x, r_z, bottom) / sf->dx, &i0, &i1);
        window(r->mc.t, backproject_footprint(sf->light.half_y, r_z, bottom) / sf->dy, &j0, &j1);
        unknown = unknown || box_mean(tab, face, -1, i0, j0, i1, j1) > 0.0; /* a caster of unknown slice */
        v *= 1.0 - box_mean(tab, face, k, i0, j0, i1, j1);
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
    .summary = "S depth slices of the map's casters as binary textures, each box-filtered (N-buffer, summed-area "
               "table or mipmap) over the light's footprint on its plane; V the product over the slices in front of p",
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
