/* rt.h -- Embree 3 behind an opaque handle: one device per process (created
 * on first use), and a BVH over all of a scene's objects or over its casters
 * only. Embree's C types need `struct`; they do not leak past this layer
 * except through rt_scene_handle(), for benchmarks and ray-cast techniques. */
#ifndef SL_RT_H
#define SL_RT_H
#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <stddef.h>
#include "core/counters.h"
#include "scene/scene.h"

typedef struct RtScene RtScene;

typedef enum RtGeometrySet {
    RT_ALL_OBJECTS, /* primary rays: everything visible */
    RT_CASTERS,     /* occlusion rays: objects with caster = true */
} RtGeometrySet;

/* Thread count Embree's builders use; call before the first rt_scene_create. */
void rt_set_threads(int threads);
/* The process's one Embree device (created on first use), for rt/ modules
 * that build geometry of their own (outer.c); NULL + err on failure. */
RTCDevice rt_device(Error *err);
RtScene *rt_scene_create(const Scene *scene, RtGeometrySet set, Error *err);
void rt_scene_release(RtScene *rs);
RTCScene rt_scene_handle(const RtScene *rs);
size_t rt_scene_bytes(const RtScene *rs);
/* Object index of an Embree geometry id. */
int rt_scene_object(const RtScene *rs, unsigned geom_id);

/* Offset (world units) along the geometric normal that lifts a ray origin off
 * the surface it was found on: scaled to the scene's extent and to the
 * point's magnitude, since float error of a hit point grows with both:
 * 1e-5 of the extent, plus ~128 ulps of the point's largest coordinate.
 * Inline, with its maximum in comparisons (not fmaxf, a libm call here), so
 * a loop over samples runs it in vector lanes (smap.c's batched set-up). A
 * NaN coordinate may or may not reach the offset; the point it lifts is NaN
 * either way, and stays NaN (every consumer tests the lifted point). */
static inline float rt_ray_offset(float scene_extent, vec3 p_world)
{
    float ax = fabsf(p_world.x), ay = fabsf(p_world.y), az = fabsf(p_world.z);
    float m = ax > ay ? ax : ay;
    m = m > az ? m : az;
    return 1e-5f * scene_extent + 128.0f * FLT_EPSILON * m;
}

/* Embree's ray calls, counted (counters.h: one call, and the rays it
 * traces). Every ray the lab traces goes through these. */
static inline void rt_occluded1(RTCScene scene, struct RTCIntersectContext *ctx, struct RTCRay *ray)
{
    work_ray_call(1);
    rtcOccluded1(scene, ctx, ray);
}

static inline void rt_intersect1(RTCScene scene, struct RTCIntersectContext *ctx, struct RTCRayHit *rayhit)
{
    work_ray_call(1);
    rtcIntersect1(scene, ctx, rayhit);
}

/* A packet of 16: its rays are the lanes whose valid[k] is non-zero (-1). */
static inline void rt_occluded16(const int *valid, RTCScene scene, struct RTCIntersectContext *ctx,
                                 struct RTCRay16 *ray)
{
    int lanes = 0;
    for (int k = 0; k < 16; k++) lanes += valid[k] != 0;
    work_ray_call((uint64_t)lanes);
    rtcOccluded16(valid, scene, ctx, ray);
}

#endif
