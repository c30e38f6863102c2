/* outer_penumbra.c -- the outer-penumbra geometry methods of course §5.3.1:
 * a hard shadow map for the umbra, and a light-space buffer, drawn from the
 * light centre's silhouette edges (resources/geometry/silhouette.h), that softens
 * the region outside it.
 *
 *   `smoothies` (Chan & Durand 2003, "Rendering fake soft shadows with
 *   smoothies", EGSR 2003): quads of constant light-space width t extruded
 *   from each silhouette edge, and fans at its vertices, into a "smoothie
 *   buffer" holding per texel the smoothie's depth z_s and its alpha, the
 *   distance from the edge over t, min-blended. A receiver at depth z_r
 *   behind the smoothie takes alpha' = alpha / (1 - z_s / z_r), clamped to
 *   [0, 1]: Parker's ratio (seed 002 §3; course §5.3.1 "using Parker's
 *   ratio"), the shared parker_ratio of rt/outer.h, since
 *   1 - z_s / z_r = (z_r - z_s) / z_r = t0 / L.
 *
 *   `penumbra_map` (Wyman & Hansen 2003, "Penumbra maps: approximate soft
 *   shadows in real-time", EGSR 2003): a cone at each silhouette vertex and
 *   a sheet along each silhouette edge, sized from the light's radius, drawn
 *   into a penumbra map of shadow intensities I = 1 - (Z_P - Z_V) /
 *   (Z_F - Z_V): Z_V the depth of the silhouette point the fragment belongs
 *   to, Z_P the depth of the cone or sheet at the texel, Z_F the shadow
 *   map's depth there (the receiver); fragments behind the receiver
 *   (Z_P >= Z_F) are dropped. I is 1 at the silhouette (Z_P = Z_V) and 0
 *   where the cone meets the receiver, so the visibility is 1 - I.
 *
 * Both add a penumbra outside the hard shadow only, so the umbra is the
 * light centre's hard shadow and is overestimated for large lights (course
 * §5.3.1 [OWN]; measured in test_outer_penumbra and
 * experiments/course-fig5.14-outer-penumbra.lua).
 *
 * Formulas. The papers' texts were not available here (a search of the
 * stored pages found the smoothies paper's abstract, not its formulas): the
 * two above are the papers' as the lab's task for issue 14 states them,
 * beside course §5.3.1 and seed 002; what follows is marked [derived].
 * The frame is a perspective face's (softmap.h): tangent coordinates
 * (x, y) / z at unit depth, depth z along the face's axis, world units.
 *  - Along a projected edge 1/z is affine in the tangent plane, so a point
 *    at parameter u has 1/z = (1 - u)/z_0 + u/z_1 [derived: perspective-
 *    correct interpolation].
 *  - Cones [derived: similar triangles through the light's rim]: a vertex V
 *    at depth Z_V shadows, from a light of radius R at depth 0, the points
 *    up to R (z - Z_V) / Z_V (world units) off its centre ray at depth z, so
 *    the cone's surface at tangent distance rho from V lies at depth Z_P with
 *    1/Z_P = 1/Z_V - rho / R. A sheet is the envelope of the cones of its
 *    edge's points (each texel is drawn by the closest point of the edge,
 *    raster/segment.h), which is Wyman & Hansen's planar sheet between the
 *    two cones when Z_V is the same at both ends.
 *  - Smoothie width [derived]: t = width x D / z_c, tangent units, with
 *    z_c the mean distance of the silhouette's vertices from the light's
 *    centre and D the light's diameter as single_sample_rt takes it
 *    (outer_light_diameter). At width 1 a smoothie at depth z_c spans D
 *    (world units), so alpha' reaches 1 exactly where Parker's outer object
 *    b = D t0 / L ends: the paper's fixed t then matches seed 002 for
 *    occluders at the casters' typical distance, and a smoothie at depth
 *    z_s spans D z_s / z_c: too narrow nearer the light, too wide beyond.
 *  - Blending: both buffers keep the darkest fragment per texel (smoothies'
 *    minimum alpha with its depth, as the paper's min-blending; the penumbra
 *    map's maximum I [derived: the paper's choice was not available to
 *    check]).
 *  - The quads extend to both sides of the edge (segment.h's band): the inner
 *    side covers the occluder's own image, where the hard map's umbra
 *    decides, so an edge's orientation in the light's image is not needed.
 *  - Cost: each edge visits its band's texels, about (length + 2 r) 2 r of
 *    them; at map_size 1024 on a cube face smoothies' t is about 90 texels
 *    on sphere-on-plane, and a vertex near the light spreads its cone over
 *    the whole face (its penumbra does too).
 *
 * Meshes that are not closed 2-manifolds: the silhouette resource extracts
 * their possible silhouette edges by Bergeron's rule (open edges included),
 * and each of those edges gets a smoothie or a sheet, as the boundary of an
 * open surface is a silhouette from every point; they are handled, not
 * refused (test_outer_penumbra: an open plate). Faces must be plain
 * perspective frusta from the light's centre (projection auto, perspective
 * or cube: softmap_frames refuses others by name). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/bufpool.h"
#include "core/counters.h"
#include "core/hash.h"
#include "raster/segment.h"
#include "resources/geometry/silhouette.h"
#include "rt/outer.h"
#include "techniques/softmap.h"

enum { P_WIDTH = SMAP_NUM_PARAMS };

#define OUTER_MAP_PARAMS SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT) /* perspective faces, one map */

static const ParamDesc smoothie_params[] = {
    OUTER_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
    {"width", PARAM_FLOAT, 1, 0.01, 100, "x D / z_c",
     "smoothie width t in the light's image (constant for every edge, as the paper's), as a multiple of the "
     "light's diameter D over z_c, the silhouette's mean distance from the light: 1 makes alpha' end where "
     "Parker's outer object does for edges at z_c",
     NULL},
};

static const ParamDesc penumbra_params[] = {
    OUTER_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
};

static const char *const smoothie_resources[] = {"shadow_map", "silhouette", "smoothie_buffer", "view_samples", NULL};
static const char *const penumbra_resources[] = {"shadow_map", "silhouette", "penumbra_map_buffer", "view_samples",
                                                 NULL};

/* A silhouette edge on one face: tangent coordinates of its (near-clipped)
 * ends, the reciprocal depths there, and the band's radius (tangent units). */
typedef struct FaceEdge {
    double a[2], b[2];
    double inv_z0, inv_z1;
    double radius;
} FaceEdge;

typedef enum OuterKind { OUTER_SMOOTHIES, OUTER_PENUMBRA_MAP } OuterKind;

/* The light-space buffer: a keyed frame resource (resources.h), so it is in
 * the run's log and frame bytes and is reused while its inputs stay. */
typedef struct OuterBuffer {
    size_t texels;
    float *value;   /* per texel of every face: smoothies' alpha (1 where nothing drew), or the penumbra map's
                       shadow intensity I (0 where nothing drew) */
    float *depth;   /* smoothies: z_s (world units along the face's axis), +inf where nothing drew; else NULL */
} OuterBuffer;

typedef struct OuterState {
    OuterKind kind;
    SoftMap sm;     /* the hard map and its faces' frames */
    SmapBias bias;
    const OuterBuffer *buf; /* owned by the resource manager */
    double smoothie_width; /* t, tangent units */
    double light_radius;   /* R = D / 2, world units */
} OuterState;

static void outer_release(void *state) { free(state); }

/* Floats per texel of the light-space buffer: smoothies' alpha and depth, or I. */
static int buffer_floats(OuterKind kind) { return kind == OUTER_SMOOTHIES ? 2 : 1; }

static size_t buffer_bytes(const void *res)
{
    const OuterBuffer *b = res;
    return sizeof *b + b->texels * sizeof(float) * (b->depth ? 2u : 1u);
}

static void buffer_free(void *res)
{
    OuterBuffer *b = res;
    if (!b) return;
    bufpool_free(b->value);
    bufpool_free(b->depth);
    free(b);
}

static const ResourceKind kind_buffer[] = {
    [OUTER_SMOOTHIES] = {"smoothie_buffer", buffer_bytes, buffer_free, RES_FRAME},
    [OUTER_PENUMBRA_MAP] = {"penumbra_map_buffer", buffer_bytes, buffer_free, RES_FRAME},
};

/* ---- projecting the silhouette onto a face ------------------------------ */

/* Tangent coordinates and depth of a face-view point. */
static void to_tangent(dvec4 v, double t[2], double *z)
{
    *z = -v.z;
    t[0] = v.x / *z;
    t[1] = v.y / *z;
}

/* The edge clipped to depths >= near (behind the light's near plane it has
 * no image); false when nothing is left. */
static bool project_edge(const MapFace *f, const SilEdge *e, FaceEdge *out)
{
    dvec4 p = m4_apply(&f->view_from_world, d3_from(e->a)), q = m4_apply(&f->view_from_world, d3_from(e->b));
    double near = f->raster.depth_near, zp = -p.z, zq = -q.z;
    if (!(zp >= near) && !(zq >= near)) return false;
    if (zp < near || zq < near) { /* move the near end onto the plane (zp != zq here) */
        double s = (near - zp) / (zq - zp);
        dvec4 c = {p.x + s * (q.x - p.x), p.y + s * (q.y - p.y), -near, 1.0};
        if (zp < near) p = c;
        else q = c;
    }
    double z0, z1;
    to_tangent(p, out->a, &z0);
    to_tangent(q, out->b, &z1);
    out->inv_z0 = 1.0 / z0;
    out->inv_z1 = 1.0 / z1;
    return true;
}

/* ---- the fragments -------------------------------------------------------- */

typedef struct Draw {
    const OuterState *st; /* its buffer is the one being drawn, not yet st->buf */
    int face;
    float *value, *depth; /* this face's texels */
    const FaceEdge *edge;
} Draw;

static size_t texel_index(const ShadowMap *m, int face, int i, int j)
{
    return ((size_t)face * (size_t)m->res + (size_t)j) * (size_t)m->res + (size_t)i;
}

/* Smoothies: alpha = distance / t, min-blended with the smoothie's depth. */
static void smoothie_fragment(void *user, int i, int j, double u, double dist)
{
    Draw *d = user;
    size_t k = (size_t)j * (size_t)d->st->sm.map->res + (size_t)i;
    float alpha = (float)(dist / d->st->smoothie_width);
    if (!(alpha < d->value[k])) return;
    d->value[k] = alpha;
    d->depth[k] = (float)(1.0 / ((1.0 - u) * d->edge->inv_z0 + u * d->edge->inv_z1));
}

/* Penumbra maps: the cone or sheet at depth Z_P (header: 1/Z_P = 1/Z_V -
 * rho / R) against the receiver Z_F the hard map holds; a NaN Z_F stays NaN. */
static void penumbra_fragment(void *user, int i, int j, double u, double dist)
{
    Draw *d = user;
    const OuterState *st = d->st;
    double inv_zv = (1.0 - u) * d->edge->inv_z0 + u * d->edge->inv_z1;
    double inv_zp = inv_zv - dist / st->light_radius;
    if (!(inv_zp > 0.0)) return; /* the cone has left every finite depth */
    double z_v = 1.0 / inv_zv, z_p = 1.0 / inv_zp, z_f = softmap_depth(&st->sm, d->face, i, j);
    if (z_f <= z_v || z_p >= z_f) return; /* the occluder itself, or the fragment lies behind the receiver */
    size_t k = (size_t)j * (size_t)st->sm.map->res + (size_t)i;
    d->value[k] = nan_maxf(d->value[k], (float)(1.0 - (z_p - z_v) / (z_f - z_v))); /* z_f > z_v: no division by 0 */
}

/* ---- the buffer ------------------------------------------------------------ */

#define BAND_ROWS 16

/* One face: every edge's band, in bands of rows drawn in parallel. */
static void draw_face(const OuterState *st, OuterBuffer *buf, int face, const FaceEdge *edges, int n)
{
    const SoftFace *sf = &st->sm.face[face];
    int res = st->sm.map->res, bands = (res + BAND_ROWS - 1) / BAND_ROWS;
    RasterGrid g = {res, res, sf->l, sf->b, sf->dx, sf->dy};
    RasterSegmentFn fn = st->kind == OUTER_SMOOTHIES ? smoothie_fragment : penumbra_fragment;
    size_t base = texel_index(st->sm.map, face, 0, 0);
#pragma omp parallel for schedule(dynamic, 1)
    for (int band = 0; band < bands; band++) {
        Draw d = {st, face, buf->value + base, buf->depth ? buf->depth + base : NULL, NULL};
        int row_end = (band + 1) * BAND_ROWS < res ? (band + 1) * BAND_ROWS : res;
        for (int e = 0; e < n; e++) {
            d.edge = &edges[e];
            raster_segment_band(&g, edges[e].a, edges[e].b, edges[e].radius, band * BAND_ROWS, row_end, fn, &d);
        }
    }
}

/* [derived] The band radius: smoothies' t; a sheet's widest cone reaches the
 * face's far plane at rho = R (1/Z_V - 1/z_far) (header: 1/Z_P = 1/Z_V - rho/R). */
static double band_radius(const OuterState *st, const MapFace *f, const FaceEdge *e)
{
    if (st->kind == OUTER_SMOOTHIES) return st->smoothie_width;
    double inv_near = fmax(e->inv_z0, e->inv_z1);
    return fmax(0.0, st->light_radius * (inv_near - 1.0 / f->raster.depth_far));
}

typedef struct BufferArgs {
    const OuterState *st;
    const Silhouette *sil;
} BufferArgs;

/* Allocates the buffer with every texel at its empty value; NULL + err when out of memory. */
static OuterBuffer *buffer_alloc(OuterKind kind, size_t texels, Error *err)
{
    OuterBuffer *b = calloc(1, sizeof *b);
    if (b) {
        b->texels = texels;
        b->value = bufpool_alloc(sizeof *b->value * texels); /* kept between builds (core/bufpool.h) */
        b->depth = buffer_floats(kind) == 2 ? bufpool_alloc(sizeof *b->depth * texels) : NULL;
    }
    if (!b || !b->value || (buffer_floats(kind) == 2 && !b->depth)) {
        buffer_free(b);
        error_set(err, "out of memory: the %s of %zu texels", kind_buffer[kind].name, texels);
        return NULL;
    }
    for (size_t k = 0; k < texels; k++) {
        b->value[k] = kind == OUTER_SMOOTHIES ? 1.0f : 0.0f;
        if (b->depth) b->depth[k] = INFINITY;
    }
    return b;
}

/* The resource's build: every face's projected edges drawn into a fresh
 * buffer. The projected edges are build scratch, freed before it returns. */
static void *build_buffer(const void *args, Error *err)
{
    const BufferArgs *a = args;
    const OuterState *st = a->st;
    const ShadowMap *m = st->sm.map;
    const Silhouette *sil = a->sil;
    OuterBuffer *buf = buffer_alloc(st->kind, (size_t)m->num_faces * (size_t)m->res * (size_t)m->res, err);
    FaceEdge *edges = buf ? malloc(sizeof *edges * (size_t)(sil->num_edges > 0 ? sil->num_edges : 1)) : NULL;
    if (!edges) {
        if (buf) error_set(err, "out of memory: %d silhouette edges", sil->num_edges);
        buffer_free(buf);
        return NULL;
    }
    for (int face = 0; face < m->num_faces; face++) {
        const MapFace *f = &m->view.face[face];
        int n = 0;
        for (int e = 0; e < sil->num_edges; e++)
            if (project_edge(f, &sil->edges[e], &edges[n])) {
                edges[n].radius = band_radius(st, f, &edges[n]);
                n++;
            }
        draw_face(st, buf, face, edges, n);
    }
    free(edges);
    return buf;
}

/* The buffer, keyed by exactly what build_buffer reads: the hard map (its
 * depths and faces' frames), the silhouette, and the band's one parameter,
 * smoothies' t or the penumbra map's R; the bias is left out (evaluate's). */
static const OuterBuffer *res_outer_buffer(ResourceManager *rm, const OuterState *st, const Silhouette *sil,
                                           Error *err)
{
    const ShadowMap *m = st->sm.map;
    double band = st->kind == OUTER_SMOOTHIES ? st->smoothie_width : st->light_radius;
    Hasher h;
    hash_init(&h);
    hash_str(&h, kind_buffer[st->kind].name);
    hash_u64(&h, m->key);
    hash_u64(&h, sil->key);
    hash_f64(&h, band);
    char desc[160], mk[17];
    hash_hex(m->key, mk);
    snprintf(desc, sizeof desc, "%s of map %s (%d x %d^2), %d edges, %s %.6g", kind_buffer[st->kind].name, mk,
             m->num_faces, m->res, sil->num_edges, st->kind == OUTER_SMOOTHIES ? "t" : "R", band);
    BufferArgs a = {st, sil};
    return rm_acquire(rm, &kind_buffer[st->kind], hash_final(&h), desc, build_buffer, &a, err);
}

/* z_c of the smoothie width: the mean distance of the silhouette's edge ends
 * from the light's centre (world units); 0 without edges. */
static double silhouette_distance(const Silhouette *sil, const Light *light)
{
    double sum = 0.0;
    for (int e = 0; e < sil->num_edges; e++)
        sum += v3_len(v3_sub(sil->edges[e].a, light->position)) + v3_len(v3_sub(sil->edges[e].b, light->position));
    return sil->num_edges > 0 ? sum / (2.0 * sil->num_edges) : 0.0;
}

/* ---- prepare and evaluate ------------------------------------------------- */

/* The hard map and the buffer beside it together stay under the cap on
 * shadow maps, checked before either is built. */
static bool check_bytes(const Light *light, const ShadowMapSpec *spec, OuterKind kind, Error *err)
{
    size_t map = shadowmap_bytes_for(light, spec);
    size_t texels = map / sizeof(float), bytes = map + texels * (size_t)buffer_floats(kind) * sizeof(float);
    if (bytes <= SHADOWMAP_MAX_BYTES) return true;
    return error_set(err, "map_size %d: the map and its light-space buffer need %.2f GiB, above the %.0f GiB "
                          "cap on shadow maps (map_size up to %d here)",
                     spec->res, (double)bytes / (1 << 30), (double)SHADOWMAP_MAX_BYTES / (1 << 30),
                     (int)floor(spec->res * sqrt((double)SHADOWMAP_MAX_BYTES / (double)bytes)));
}

static bool outer_prepare(const TechContext *ctx, OuterKind kind, const char *name, void **state, Error *err)
{
    const double *p = ctx->params;
    ShadowMapSpec spec = smap_spec(p);
    if (!check_bytes(ctx->light, &spec, kind, err)) return false;
    OuterState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->kind = kind;
    st->bias = smap_bias(p, ctx->scene);
    st->light_radius = 0.5 * outer_light_diameter(ctx->light);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    const Silhouette *sil = map && softmap_frames(&st->sm, map, ctx->light, name, err)
                                ? res_silhouette(ctx->rm, ctx->scene, ctx->light_index, err)
                                : NULL;
    if (sil && kind == OUTER_SMOOTHIES) {
        double z_c = silhouette_distance(sil, ctx->light);
        /* t = width D / z_c (header); no silhouette: nothing is drawn, any positive t serves */
        st->smoothie_width = z_c > 0.0 ? p[P_WIDTH] * 2.0 * st->light_radius / z_c : 1.0;
    }
    if (!sil || !(st->buf = res_outer_buffer(ctx->rm, st, sil, err))) {
        outer_release(st);
        return false;
    }
    *state = st;
    return true;
}

static bool smoothies_prepare(const TechContext *ctx, void **state, Error *err)
{
    return outer_prepare(ctx, OUTER_SMOOTHIES, "smoothies", state, err);
}

static bool penumbra_prepare(const TechContext *ctx, void **state, Error *err)
{
    return outer_prepare(ctx, OUTER_PENUMBRA_MAP, "penumbra_map", state, err);
}

/* Visibility outside the hard shadow at texel (i, j) of the receiver's face. */
static float outer_lit(const OuterState *st, const SmapReceiver *r, int i, int j)
{
    const ShadowMap *m = st->sm.map;
    i = i < 0 ? 0 : i >= m->res ? m->res - 1 : i;
    j = j < 0 ? 0 : j >= m->res ? m->res - 1 : j;
    size_t k = texel_index(m, r->mc.face, i, j);
    const OuterBuffer *b = st->buf;
    work_texels(buffer_floats(st->kind), sizeof *b->value); /* the buffer's texel (core/counters.h) */
    if (st->kind == OUTER_PENUMBRA_MAP) return 1.0f - b->value[k]; /* Wyman & Hansen's I is the shadow's */
    double z_s = b->depth[k], z_r = r->mc.depth_linear;
    if (!(z_r > z_s)) return 1.0f; /* in front of the smoothie, or none here */
    /* Chan & Durand 2003: alpha' = alpha / (1 - z_s / z_r), clamped; z_r > z_s > 0, so the ratio is > 0 */
    return (float)nan_clamp(b->value[k] / parker_ratio((float)(z_r - z_s), (float)z_r), 0.0, 1.0);
}

static void outer_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const OuterState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r)) {
            int i, j;
            smap_texel(&r, &i, &j);
            v = smap_lit(st->sm.map, &r, i, j); /* the umbra: the light centre's hard shadow; NaN stays NaN */
            if (v > 0.0f) v = outer_lit(st, &r, i, j);
        }
        tech_store(ctx, out, begin, s, v);
    }
}

#define OUTER_LIGHTS (LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT))

const Technique tech_smoothies = {
    .name = "smoothies",
    .family = "outer penumbra",
    .source = "course §5.3.1 (Chan & Durand 2003, Rendering fake soft shadows with smoothies); seed 002's ratio",
    .summary = "hard shadow map plus constant-width light-space quads at the centre's silhouette edges; alpha = "
               "distance / width, min-blended, rescaled by Parker's ratio: outer penumbra only",
    .params = smoothie_params,
    .num_params = (int)(sizeof smoothie_params / sizeof smoothie_params[0]),
    .resources = smoothie_resources,
    .rgb = false,
    .lights = OUTER_LIGHTS,
    .main_param = "width",
    .prepare = smoothies_prepare,
    .evaluate = outer_evaluate,
    .release = outer_release,
};

const Technique tech_penumbra_map = {
    .name = "penumbra_map",
    .family = "outer penumbra",
    .source = "course §5.3.1 (Wyman & Hansen 2003, Penumbra maps: approximate soft shadows in real-time)",
    .summary = "hard shadow map plus cones at the centre's silhouette vertices and sheets along its edges, sized "
               "from the light's radius; visibility 1 - I, I = 1 - (Z_P - Z_V) / (Z_F - Z_V): outer penumbra only",
    .params = penumbra_params,
    .num_params = (int)(sizeof penumbra_params / sizeof penumbra_params[0]),
    .resources = penumbra_resources,
    .rgb = false,
    .lights = OUTER_LIGHTS,
    .main_param = "map_size",
    .prepare = penumbra_prepare,
    .evaluate = outer_evaluate,
    .release = outer_release,
};
