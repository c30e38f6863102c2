/* standard.h -- the engine's own resources, each keyed by exactly what it
 * depends on: Embree BVHs (all objects, or casters only; one and the same
 * when every object casts), view samples (geometry + camera), per-light
 * sample classes, and references (also cached on disk, refcache.h). */
#ifndef SL_STANDARD_RESOURCES_H
#define SL_STANDARD_RESOURCES_H
#include "resources/resources.h"
#include "rt/reference.h"

const RtScene *res_bvh(ResourceManager *rm, const Scene *scene, RtGeometrySet set, Error *err);
const ViewSamples *res_view_samples(ResourceManager *rm, const Scene *scene, Error *err);
const uint8_t *res_classes(ResourceManager *rm, const Scene *scene, int light_index, Error *err);
/* Per view sample, 1 where it is a lit candidate whose tangent plane cuts
 * the light (scene/light.h's light_crosses_horizon): the metrics' terminator
 * region. Built with the classes, in the same resource. */
const uint8_t *res_terminator(ResourceManager *rm, const Scene *scene, int light_index, Error *err);

/* A scene-independent table of n points (a tap pattern, a Poisson disk),
 * made by fill(pts, n) with the generator's own fixed seed and keyed by the
 * generator's name (which names that seed) and n: a set-up resource, built
 * once per manager whatever the sweep and left out of the frame. */
typedef struct PointTable { int n; float (*pts)[2]; } PointTable;
typedef void (*PointTableFill)(float (*pts)[2], int n);
const PointTable *res_point_table(ResourceManager *rm, const char *generator, PointTableFill fill, int n, Error *err);

/* Where a reference came from. */
typedef enum RefOrigin { REF_COMPUTED, REF_CACHE_HIT, REF_CACHE_CORRUPT_RECOMPUTED, REF_REUSED } RefOrigin;
const char *ref_origin_name(RefOrigin o);

typedef struct RefRequest {
    int light_index;
    ReferenceParams params;
    const char *cache_dir; /* NULL: no disk cache */
} RefRequest;

typedef struct RefInfo {
    RefOrigin origin;
    uint64_t key;
    char cache_path[1024];
    char cache_note[512];   /* why a cache entry was rejected, or why none was written */
    double seconds;         /* compute or load time */
    double rays_per_second; /* of the computation that made it (0 when loaded) */
} RefInfo;

const Reference *res_reference(ResourceManager *rm, const Scene *scene, const RefRequest *req, RefInfo *info,
                               Error *err);
uint64_t reference_key(const Scene *scene, const RefRequest *req);

#endif
