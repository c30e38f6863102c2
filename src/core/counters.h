/* counters.h -- machine-independent work counters (issue 17, "Cost that
 * transfers to other machines"): what an evaluation or a resource build
 * did, counted where the work is done, in the SHARED readers and calls
 * (shadowmap.h's texel reader, prefilter.c's moment / SAT / min-max reads,
 * rt.h's ray calls, raster.c's stats), never by hand in a technique.
 *
 * Each thread adds to its own block (`_Thread_local`, one add per call, no
 * lock, no atomic); work_snapshot sums every thread's block. An interval's
 * work is the difference of two snapshots taken from serial code around it,
 * so the engine needs nothing in its parallel regions and the evaluate
 * signature stays as it is. */
#ifndef SL_COUNTERS_H
#define SL_COUNTERS_H
#include <stdbool.h>
#include <stdint.h>

typedef struct WorkCounters {
    uint64_t texel_fetches; /* texels read from maps: depth texels, moment / SAT / min-max entries */
    uint64_t texel_bytes;   /* bytes those reads load, at the element size stored here
                             * (float32 depth: 4; a SAT corner: channels x 4 or 8) */
    uint64_t ray_calls;     /* Embree calls (rtcOccluded1/16, rtcIntersect1): a packet is one call */
    uint64_t rays;          /* rays those calls traced (a packet's active lanes) */
    uint64_t triangles;     /* triangles the rasterizer set up (before culling and clipping) */
    uint64_t fragments;     /* texels the rasterizer wrote (a fragment the depth test rejected is
                             * not counted: a lower bound of a GPU's fragment count under overdraw) */
    uint64_t edges;         /* possible silhouette edges tested against a view sample's cone
                             * (exact_soft.c's exact_for_silhouette: each edge sphere's cone test) */
    uint64_t influence;     /* (caster triangle, view sample) pairs view_sample_mapping maps: the sum of the
                             * triangles' influence regions in view samples (map_triangle's calls, both
                             * mask paths; a sample whose light samples are all hidden takes no more) */
    uint64_t micropatches;  /* occluder polygons backprojected onto the light's samples (backprojection.c's
                             * cover() and contour loops: each micropatch, microquad or microtri, each contour edge) */
} WorkCounters;

/* This thread's block; register-free to write (work_snapshot finds it).
 * initial-exec: one %fs-relative add, also inside the Lua module. */
typedef struct WorkThread {
    WorkCounters c;
    bool registered;
} WorkThread;
extern _Thread_local WorkThread work_thread __attribute__((tls_model("initial-exec")));

/* n texel reads of `bytes_each` bytes each. */
static inline void work_texels(uint64_t n, uint64_t bytes_each)
{
    work_thread.c.texel_fetches += n;
    work_thread.c.texel_bytes += n * bytes_each;
}

/* One Embree call tracing `rays` rays. */
static inline void work_ray_call(uint64_t rays)
{
    work_thread.c.ray_calls++;
    work_thread.c.rays += rays;
}

/* One render of `triangles` triangles writing `fragments` texels. */
static inline void work_raster(uint64_t triangles, uint64_t fragments)
{
    work_thread.c.triangles += triangles;
    work_thread.c.fragments += fragments;
}

/* n silhouette edges tested against a view sample's cone. */
static inline void work_edges(uint64_t n) { work_thread.c.edges += n; }

/* n (triangle, view sample) pairs of an influence region mapped. */
static inline void work_influence(uint64_t n) { work_thread.c.influence += n; }
/* n occluder polygons (or contour edges) backprojected onto the light. */
static inline void work_micropatches(uint64_t n) { work_thread.c.micropatches += n; }

/* The sum over every thread that ever counted (threads that have exited
 * included). Call it from serial code, outside parallel regions: it runs one
 * OpenMP region of its own, in which each thread of the team registers its
 * block on first use. */
void work_snapshot(WorkCounters *total);

/* a += b; out = a - b (a later snapshot less an earlier one). */
void work_add(WorkCounters *a, const WorkCounters *b);
WorkCounters work_diff(const WorkCounters *later, const WorkCounters *earlier);

#endif
