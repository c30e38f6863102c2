/* standard.c -- builders and keys of the engine's own resources. */
#include "resources/standard.h"
#include <stdio.h>
#include <stdlib.h>
#include "core/hash.h"
#include "core/timer.h"
#include "resources/refcache.h"

/* ---- Embree BVH ------------------------------------------------------- */

typedef struct BvhArgs { const Scene *scene; RtGeometrySet set; } BvhArgs;

static void *build_bvh(const void *args, Error *err)
{
    const BvhArgs *a = args;
    return rt_scene_create(a->scene, a->set, err);
}
static size_t bvh_bytes(const void *r) { return rt_scene_bytes(r); }
static void bvh_destroy(void *r) { rt_scene_release(r); }
static const ResourceKind kind_bvh = {"embree_bvh", bvh_bytes, bvh_destroy, RES_FRAME};

const RtScene *res_bvh(ResourceManager *rm, const Scene *scene, RtGeometrySet set, Error *err)
{
    /* When every object casts, the caster BVH is the full one: one key. */
    bool all = set == RT_ALL_OBJECTS || scene_all_cast(scene);
    BvhArgs a = {scene, all ? RT_ALL_OBJECTS : RT_CASTERS};
    uint64_t key = all ? scene->hash_geometry : scene->hash_casters;
    char desc[160];
    snprintf(desc, sizeof desc, "%s, %d triangles", all ? "all objects" : "casters only", scene->num_triangles);
    return rm_acquire(rm, &kind_bvh, key, desc, build_bvh, &a, err);
}

/* ---- view samples ----------------------------------------------------- */

typedef struct ViewArgs { ResourceManager *rm; const Scene *scene; } ViewArgs;

static void *build_view(const void *args, Error *err)
{
    const ViewArgs *a = args;
    const RtScene *bvh = res_bvh(a->rm, a->scene, RT_ALL_OBJECTS, err);
    ViewSamples *vs = calloc(1, sizeof *vs);
    if (!bvh || !vs || !view_samples_trace(bvh, a->scene, vs, err)) {
        if (!vs) error_set(err, "out of memory");
        free(vs);
        return NULL;
    }
    return vs;
}
static size_t view_bytes(const void *r) { return view_samples_bytes(r); }
static void view_destroy(void *r)
{
    view_samples_free(r);
    free(r);
}
/* A renderer has its G-buffer: view samples (and the BVH they were traced with) are not in the frame. */
static const ResourceKind kind_view = {"view_samples", view_bytes, view_destroy, RES_GBUFFER};

static uint64_t view_key(const Scene *scene)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, scene->hash_geometry);
    hash_u64(&h, scene->hash_camera);
    return hash_final(&h);
}

const ViewSamples *res_view_samples(ResourceManager *rm, const Scene *scene, Error *err)
{
    ViewArgs a = {rm, scene};
    char desc[160];
    snprintf(desc, sizeof desc, "%dx%d samples", scene->camera.width * scene->camera.supersample,
             scene->camera.height * scene->camera.supersample);
    return rm_acquire(rm, &kind_view, view_key(scene), desc, build_view, &a, err);
}

/* ---- sample classes per light ----------------------------------------- */

typedef struct ClassArgs { const ViewSamples *vs; const Scene *scene; int light; } ClassArgs;
/* cls: SampleClass per sample; terminator: 1 where the sample is a lit
 * candidate whose tangent plane cuts the light (light_crosses_horizon). */
typedef struct Classes { uint8_t *cls, *terminator; size_t n; } Classes;

static void classes_destroy(void *r)
{
    free(((Classes *)r)->cls);
    free(((Classes *)r)->terminator);
    free(r);
}

static void mark_terminator(const ViewSamples *vs, const Light *l, const uint8_t *cls, uint8_t *terminator)
{
#pragma omp parallel for schedule(static)
    for (int s = 0; s < vs->count; s++)
        terminator[s] = cls[s] == SAMPLE_LIT_CANDIDATE &&
                        light_crosses_horizon(l, vs->p_world[s], vs->n_geom_world[s]);
}

static void *build_classes(const void *args, Error *err)
{
    const ClassArgs *a = args;
    Classes *c = calloc(1, sizeof *c);
    if (c) {
        c->cls = malloc((size_t)a->vs->count);
        c->terminator = malloc((size_t)a->vs->count);
    }
    if (!c || !c->cls || !c->terminator) {
        if (c) classes_destroy(c);
        error_set(err, "out of memory");
        return NULL;
    }
    c->n = (size_t)a->vs->count;
    view_samples_classify(a->vs, a->scene, a->light, c->cls);
    mark_terminator(a->vs, &a->scene->lights[a->light], c->cls, c->terminator);
    return c;
}
static size_t classes_bytes(const void *r) { return 2 * ((const Classes *)r)->n; }
static const ResourceKind kind_classes = {"sample_classes", classes_bytes, classes_destroy, RES_GBUFFER};

static const Classes *acquire_classes(ResourceManager *rm, const Scene *scene, int light_index, Error *err)
{
    const ViewSamples *vs = res_view_samples(rm, scene, err);
    if (!vs) return NULL;
    Hasher h;
    hash_init(&h);
    hash_u64(&h, view_key(scene));
    hash_u64(&h, scene->hash_lights[light_index]);
    ClassArgs a = {vs, scene, light_index};
    char desc[160];
    snprintf(desc, sizeof desc, "light %d (%s)", light_index + 1, light_kind_name(scene->lights[light_index].kind));
    return rm_acquire(rm, &kind_classes, hash_final(&h), desc, build_classes, &a, err);
}

const uint8_t *res_classes(ResourceManager *rm, const Scene *scene, int light_index, Error *err)
{
    const Classes *c = acquire_classes(rm, scene, light_index, err);
    return c ? c->cls : NULL;
}

const uint8_t *res_terminator(ResourceManager *rm, const Scene *scene, int light_index, Error *err)
{
    const Classes *c = acquire_classes(rm, scene, light_index, err);
    return c ? c->terminator : NULL;
}

/* ---- constant point tables ---------------------------------------------- */

typedef struct TableArgs { PointTableFill fill; int n; } TableArgs;

static void *build_table(const void *args, Error *err)
{
    const TableArgs *a = args;
    PointTable *t = malloc(sizeof *t);
    if (t) t->pts = malloc(sizeof *t->pts * (size_t)a->n);
    if (!t || !t->pts) {
        free(t);
        error_set(err, "out of memory for a table of %d points", a->n);
        return NULL;
    }
    t->n = a->n;
    a->fill(t->pts, a->n);
    return t;
}
static size_t table_bytes(const void *r) { return sizeof(float[2]) * (size_t)((const PointTable *)r)->n; }
static void table_destroy(void *r)
{
    free(((PointTable *)r)->pts);
    free(r);
}
static const ResourceKind kind_table = {"point_table", table_bytes, table_destroy, RES_SETUP};

const PointTable *res_point_table(ResourceManager *rm, const char *generator, PointTableFill fill, int n, Error *err)
{
    if (n < 1) {
        error_set(err, "%s: %d points; at least 1", generator, n);
        return NULL;
    }
    Hasher h;
    hash_init(&h);
    hash_str(&h, generator);
    hash_u64(&h, (uint64_t)n);
    TableArgs a = {fill, n};
    char desc[160];
    snprintf(desc, sizeof desc, "%s, %d points", generator, n);
    return rm_acquire(rm, &kind_table, hash_final(&h), desc, build_table, &a, err);
}

/* ---- references --------------------------------------------------------- */

/* Bump when the reference's algorithm changes, so old cache entries miss. */
#define REFERENCE_VERSION 3 /* 2: visibility over the part of the light above the horizon; 3: std_error by randomised QMC (rt/reference.c) */

const char *ref_origin_name(RefOrigin o)
{
    static const char *const names[] = {"computed", "cache_hit", "cache_corrupt_recomputed", "reused_in_process"};
    return names[o];
}

uint64_t reference_key(const Scene *scene, const RefRequest *req)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, REFERENCE_VERSION);
    hash_u64(&h, view_key(scene));
    hash_u64(&h, scene->hash_casters);
    hash_u64(&h, scene->hash_lights[req->light_index]);
    hash_u64(&h, (uint64_t)req->params.measure);
    hash_u64(&h, (uint64_t)req->params.samples);
    hash_u64(&h, (uint64_t)req->params.pattern);
    hash_u64(&h, req->params.seed);
    if (req->params.shared_set) hash_u64(&h, 1); /* per-view-sample keys stay as they were */
    return hash_final(&h);
}

typedef struct RefArgs {
    ResourceManager *rm;
    const Scene *scene;
    const RefRequest *req;
    RefInfo *info;
} RefArgs;

static void *compute_reference(const RefArgs *a, Reference *ref, Error *err)
{
    const RtScene *bvh = res_bvh(a->rm, a->scene, RT_CASTERS, err);
    const ViewSamples *vs = bvh ? res_view_samples(a->rm, a->scene, err) : NULL;
    const uint8_t *cls = vs ? res_classes(a->rm, a->scene, a->req->light_index, err) : NULL;
    if (!cls) return NULL;
    double t0 = timer_now_s();
    if (!reference_compute(bvh, a->scene, a->req->light_index, vs, cls, &a->req->params, ref, err)) return NULL;
    double dt = timer_now_s() - t0;
    a->info->rays_per_second = dt > 0 ? (double)ref->rays / dt : 0.0;
    return ref;
}

static void *build_reference(const void *args, Error *err)
{
    const RefArgs *a = args;
    RefInfo *info = a->info;
    Reference *ref = calloc(1, sizeof *ref);
    if (!ref) { error_set(err, "out of memory"); return NULL; }
    double t0 = timer_now_s();
    info->origin = REF_COMPUTED;
    if (a->req->cache_dir) {
        refcache_path(a->req->cache_dir, info->key, info->cache_path, sizeof info->cache_path);
        Error why;
        RefcacheStatus st = refcache_read(info->cache_path, info->key, ref, &why);
        if (st == REFCACHE_HIT) {
            info->origin = REF_CACHE_HIT;
            info->seconds = timer_now_s() - t0;
            return ref;
        }
        if (st == REFCACHE_CORRUPT) {
            info->origin = REF_CACHE_CORRUPT_RECOMPUTED;
            snprintf(info->cache_note, sizeof info->cache_note, "%s; recomputed", why.msg);
        }
    }
    if (!compute_reference(a, ref, err)) {
        free(ref);
        return NULL;
    }
    info->seconds = timer_now_s() - t0;
    if (a->req->cache_dir) {
        Error werr;
        if (!refcache_write(a->req->cache_dir, info->cache_path, info->key, ref, &werr))
            snprintf(info->cache_note, sizeof info->cache_note, "not cached: %s", werr.msg);
    }
    return ref;
}

static size_t ref_bytes(const void *r)
{
    const Reference *ref = r;
    return 2 * sizeof(float) * image_count(&ref->value);
}
static void ref_destroy(void *r)
{
    reference_free(r);
    free(r);
}
static const ResourceKind kind_reference = {"reference", ref_bytes, ref_destroy, RES_EVALUATION};

const Reference *res_reference(ResourceManager *rm, const Scene *scene, const RefRequest *req, RefInfo *info,
                               Error *err)
{
    *info = (RefInfo){.origin = REF_REUSED};
    if (!reference_params_check(&req->params, err)) return NULL;
    info->key = reference_key(scene, req);
    RefArgs a = {rm, scene, req, info};
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %s, %d %s samples%s", req->light_index + 1,
             measure_name(req->params.measure), req->params.samples, sampling_pattern_name(req->params.pattern),
             req->params.shared_set ? " (one shared set)" : "");
    const Reference *ref = rm_acquire(rm, &kind_reference, info->key, desc, build_reference, &a, err);
    if (ref && info->origin != REF_REUSED) rm_log_note(rm, kind_reference.name, info->key, ref_origin_name(info->origin));
    return ref;
}
