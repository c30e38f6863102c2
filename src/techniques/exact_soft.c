/* exact_soft.c -- the exact soft-shadow techniques' shared light samples,
 * normalised light frame and caster culling (see exact_soft.h). */
#include "techniques/exact_soft.h"
#include <math.h>
#include <stdlib.h>
#include "core/counters.h"
#include "resources/silhouette.h"
#include "resources/standard.h"

const char *const exact_pattern_names[] = {"r2", "stratified", "random", NULL}; /* SamplingPattern order */

/* A sphere around corners [first, last): their box's centre, the farthest corner. */
static Ball bound_corners(const vec3 *p, int first, int last)
{
    vec3 lo = p[first], hi = lo;
    for (int k = first; k < last; k++) {
        lo = v3_min(lo, p[k]);
        hi = v3_max(hi, p[k]);
    }
    Ball b = {d3_scale(d3_add(d3_from(lo), d3_from(hi)), 0.5), 0.0};
    for (int k = first; k < last; k++) b.radius = fmax(b.radius, d3_len(d3_sub(d3_from(p[k]), b.centre)));
    b.radius *= 1.0 + 1e-6;
    return b;
}

static bool alloc_casters(ExactCasters *c, long tris, long chunks, int objects)
{
    c->tri = malloc(sizeof *c->tri * 3 * (size_t)(tris + 1));
    c->chunk_first = malloc(sizeof *c->chunk_first * (size_t)(chunks + 1));
    c->chunk_ball = malloc(sizeof *c->chunk_ball * (size_t)(chunks + 1));
    c->object_first = malloc(sizeof *c->object_first * (size_t)(objects + 1));
    c->object_ball = malloc(sizeof *c->object_ball * (size_t)(objects + 1));
    c->object_closed = calloc((size_t)objects + 1, sizeof *c->object_closed);
    return c->tri && c->chunk_first && c->chunk_ball && c->object_first && c->object_ball && c->object_closed;
}

static bool object_closed(const Silhouette *sil, int object)
{
    for (int i = 0; i < sil->num_objects; i++)
        if (sil->objects[i].object == object) return sil->objects[i].closed;
    return false;
}

static bool collect_casters(const Scene *scene, const Silhouette *sil, ExactCasters *c, Error *err)
{
    long n = 0, chunks = 0;
    int objects = 0;
    for (int i = 0; i < scene->num_objects; i++) {
        int t = scene->objects[i].mesh.num_triangles;
        if (!scene->objects[i].caster || t == 0) continue;
        n += t;
        chunks += (t + EXACT_CHUNK - 1) / EXACT_CHUNK;
        objects++;
    }
    if (n > INT32_MAX / 3) return error_set(err, "%ld caster triangles (at most %d)", n, INT32_MAX / 3);
    if (!alloc_casters(c, n, chunks, objects)) return error_set(err, "out of memory for %ld caster triangles", n);
    for (int i = 0; i < scene->num_objects; i++) {
        const Mesh *m = &scene->objects[i].mesh;
        if (!scene->objects[i].caster || m->num_triangles == 0) continue;
        int first = c->num_tris;
        c->object_first[c->num_objects] = c->num_chunks;
        for (int t = 0; t < m->num_triangles; t++, c->num_tris++) {
            if (t % EXACT_CHUNK == 0) c->chunk_first[c->num_chunks++] = c->num_tris;
            for (int k = 0; k < 3; k++) c->tri[3 * c->num_tris + k] = m->positions[m->indices[3 * t + k]];
        }
        c->object_closed[c->num_objects] = object_closed(sil, i);
        c->object_ball[c->num_objects++] = bound_corners(c->tri, 3 * first, 3 * c->num_tris);
    }
    c->chunk_first[c->num_chunks] = c->num_tris;
    c->object_first[c->num_objects] = c->num_chunks;
    for (int k = 0; k < c->num_chunks; k++)
        c->chunk_ball[k] = bound_corners(c->tri, 3 * c->chunk_first[k], 3 * c->chunk_first[k + 1]);
    return true;
}

void exact_casters_free(ExactCasters *c)
{
    free(c->tri);
    free(c->chunk_first);
    free(c->chunk_ball);
    free(c->object_first);
    free(c->object_ball);
    free(c->object_closed);
}

bool exact_casters_init(const TechContext *ctx, ExactCasters *c, Error *err)
{
    *c = (ExactCasters){0};
    if (!sampling_check_count((SamplingPattern)ctx->params[EXACT_P_PATTERN], (int)ctx->params[EXACT_P_SAMPLES], err))
        return false;
    const RtScene *bvh = res_bvh(ctx->rm, ctx->scene, RT_CASTERS, err);
    if (!bvh) return false;
    const Silhouette *sil = res_silhouette(ctx->rm, ctx->scene, ctx->light_index, err);
    if (!sil) return false;
    c->rtc = rt_scene_handle(bvh);
    c->extent = scene_extent(ctx->scene);
    if (collect_casters(ctx->scene, sil, c, err)) return true;
    exact_casters_free(c);
    return false;
}

/* Can ball b reach the cone from org around f->c of half-angle acos(cos_cone)?
 * The ball subtends asin(r / |m - org|) about m - org. */
static bool ball_in_cone(const Ball *b, const Frame *f, double cos_cone)
{
    dvec3 w = d3_sub(b->centre, f->org);
    double dist = d3_len(w);
    if (dist <= b->radius) return true;
    double axis = acos(fmax(-1.0, fmin(1.0, d3_dot(w, f->c) / dist)));
    return axis - asin(b->radius / dist) <= acos(fmax(-1.0, fmin(1.0, cos_cone))) + 1e-9;
}

/* Are org and the whole light (ball) strictly on one side of triangle t's
 * plane? Then their convex hull, which holds every segment toward a light
 * sample, misses it (a receiver's own ground under a light above it). */
static bool plane_separates(const vec3 *t, const Frame *f, const Ball *light)
{
    dvec3 a = d3_from(t[0]), n = d3_cross(d3_sub(d3_from(t[1]), a), d3_sub(d3_from(t[2]), a));
    double len = d3_len(n);
    if (!(len > 0.0)) return true; /* zero area: blocks nothing */
    double so = d3_dot(n, d3_sub(f->org, a)), sc = d3_dot(n, d3_sub(light->centre, a));
    return (so > 0.0 && sc > light->radius * len) || (so < 0.0 && sc < -light->radius * len);
}

static bool outside_closed(const ExactCasters *c, int o, const Frame *f)
{
    return c->object_closed[o] && d3_len(d3_sub(c->object_ball[o].centre, f->org)) > c->object_ball[o].radius;
}

/* Visits (fn) or finds (fn NULL) the triangles reaching the cone. */
static bool visit_casters(const ExactCasters *c, const Frame *f, const Ball *light, double cos_cone, ExactTriangleFn fn,
                          void *user)
{
    bool any = false;
    for (int o = 0; o < c->num_objects; o++) {
        if (!ball_in_cone(&c->object_ball[o], f, cos_cone)) continue;
        bool front_only = outside_closed(c, o, f);
        for (int k = c->object_first[o]; k < c->object_first[o + 1]; k++) {
            if (!ball_in_cone(&c->chunk_ball[k], f, cos_cone)) continue;
            for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++) {
                if (plane_separates(&c->tri[3 * t], f, light)) continue;
                if (!fn) return true;
                any = true;
                fn(user, &c->tri[3 * t], front_only);
            }
        }
    }
    return any;
}

void exact_for_casters(const ExactCasters *c, const LightPoints *lp, ExactTriangleFn fn, void *user)
{
    visit_casters(c, &lp->f, &lp->light, lp->cos_cone, fn, user);
}

bool exact_object_reaches(const ExactCasters *c, int o, const LightPoints *lp)
{
    return ball_in_cone(&c->object_ball[o], &lp->f, lp->cos_cone);
}

bool exact_front_faces_suffice(const ExactCasters *c, int o, const LightPoints *lp)
{
    return outside_closed(c, o, &lp->f);
}

bool exact_chunk_reaches(const ExactCasters *c, int k, const LightPoints *lp)
{
    return ball_in_cone(&c->chunk_ball[k], &lp->f, lp->cos_cone);
}

bool exact_triangle_reaches(const ExactCasters *c, int t, const LightPoints *lp)
{
    return !plane_separates(&c->tri[3 * t], &lp->f, &lp->light);
}

static Ball light_ball(const Light *l)
{
    double r = l->kind == LIGHT_RECT ? 0.5 * hypot(l->width, l->height) : l->radius;
    return (Ball){d3_from(l->position), r * (1.0 + 1e-6)};
}

bool exact_begin(const ExactCasters *c, const TechContext *ctx, int s, LightPoints *lp)
{
    vec3 p = ctx->vs->p_world[s];
    lp->org = v3_madd(p, ctx->vs->n_geom_world[s], rt_ray_offset(c->extent, p));
    LightSample centre = light_sample_center(ctx->light, p);
    Frame *f = &lp->f;
    *f = (Frame){d3_from(lp->org), d3(0, 0, 0), d3(0, 0, 0), d3_normalize_or(d3_from(centre.dir_world), d3(0, 0, 1))};
    dvec3 helper = fabs(f->c.x) < 0.6 ? d3(1, 0, 0) : d3(0, 1, 0);
    f->u = d3_normalize_or(d3_cross(helper, f->c), d3(1, 0, 0));
    f->v = d3_cross(f->c, f->u);
    lp->light = light_ball(ctx->light);
    double dist = d3_len(d3_sub(lp->light.centre, f->org)), r = lp->light.radius;
    double cos_light = dist <= r ? -1.0 : sqrt(1.0 - (r / dist) * (r / dist)); /* every light point is inside */
    return visit_casters(c, f, &lp->light, cos_light, NULL, NULL);
}

void exact_draw(LightPoints *lp, const TechContext *ctx, int s)
{
    vec3 p = ctx->vs->p_world[s], ng = ctx->vs->n_geom_world[s];
    SamplingPattern pat = (SamplingPattern)ctx->params[EXACT_P_PATTERN];
    uint32_t stream = sampling_stream((uint32_t)ctx->params[EXACT_P_SEED], (uint32_t)s);
    lp->n = (int)ctx->params[EXACT_P_SAMPLES];
    lp->kept = lp->off_axis = 0;
    lp->lo = (P2){INFINITY, INFINITY};
    lp->hi = (P2){-INFINITY, -INFINITY};
    lp->cos_cone = 1.0;
    for (int i = 0; i < lp->n; i++) {
        float u, v;
        sample_2d(pat, stream, i, lp->n, &u, &v);
        lp->ls[i] = light_sample(ctx->light, p, u, v);
        dvec3 d = d3_from(lp->ls[i].dir_world);
        bool horizon = v3_dot(ng, lp->ls[i].dir_world) > 0.0f; /* the reference's test (fill_batch) */
        lp->above[i] = horizon && d3_dot(d, lp->f.c) > 0.0;
        lp->off_axis += horizon && !lp->above[i];
        if (!lp->above[i]) continue;
        lp->kept++;
        lp->x[i] = exact_project(&lp->f, d);
        lp->cos_cone = fmin(lp->cos_cone, d3_dot(d, lp->f.c) / d3_len(d));
        lp->lo = (P2){fmin(lp->lo.x, lp->x[i].x), fmin(lp->lo.y, lp->x[i].y)};
        lp->hi = (P2){fmax(lp->hi.x, lp->x[i].x), fmax(lp->hi.y, lp->x[i].y)};
    }
}

bool exact_occluded(const ExactCasters *c, vec3 org, const LightSample *ls)
{
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    struct RTCRay ray = {.org_x = org.x, .org_y = org.y, .org_z = org.z, .tnear = 0.0f,
                         .dir_x = ls->dir_world.x, .dir_y = ls->dir_world.y, .dir_z = ls->dir_world.z,
                         .tfar = isinf(ls->dist) ? INFINITY : ls->dist * (1.0f - 1e-5f), .mask = 0xFFFFFFFFu};
    rt_occluded1(c->rtc, &ictx, &ray);
    return ray.tfar == -INFINITY;
}

float exact_sliver_visibility(const ExactCasters *c, const TechContext *ctx, int s, const LightPoints *lp)
{
    LightSample hi = light_sample_highest(ctx->light, ctx->vs->p_world[s], ctx->vs->n_geom_world[s]);
    return exact_occluded(c, lp->org, &hi) ? 0.0f : 1.0f;
}

int exact_clip(const Frame *f, const vec3 *t, dvec3 poly[4], int *facing)
{
    work_raster(1, 0); /* a triangle set up against the light frame (core/counters.h) */
    dvec3 q[3];
    double h[3];
    for (int k = 0; k < 3; k++) {
        q[k] = d3_sub(d3_from(t[k]), f->org);
        h[k] = d3_dot(q[k], f->c);
    }
    dvec3 n = d3_cross(d3_sub(q[1], q[0]), d3_sub(q[2], q[0]));
    double s = -d3_dot(n, q[0]); /* n . (org - corner) */
    *facing = s > 0.0 ? 1 : s < 0.0 ? -1 : 0;
    if (h[0] < EXACT_CLIP_EPS && h[1] < EXACT_CLIP_EPS && h[2] < EXACT_CLIP_EPS) return 0;
    int np = 0;
    for (int k = 0; k < 3; k++) {
        int j = (k + 1) % 3;
        bool in_k = h[k] >= EXACT_CLIP_EPS, in_j = h[j] >= EXACT_CLIP_EPS;
        if (in_k) poly[np++] = q[k];
        if (in_k != in_j) {
            int i = in_k ? k : j, o = in_k ? j : k;
            poly[np++] = d3_madd(q[i], d3_sub(q[o], q[i]), (h[i] - EXACT_CLIP_EPS) / (h[i] - h[o]));
        }
    }
    return np;
}
