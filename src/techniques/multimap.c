/* multimap.c -- `layered_attenuation`: layered attenuation maps (Agrawala,
 * Ramamoorthi, Heirich & Moll 2000, "Efficient image-based methods for
 * rendering soft shadows", SIGGRAPH 2000, the layered attenuation maps;
 * course §5.2.4, its second paragraph). The N light samples' hard maps
 * (multimap.h: the same points and the same map resources as
 * `light_sampling`) are warped into one layered depth image (LDI) on the
 * grid of the light centre's map: every texel of sample k's map is lifted
 * to the world point it stores and reprojected into the centre's view.
 * Where the warped depth lies within epsilon (world units) of an entry
 * already in that LDI texel, the entry's counter is incremented (once per
 * sample); otherwise the depth is a new layer, up to the layer cap (beyond
 * it the warped texel is dropped and counted). An entry's attenuation is
 * counter / N: the fraction of the samples that see that surface. A receiver
 * looks up its texel of the LDI and takes the entry matching its depth
 * within epsilon: V = counter / N; no entry matches, no sample saw it: umbra
 * (course §5.2.4: "no match -> umbra").
 *
 * Unlike `light_sampling`, V counts all N samples, also those below the
 * receiver's tangent plane (the counter cannot tell them apart): the two
 * agree off the terminator. Epsilon is stiff (course §5.2.4 [OWN]): too
 * small, the warped depths of one surface (each sample's texel grid lands
 * off the centre's, and the surface's depth changes across a texel by its
 * slope) split into layers of a few counts each, and receivers match none
 * (umbra everywhere); too large, occluder and receiver merge into one entry
 * counting every sample (lit everywhere). test_multimap measures both. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/counters.h"
#include "core/hash.h"
#include "rt/rt.h"
#include "techniques/multimap.h"

#define LA_MAX_LAYERS 64
/* Each source texel is warped at 2 x 2 points of its area (at its stored
 * depth): points half a source texel apart land at most one LDI texel apart
 * while the warp magnifies a surface by up to 2, so every LDI texel the
 * surface covers receives one and the forward warp leaves no holes
 * [derived: a grid of spacing <= 1 texel meets every texel it spans]. */
#define LA_WARP_SUB 2

enum { P_LS_SAMPLES = SMAP_P_BIAS, P_LS_PATTERN, P_EPSILON, P_LAYERS }; /* after SMAP_MAP_PARAMS */

/* The map parameters only: matching is within epsilon, not a biased depth
 * test, so the depth biases would change nothing. */
static const ParamDesc la_params[] = {
    SMAP_MAP_PARAMS,
    LS_SAMPLE_PARAMS,
    {"epsilon", PARAM_FLOAT, 0.1, 0, 1e6, "world units",
     "tolerance along the centre's depth axis within which a warped depth counts for an existing layer, and a "
     "receiver matches a layer (Agrawala et al. 2000); stiff: too small splits one surface into many layers "
     "(umbra everywhere), too large merges occluder and receiver (lit everywhere)",
     NULL},
    {"layers", PARAM_INT, 8, 1, LA_MAX_LAYERS, "layers",
     "layer cap per texel of the LDI: warped depths matching no layer when the texel is full are dropped and "
     "counted (aux overflow)",
     NULL},
};

static const char *const la_resources[] = {"shadow_map", "layered_attenuation_ldi", "view_samples", NULL};
static const char *const la_aux[] = {"layers", "overflow", NULL};

/* The layered depth image on the centre map's grid (faces x res^2 texels):
 * a keyed frame resource (resources.h), so it is in the run's log and frame
 * bytes and is reused while its inputs stay. */
typedef struct Ldi {
    const LightView *view; /* the centre's */
    int cap;               /* layers per texel */
    size_t texels;
    uint8_t *used;         /* entries in use per texel */
    uint8_t *unknown;      /* a NaN depth of some sample's map may land here */
    uint32_t *overflow;    /* warped depths dropped: the texel was full */
    float *depth;          /* [texel * cap + l]: depth along the centre face's axis, world units */
    uint16_t *count;       /* samples that saw the entry */
    uint16_t *last;        /* 1 + the last sample counted, so each sample counts once */
} Ldi;

typedef struct LaState {
    int n;
    double epsilon;
    float scene_extent;
    const Ldi *ldi; /* owned by the resource manager */
} LaState;

static void ldi_free(void *res)
{
    Ldi *l = res;
    if (!l) return;
    free(l->used);
    free(l->unknown);
    free(l->overflow);
    free(l->depth);
    free(l->count);
    free(l->last);
    free(l);
}

/* Bytes of an LDI of `texels` texels and `cap` layers: per texel its layer
 * count, unknown flag and overflow counter, per entry depth, count, last. */
static double ldi_bytes(size_t texels, int cap)
{
    return (double)texels * (2.0 + sizeof(uint32_t) + cap * (sizeof(float) + 2.0 * sizeof(uint16_t)));
}

/* Refused before any map is rendered: the LDI of up to `texels` texels (the
 * centre map's most faces) above SHADOWMAP_MAX_BYTES. */
static bool ldi_check(size_t texels, int cap, int res, Error *err)
{
    double bytes = ldi_bytes(texels, cap);
    if (bytes <= (double)SHADOWMAP_MAX_BYTES) return true;
    return error_set(err, "layers = %d at map_size = %d take up to %.2f GiB, above the %.0f GiB "
                          "limit: lower layers or map_size",
                     cap, res, bytes / (1u << 30), (double)SHADOWMAP_MAX_BYTES / (1u << 30));
}

static size_t ldi_resource_bytes(const void *res)
{
    const Ldi *l = res;
    return sizeof *l + (size_t)ldi_bytes(l->texels, l->cap);
}

static const ResourceKind kind_ldi = {"layered_attenuation_ldi", ldi_resource_bytes, ldi_free, RES_FRAME};

static Ldi *ldi_alloc(const LightView *view, int cap, Error *err)
{
    size_t texels = (size_t)view->num_faces * (size_t)view->res * (size_t)view->res;
    Ldi *l = calloc(1, sizeof *l);
    if (!l) {
        error_set(err, "out of memory");
        return NULL;
    }
    *l = (Ldi){.view = view, .cap = cap, .texels = texels};
    l->used = calloc(texels, 1);
    l->unknown = calloc(texels, 1);
    l->overflow = calloc(texels, sizeof *l->overflow);
    l->depth = malloc(texels * (size_t)cap * sizeof *l->depth);
    l->count = malloc(texels * (size_t)cap * sizeof *l->count);
    l->last = malloc(texels * (size_t)cap * sizeof *l->last);
    if (l->used && l->unknown && l->overflow && l->depth && l->count && l->last) return l;
    ldi_free(l);
    error_set(err, "out of memory for the LDI (%.2f GiB)", ldi_bytes(texels, cap) / (1u << 30));
    return NULL;
}

/* The entry of texel `t` nearest depth z within epsilon, or -1. */
static int ldi_match(const Ldi *l, size_t t, double z, double epsilon)
{
    int best = -1;
    double best_d = INFINITY;
    for (int k = 0; k < l->used[t]; k++) {
        double d = fabs(l->depth[t * l->cap + k] - z);
        if (d <= epsilon && d < best_d) best = k, best_d = d;
    }
    return best;
}

/* Sample `k`'s depth z (world units, the centre's axis) lands in texel t. */
static void ldi_insert(Ldi *l, size_t t, double z, int k, double epsilon)
{
    int e = ldi_match(l, t, z, epsilon);
    if (e < 0) {
        if (l->used[t] == l->cap) {
            l->overflow[t]++;
            return;
        }
        e = l->used[t]++;
        l->depth[t * l->cap + e] = (float)z;
        l->count[t * l->cap + e] = 0;
        l->last[t * l->cap + e] = 0;
    }
    size_t i = t * l->cap + e;
    if (l->last[i] == k + 1) return;
    l->last[i] = (uint16_t)(k + 1);
    l->count[i]++;
}

/* The LDI texel of a world point, false when the centre's map misses it. */
static bool ldi_texel(const Ldi *l, dvec3 x, size_t *t, double *z)
{
    MapCoord mc = lightview_locate(l->view, x);
    if (!mc.inside) return false;
    int res = l->view->res, i = (int)mc.s, j = (int)mc.t;
    i = i < res ? i : res - 1; /* s < res, but rounding may reach it */
    j = j < res ? j : res - 1;
    *t = ((size_t)mc.face * (size_t)res + (size_t)j) * (size_t)res + (size_t)i;
    *z = mc.depth_linear;
    return true;
}

/* The stored point of a map at depth z (lightview.h: depth is the face's
 * depth_row, affine in world space, or a paraboloid's radius). */
bool mm_texel_point(const LightView *v, int face, double s, double t, double z, dvec3 *x)
{
    const MapFace *f = &v->face[face];
    dvec3 org, dir;
    lightview_texel_ray(v, face, s, t, &org, &dir);
    if (f->paraboloid) {
        *x = d3_madd(org, dir, z);
        return true;
    }
    const double *row = f->raster.depth_row;
    double at_org = row[0] * org.x + row[1] * org.y + row[2] * org.z + row[3];
    double rate = row[0] * dir.x + row[1] * dir.y + row[2] * dir.z; /* > 0 inside a face's frustum */
    if (!(fabs(rate) > 1e-12)) return false;
    *x = d3_madd(org, dir, (z - at_org) / rate);
    return true;
}

/* A NaN texel's depth is unknown: every LDI texel its ray crosses between
 * the face's near and far depths may hold it, so each becomes unknown (NaN
 * at lookup, issue 13 §1). The segment is walked at half-texel steps of
 * the centre's grid, at most 2 res steps per face it spans. */
static void ldi_mark_ray(Ldi *l, const ShadowMap *m, int face, double s, double t)
{
    const RasterView *rv = &m->view.face[face].raster;
    dvec3 a, b;
    if (!mm_texel_point(&m->view, face, s, t, rv->depth_near, &a) ||
        !mm_texel_point(&m->view, face, s, t, rv->depth_far, &b))
        return;
    MapCoord ca = lightview_locate(l->view, a), cb = lightview_locate(l->view, b);
    double len = ca.face == cb.face ? hypot(cb.s - ca.s, cb.t - ca.t) : 2.0 * l->view->res;
    int steps = (int)fmin(ceil(2.0 * len), 2.0 * l->view->res * l->view->num_faces) + 1;
    for (int k = 0; k <= steps; k++) {
        size_t tx;
        double z;
        if (ldi_texel(l, d3_madd(a, d3_sub(b, a), (double)k / steps), &tx, &z)) l->unknown[tx] = 1;
    }
}

/* The homogeneous world point of texel coordinates (s, t) at stored depth
 * `stored` on an unwarped projective face (perspective or ortho): the face's
 * unprojection of (x_ndc, y_ndc, z_ndc), z_ndc from a linear depth by
 * z = f/(f-n) (1 - n/d) or (d - n)/(f - n) (smap_linear_depth's inverse).
 * Affine in (s, t), so a texel's sub-points are steps of its columns. */
static dvec4 clip_point(const ShadowMap *m, const MapFace *f, double s, double t, double stored)
{
    double n = f->raster.depth_near, far = f->raster.depth_far, z = stored;
    if (m->spec.depth == RASTER_DEPTH_LINEAR)
        z = f->perspective ? far / (far - n) * (1.0 - n / stored) : (stored - n) / (far - n);
    return m4_apply4(&f->world_from_clip, (dvec4){2.0 * s / m->res - 1.0, 2.0 * t / m->res - 1.0, z, 1.0});
}

/* The LA_WARP_SUB^2 sub-points of texel (i, j) at its stored depth, world;
 * returns how many are finite. */
static int texel_points(const ShadowMap *m, int face, int i, int j, float stored, dvec3 *x)
{
    const MapFace *f = &m->view.face[face];
    int k = 0;
    if (f->paraboloid || f->warp != MAP_WARP_NONE) { /* the ray through each sub-point */
        double z = smap_linear_depth(m, face, stored);
        for (int b = 0; b < LA_WARP_SUB; b++)
            for (int a = 0; a < LA_WARP_SUB; a++)
                k += mm_texel_point(&m->view, face, i + (a + 0.5) / LA_WARP_SUB, j + (b + 0.5) / LA_WARP_SUB, z, &x[k]);
        return k;
    }
    dvec4 c = clip_point(m, f, i, j, stored), ds = clip_point(m, f, i + 1, j, stored),
          dt = clip_point(m, f, i, j + 1, stored);
    ds = (dvec4){ds.x - c.x, ds.y - c.y, ds.z - c.z, ds.w - c.w};
    dt = (dvec4){dt.x - c.x, dt.y - c.y, dt.z - c.z, dt.w - c.w};
    for (int b = 0; b < LA_WARP_SUB; b++)
        for (int a = 0; a < LA_WARP_SUB; a++) {
            double u = (a + 0.5) / LA_WARP_SUB, v = (b + 0.5) / LA_WARP_SUB;
            double w = c.w + u * ds.w + v * dt.w;
            if (!(fabs(w) > 0.0)) continue;
            x[k++] = d3((c.x + u * ds.x + v * dt.x) / w, (c.y + u * ds.y + v * dt.y) / w,
                        (c.z + u * ds.z + v * dt.z) / w);
        }
    return k;
}

/* One warped sub-point: its LDI texel and depth there. */
typedef struct Warped {
    size_t texel;
    double z;
} Warped;

/* Warp row j of face f of sample k's map (the forward warp of Agrawala et
 * al.'s layered attenuation maps: each texel's stored point, reprojected
 * into the centre's view); returns the sub-points that land in the LDI. */
static int warp_row(const Ldi *l, const ShadowMap *m, int f, int j, Warped *out)
{
    int n = 0;
    for (int i = 0; i < m->res; i++) {
        float stored = shadowmap_texel(m, f, i, j);
        if (!isfinite(stored)) continue; /* no caster seen (+inf); NaN: marked apart */
        dvec3 x[LA_WARP_SUB * LA_WARP_SUB];
        int k = texel_points(m, f, i, j, stored, x);
        for (int q = 0; q < k; q++) n += ldi_texel(l, x[q], &out[n].texel, &out[n].z);
    }
    return n;
}

/* Warp sample k's map into the LDI, row by row in order (serial: the
 * layers' order is the samples' and the rows', whatever the thread count;
 * an omp-ordered loop ran 18x slower on a loaded machine). The row's warped
 * points are build scratch, freed before it returns. */
static bool ldi_warp(Ldi *l, const ShadowMap *m, int k, double epsilon)
{
    Warped *buf = malloc((size_t)m->res * LA_WARP_SUB * LA_WARP_SUB * sizeof *buf);
    if (!buf) return false;
    for (int f = 0; f < m->num_faces; f++)
        for (int j = 0; j < m->res; j++) {
            int n = warp_row(l, m, f, j, buf);
            for (int q = 0; q < n; q++) ldi_insert(l, buf[q].texel, buf[q].z, k, epsilon);
            for (int i = 0; i < m->res; i++)
                if (isnan(shadowmap_texel(m, f, i, j))) ldi_mark_ray(l, m, f, i + 0.5, j + 0.5);
        }
    free(buf);
    return true;
}

typedef struct LdiArgs {
    const ShadowMap *centre;
    const ShadowMap *const *map; /* the n samples' */
    int n, cap;
    double epsilon;
} LdiArgs;

static void *build_ldi(const void *args, Error *err)
{
    const LdiArgs *a = args;
    Ldi *l = ldi_alloc(&a->centre->view, a->cap, err);
    for (int k = 0; l && k < a->n; k++)
        if (!ldi_warp(l, a->map[k], k, a->epsilon)) {
            ldi_free(l);
            l = NULL;
            error_set(err, "out of memory");
        }
    return l;
}

/* The LDI, keyed by exactly what build_ldi reads: the centre's map (its
 * grid), the samples' maps in order, the layer cap and epsilon. */
static const Ldi *res_ldi(ResourceManager *rm, const LdiArgs *a, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, kind_ldi.name);
    hash_u64(&h, a->centre->key);
    hash_u64(&h, (uint64_t)a->n);
    for (int k = 0; k < a->n; k++) hash_u64(&h, a->map[k]->key);
    hash_u64(&h, (uint64_t)a->cap);
    hash_f64(&h, a->epsilon);
    char desc[160], mk[17];
    hash_hex(a->centre->key, mk);
    snprintf(desc, sizeof desc, "LDI on map %s (%d x %d^2) of %d samples' maps, %d layers, epsilon %.6g", mk,
             a->centre->num_faces, a->centre->res, a->n, a->cap, a->epsilon);
    return rm_acquire(rm, &kind_ldi, hash_final(&h), desc, build_ldi, a, err);
}

static bool la_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    LaState *st = calloc(1, sizeof *st);
    const ShadowMap **map = calloc(LS_MAX_SAMPLES, sizeof *map);
    vec3 *point = calloc(LS_MAX_SAMPLES, sizeof *point);
    if (!st || !map || !point) {
        free(st), free(map), free(point);
        return error_set(err, "out of memory");
    }
    st->n = (int)p[P_LS_SAMPLES];
    st->epsilon = p[P_EPSILON];
    st->scene_extent = scene_extent(ctx->scene);
    ShadowMapSpec spec = smap_spec(p);
    Light probe = {.kind = LIGHT_POINT, .position = ctx->light->position};
    size_t most_texels = shadowmap_bytes_for(&probe, &spec) / sizeof(float);
    LdiArgs a = {NULL, map, st->n, (int)p[P_LAYERS], st->epsilon};
    bool ok = ldi_check(most_texels, a.cap, spec.res, err) &&
              ls_sample_maps(ctx, &spec, st->n, (int)p[P_LS_PATTERN], point, map, err) &&
              (a.centre = ls_point_map(ctx, &spec, ctx->light->position, err)) &&
              (st->ldi = res_ldi(ctx->rm, &a, err));
    free(map);
    free(point);
    if (!ok) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

static void la_release(void *state) { free(state); }
/* V = counter / N of the entry matching the receiver's depth (lifted off
 * the surface by rt_ray_offset, as the reference's rays); lit outside the
 * centre's map, as light_sampling; NaN where a sample's NaN may land. */
static float la_visibility(const LaState *st, vec3 p, vec3 n, float *aux)
{
    const Ldi *l = st->ldi;
    dvec3 q = d3_madd(d3_from(p), d3_from(n), rt_ray_offset(st->scene_extent, p));
    size_t t;
    double z;
    aux[0] = aux[1] = 0.0f;
    if (!ldi_texel(l, q, &t, &z)) return 1.0f;
    aux[0] = l->used[t];
    aux[1] = (float)l->overflow[t];
    if (l->unknown[t]) return NAN;
    work_texels(l->used[t], sizeof *l->depth + sizeof *l->count); /* the texel's layers read (core/counters.h) */
    int e = ldi_match(l, t, z, st->epsilon);
    return e < 0 ? 0.0f : (float)l->count[t * l->cap + e] / (float)st->n;
}

static void la_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const LaState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float aux[2];
        float v = la_visibility(st, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], aux);
        tech_store(ctx, out, begin, s, v);
        if (ctx->aux) memcpy(ctx->aux + (size_t)s * 2, aux, sizeof aux);
    }
}

const Technique tech_layered_attenuation = {
    .name = "layered_attenuation",
    .family = "soft",
    .source = "course §5.2.4 (Agrawala, Ramamoorthi, Heirich & Moll 2000, layered attenuation maps)",
    .summary = "N light samples' hard maps warped into a layered depth image from the light's centre; within "
               "epsilon a layer's counter is incremented, else a layer is added; V = counter / N of the layer "
               "matching the receiver, umbra where none does",
    .params = la_params,
    .num_params = (int)(sizeof la_params / sizeof la_params[0]),
    .resources = la_resources,
    .aux = la_aux,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "samples",
    .prepare = la_prepare,
    .evaluate = la_evaluate,
    .release = la_release,
};
