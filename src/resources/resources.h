/* resources.h -- the resource manager: values with keys (architecture.md).
 * A resource (an Embree BVH, view samples, a depth map at a resolution and
 * projection, a SAT, ...) is identified by a 64-bit key hashed from exactly
 * the inputs it depends on. rm_acquire builds it on first request, times it,
 * counts its bytes, and hands the same object to every later request with the
 * same key. Every acquisition is logged, so a run's record says what was
 * built and what was reused: that is how a scene's unneeded work is left out,
 * and how a sweep over a kernel size proves it built its depth map once. */
#ifndef SL_RESOURCES_H
#define SL_RESOURCES_H
#include <stddef.h>
#include <stdint.h>
#include "core/counters.h"
#include "core/error.h"

/* What a renderer would pay for a resource each frame (architecture.md,
 * "Frame time"). A resource acquired while one of another category is built
 * is of that category too (the BVH the view samples were traced with is
 * G-buffer), unless a frame resource also acquires it directly. */
typedef enum ResourceCategory {
    RES_FRAME,      /* rebuilt every frame (a shadow map): in the frame time; the default */
    RES_GBUFFER,    /* what a renderer already has (view samples, their classes): left out */
    RES_SETUP,      /* scene-independent constant tables (tap patterns), keyed by their
                     * parameters and kept by rm_clear, so built once: set-up, left out */
    RES_EVALUATION, /* the lab's own measurement (the reference): never in a frame */
} ResourceCategory;
const char *resource_category_name(ResourceCategory c);

/* What a kind of resource is and how to measure and free one. */
typedef struct ResourceKind {
    const char *name;                  /* e.g. "embree_bvh" */
    size_t (*bytes)(const void *res);
    void (*destroy)(void *res);
    ResourceCategory category;
} ResourceKind;

/* Builds a resource from the caller's arguments; NULL + err on failure. */
typedef void *(*ResourceBuildFn)(const void *args, Error *err);

/* One line of a run's resource log. */
typedef struct ResourceEvent {
    const char *kind;
    char desc[160];   /* human-readable key, e.g. "casters of scene 3fa2..." */
    uint64_t key;
    bool built;       /* false: reused */
    double build_s;   /* time of the build that made it (also shown on reuse) */
    size_t bytes;
    double own_s;     /* build_s less the builds of resources acquired inside it */
    ResourceCategory category; /* the kind's, or the one it was acquired for (see above) */
    int builds;       /* build_s and own_s are the medians of this many builds (rm_scope_begin) */
    double cold_own_s; /* own_s of the first of them */
    WorkCounters work; /* counters.h: of its first build, less the builds nested inside it */
} ResourceEvent;

typedef struct ResourceManager ResourceManager;

ResourceManager *rm_create(void);
void rm_destroy(ResourceManager *rm);
/* Destroy every resource but the set-up tables (and the log): later requests
 * build afresh. A sweep calls it between techniques that share nothing, to
 * bound memory; the small scene-independent tables stay, built once. */
void rm_clear(ResourceManager *rm);

/* Find or build the resource (kind, key). `desc` describes the key for the
 * log. Thread-compatible, not thread-safe: acquire from one thread. */
void *rm_acquire(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                 ResourceBuildFn build, const void *args, Error *err);

/* Instrumentation: fn sees every resource the manager builds, with its
 * kind's name, as soon as it is built and before anything acquires it
 * (NULL: none). Fault-injection tests use it (test_nan_inject.c poisons
 * every shadow map, whatever key a technique asks for, before anything
 * derived from it is built). */
typedef void (*ResourceBuiltFn)(const char *kind, void *res, void *user);
void rm_on_build(ResourceManager *rm, ResourceBuiltFn fn, void *user);

/* The log since the last rm_log_reset (one run's worth). */
int rm_log_count(const ResourceManager *rm);
const ResourceEvent *rm_log_event(const ResourceManager *rm, int i);
void rm_log_reset(ResourceManager *rm);
/* Append a note to the logged description of (kind name, key), e.g. where a
 * resource was loaded from. */
void rm_log_note(ResourceManager *rm, const char *kind, uint64_t key, const char *note);

/* Scopes: what one stage (a technique's prepare) depends on. Between
 * rm_scope_begin and rm_scope_end every acquisition is recorded once, built or
 * reused, together with the resources it was built from (also when it is
 * reused and they are not asked for again), so the sum of their own_s is the
 * cost of building the stage's resources from nothing, whatever an earlier
 * stage or run already built. `built` is true for builds inside the scope.
 * A frame resource built inside the scope is built `builds` times, each
 * further one a fresh build made after the one before is destroyed (so its
 * buffers serve it, core/bufpool.h; the last stays cached), and
 * its build_s and own_s are their medians, so the build time a frame pays is
 * as steady as a median evaluation; builds = 1 times the one (cold) build.
 * With budget_s > 0 a resource's builds stop once they took budget_s (as
 * timed evaluations do, lab.h RenderTiming). A reused resource keeps the
 * medians of the builds that made it. */
void rm_scope_begin(ResourceManager *rm, int builds, double budget_s);
void rm_scope_end(ResourceManager *rm);
int rm_scope_count(const ResourceManager *rm);
const ResourceEvent *rm_scope_event(const ResourceManager *rm, int i);
/* Wall time of the builds made inside the scope, every repeat and category
 * (what the stage's own set-up is net of). */
double rm_scope_build_s(const ResourceManager *rm);
/* The work (counters.h) of those builds, every repeat and category. */
WorkCounters rm_scope_work(const ResourceManager *rm);

/* Totals over everything the manager holds. */
size_t rm_bytes(const ResourceManager *rm);
int rm_count(const ResourceManager *rm);

#endif
