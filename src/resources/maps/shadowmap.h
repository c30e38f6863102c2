/* shadowmap.h -- the light-space depth map as a keyed resource (course §2.1):
 * the casters rendered by src/raster from the light's fitted faces
 * (lightview.h). A map is identified by exactly what it depends on: the
 * casters' geometry, the light, the fitting target (scene bounds, or the
 * camera's view samples), and the spec below; a sweep over a filter kernel,
 * a bias or a light radius reuses it. A second layer (by back faces, or
 * peeled behind the first) is a map of its own, so techniques that need
 * both acquire both and share the first with everyone else. */
#ifndef SL_SHADOWMAP_H
#define SL_SHADOWMAP_H
#include "core/counters.h"
#include "resources/views/lightview.h"
#include "resources/resources.h"

/* Maps above this many bytes are refused with the size, never attempted. */
#define SHADOWMAP_MAX_BYTES ((size_t)2 << 30)

typedef enum MapLayer {
    MAP_LAYER_FIRST,     /* the nearest surface (back faces included unless culled) */
    MAP_LAYER_BACKFACES, /* the nearest back face: the second layer of closed meshes (Wang & Molnar) */
    MAP_LAYER_PEELED,    /* the nearest surface strictly behind the first layer: any mesh */
    MAP_LAYER_FARTHEST_BACKFACES, /* the farthest back face (a 'z-greater' test, seed 003 §5) */
} MapLayer;

typedef struct ShadowMapSpec {
    int res;                  /* texels per side of each face */
    MapProjection projection;
    MapFit fit;
    RasterDepth depth;        /* linear (world units) or post-projective */
    int depth_bits;           /* 0 (float32), 24 or 16 */
    MapLayer layer;
    RasterCull cull;          /* MAP_LAYER_FIRST only: RASTER_CULL_NONE or _BACK */
    bool triangle_ids;
    bool conservative;
    LightViewParams view;     /* warps, cascades, stabilisation (lightview.h) */
} ShadowMapSpec;

typedef struct ShadowMap {
    uint64_t key;        /* its resource key: maps derived from it (moments, SATs) hash it into theirs */
    ShadowMapSpec spec;
    LightView view;
    int res, num_faces;
    float *depth;        /* num_faces * res * res; +INFINITY where no caster */
    int32_t *triangle;   /* same layout, or NULL */
    RasterStats stats;
} ShadowMap;

/* The spec's defaults: 1024^2, auto projection, scene fit, linear float depth,
 * first layer, one cascade. LogPSM maps are ray cast (logmap.h), the others
 * rasterized. */
ShadowMapSpec shadowmap_spec_default(void);
const ShadowMap *res_shadow_map(ResourceManager *rm, const Scene *scene, int light_index, const ShadowMapSpec *spec,
                                Error *err);
/* Bytes a map of this spec would take (faces from the light and projection). */
size_t shadowmap_bytes_for(const Light *light, const ShadowMapSpec *spec);

/* Depth peeling (course §5.2.3.3's layers, Fig. 1.8): a map of under's view
 * and spec holding, per texel, the nearest surface behind under's by more
 * than shadowmap_peel_epsilon (the rasterizer's peel test, raster.h); empty
 * (+INFINITY) where under is empty or nothing lies behind it. Its key is the
 * caller's (resources/maps/peeled.c keys the layers of a map). Refused for
 * ray-cast (logpsm) maps and warped ndc maps. */
ShadowMap *shadowmap_render_behind(const Scene *scene, const ShadowMap *under, uint64_t key, Error *err);
/* The peel test's epsilon on a face of m, in its stored value space. */
float shadowmap_peel_epsilon(const ShadowMap *m, int face);
/* A map's bytes, and its release (ResourceKind's bytes and destroy). */
size_t shadowmap_bytes(const void *map);
void shadowmap_free(void *map);

/* Stored depth of texel (i, j) of a face, clamped to the edge: one texel
 * fetch of 4 bytes (counters.h). */
static inline float shadowmap_texel(const ShadowMap *m, int face, int i, int j)
{
    work_texels(1, sizeof *m->depth);
    i = i < 0 ? 0 : i >= m->res ? m->res - 1 : i;
    j = j < 0 ? 0 : j >= m->res ? m->res - 1 : j;
    return m->depth[((size_t)face * (size_t)m->res + (size_t)j) * (size_t)m->res + (size_t)i];
}

/* Row j of a face, clamped to the edge, for a caller that reads `taps`
 * texels of it itself (a box filter's row loop): counted here as those taps,
 * so a vectorised row loop carries no counter. */
static inline const float *shadowmap_row(const ShadowMap *m, int face, int j, int taps)
{
    work_texels((uint64_t)taps, sizeof *m->depth);
    j = j < 0 ? 0 : j >= m->res ? m->res - 1 : j;
    return m->depth + ((size_t)face * (size_t)m->res + (size_t)j) * (size_t)m->res;
}

#endif
