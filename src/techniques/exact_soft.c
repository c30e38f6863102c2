/* exact_soft.c -- the exact soft-shadow techniques' shared light samples,
 * normalised light frame and caster culling (see exact_soft.h). */
#include "techniques/exact_soft.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "core/counters.h"
#include "resources/silhouette.h"
#include "resources/standard.h"

const char *const exact_pattern_names[] = {"r2", "stratified", "random", NULL}; /* SamplingPattern order */
const char *const exact_sample_set_names[] = {"per_view_sample", "shared", NULL};

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

static Ball light_ball(const Light *l)
{
    bool rect = l->kind == LIGHT_RECT || l->kind == LIGHT_TEXTURED_RECT;
    double r = rect ? 0.5 * hypot(l->width, l->height) : l->radius;
    return (Ball){d3_from(l->position), r * (1.0 + 1e-6)};
}

/* ---- edges: welded adjacency for the silhouette sums ------------------------- */

static uint32_t position_bits(float f)
{
    f += 0.0f; /* -0 -> +0: equal values give equal predicates */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static uint64_t corner_hash(vec3 p)
{
    uint64_t h = hash_u32(position_bits(p.x));
    h = h * 0x9E3779B97F4A7C15ull ^ hash_u32(position_bits(p.y));
    return h * 0x9E3779B97F4A7C15ull ^ hash_u32(position_bits(p.z));
}

static bool same_corner(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* A power of two at least twice n. */
static size_t table_size(size_t n)
{
    size_t s = 16;
    while (s < 2 * n) s *= 2;
    return s;
}

/* vertex[k] = the first corner with corner k's position (open addressing). */
static bool weld_corners(const vec3 *p, size_t n, int32_t *vertex)
{
    size_t size = table_size(n), mask = size - 1;
    int32_t *slot = malloc(size * sizeof *slot);
    if (!slot) return false;
    memset(slot, 0xff, size * sizeof *slot);
    for (size_t k = 0; k < n; k++) {
        size_t i = (size_t)corner_hash(p[k]) & mask;
        while (slot[i] >= 0 && !same_corner(p[slot[i]], p[k])) i = (i + 1) & mask;
        if (slot[i] < 0) slot[i] = (int32_t)k;
        vertex[k] = slot[i];
    }
    free(slot);
    return true;
}

/* edge[k]: one id per undirected welded edge (lo, hi) of corner k -> the
 * next corner of its triangle; returns the number of edges, -1 when out of
 * memory. */
static long number_edges(const vec3 *tri, size_t n, int32_t *edge)
{
    size_t size = table_size(n), mask = size - 1;
    int32_t *vertex = malloc(n * sizeof *vertex), *slot = malloc(size * sizeof *slot);
    uint64_t *key = malloc(n * sizeof *key); /* per edge id: lo << 32 | hi */
    long edges = vertex && slot && key && weld_corners(tri, n, vertex) ? 0 : -1;
    if (edges == 0) memset(slot, 0xff, size * sizeof *slot);
    for (size_t k = 0; edges >= 0 && k < n; k++) {
        uint32_t a = (uint32_t)vertex[k], b = (uint32_t)vertex[k - k % 3 + (k + 1) % 3];
        uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
        uint64_t kk = (uint64_t)lo << 32 | hi;
        size_t i = (size_t)(hash_u32(lo) * 0x9E3779B97F4A7C15ull ^ hash_u32(hi)) & mask;
        while (slot[i] >= 0 && key[slot[i]] != kk) i = (i + 1) & mask;
        if (slot[i] < 0) {
            slot[i] = (int32_t)edges;
            key[edges++] = kk;
        }
        edge[k] = slot[i];
    }
    free(vertex);
    free(slot);
    free(key);
    return edges;
}

/* Triangle t's normal (t1 - t0) x (t2 - t0) and the side of its plane the
 * whole ball lies on, strictly: LIGHT_FRONT (where the normal points),
 * LIGHT_BACK, LIGHT_CUT (the plane cuts the ball) or LIGHT_NONE (zero area:
 * the triangle blocks nothing). Both depend on the light alone, so
 * plane_separates is one dot product per org. */
enum { LIGHT_BACK = -1, LIGHT_CUT = 0, LIGHT_FRONT = 1, LIGHT_NONE = 2 };

static void plane_and_side(const vec3 *t, const Ball *ball, dvec3 *normal, int8_t *side)
{
    dvec3 a = d3_from(t[0]), n = d3_cross(d3_sub(d3_from(t[1]), a), d3_sub(d3_from(t[2]), a));
    double len = d3_len(n), sc = d3_dot(n, d3_sub(ball->centre, a));
    *normal = n;
    *side = !(len > 0.0) ? LIGHT_NONE : sc > ball->radius * len ? LIGHT_FRONT : sc < -ball->radius * len ? LIGHT_BACK : LIGHT_CUT;
}

/* Can edge e be a silhouette from a point of the ball? Not when it has two
 * triangles that traverse it in opposite directions (corner k -> k + 1) and
 * both see the ball strictly on the same side. */
static bool possible_silhouette(const ExactCasters *c, const int *side, int n)
{
    const int8_t *ball = c->tri_light_side;
    if (n != 2) return true; /* open or non-manifold */
    int t0 = side[0] / 3, t1 = side[1] / 3;
    const vec3 *p = c->tri;
    vec3 a0 = p[side[0]], a1 = p[side[1]]; /* each side's first corner: the other's second when opposite */
    bool opposite = a0.x != a1.x || a0.y != a1.y || a0.z != a1.z;
    return !opposite || (ball[t0] != LIGHT_FRONT && ball[t0] != LIGHT_BACK) || ball[t0] != ball[t1];
}

/* An edge's entry under a chunk: its side count, its sphere in edge_ball,
 * then each side 3 t + k and t's chunk; returns the ints it takes (written
 * only when out is not NULL). */
static long list_entry(const ExactCasters *c, const int *side, int ns, int ball, int *out)
{
    if (out) {
        out[0] = ns;
        out[1] = ball;
        for (int i = 0; i < ns; i++) {
            out[2 + 2 * i] = side[i];
            out[3 + 2 * i] = c->tri_chunk[side[i] / 3];
        }
    }
    return 2 + 2 * (long)ns;
}

/* The sphere around side 3 t + k's edge (corner k -> k + 1 of t). */
static Ball bound_edge(const ExactCasters *c, int side)
{
    dvec3 a = d3_from(c->tri[side]), b = d3_from(c->tri[side - side % 3 + (side + 1) % 3]);
    return (Ball){d3_scale(d3_add(a, b), 0.5), 0.5 * d3_len(d3_sub(b, a)) * (1.0 + 1e-6)};
}

/* The sides of every edge (counting sort by edge id), then each possible
 * silhouette edge's entry under each distinct chunk of its sides, entries of
 * one chunk consecutive, so stage two streams through them. */
static bool list_edges(ExactCasters *c, const int32_t *edge)
{
    size_t n = 3 * (size_t)c->num_tris;
    int *first = calloc((size_t)c->num_edges + 2, sizeof *first), *side = malloc(sizeof *side * (n + 1));
    long *fill = calloc((size_t)c->num_chunks + 1, sizeof *fill);
    c->chunk_edges = calloc((size_t)c->num_chunks + 1, sizeof *c->chunk_edges);
    bool ok = first && side && fill && c->chunk_edges;
    for (size_t k = 0; ok && k < n; k++) first[edge[k] + 2]++;
    for (int e = 0; ok && e < c->num_edges; e++) first[e + 2] += first[e + 1];
    for (size_t k = 0; ok && k < n; k++) side[first[edge[k] + 1]++] = (int)k; /* first[e] .. first[e + 1]: e's */
    for (int pass = 0; ok && pass < 2; pass++) {
        int balls = 0;
        for (int e = 0; e < c->num_edges; e++) {
            const int *se = &side[first[e]];
            int ns = first[e + 1] - first[e];
            if (!possible_silhouette(c, se, ns)) continue;
            if (pass) c->edge_ball[balls] = bound_edge(c, se[0]);
            balls++;
            for (int i = 0; i < ns; i++) {
                int k = c->tri_chunk[se[i] / 3];
                bool seen = false;
                for (int j = 0; j < i; j++) seen |= c->tri_chunk[se[j] / 3] == k;
                if (seen) continue;
                int *out = pass ? &c->listing[c->chunk_edges[k] + fill[k]] : NULL;
                long size = list_entry(c, se, ns, balls - 1, out);
                if (pass) fill[k] += size;
                else c->chunk_edges[k + 1] += size;
            }
        }
        if (pass == 0) {
            for (int k = 0; k < c->num_chunks; k++) c->chunk_edges[k + 1] += c->chunk_edges[k];
            c->listing = malloc(sizeof *c->listing * (size_t)(c->chunk_edges[c->num_chunks] + 1));
            c->edge_ball = malloc(sizeof *c->edge_ball * (size_t)(balls + 1));
            ok = c->listing && c->edge_ball;
        }
    }
    free(first);
    free(side);
    free(fill);
    return ok;
}

/* The triangles' planes, and the possible silhouette edges if wanted. */
static bool build_edges(ExactCasters *c, const Ball *light, bool edges_wanted)
{
    size_t n = 3 * (size_t)c->num_tris;
    for (int t = 0; t < c->num_tris; t++) plane_and_side(&c->tri[3 * t], light, &c->tri_normal[t], &c->tri_light_side[t]);
    if (!edges_wanted) return true;
    int32_t *edge = malloc(sizeof *edge * (n + 1));
    long edges = edge ? number_edges(c->tri, n, edge) : -1;
    c->num_edges = (int)edges;
    bool ok = edges >= 0 && list_edges(c, edge);
    free(edge);
    return ok;
}

static bool alloc_casters(ExactCasters *c, long tris, long chunks, int objects)
{
    c->tri = malloc(sizeof *c->tri * 3 * (size_t)(tris + 1));
    c->chunk_first = malloc(sizeof *c->chunk_first * (size_t)(chunks + 1));
    c->chunk_ball = malloc(sizeof *c->chunk_ball * (size_t)(chunks + 1));
    c->object_first = malloc(sizeof *c->object_first * (size_t)(objects + 1));
    c->object_ball = malloc(sizeof *c->object_ball * (size_t)(objects + 1));
    c->object_closed = calloc((size_t)objects + 1, sizeof *c->object_closed);
    c->tri_chunk = malloc(sizeof *c->tri_chunk * (size_t)(tris + 1));
    c->chunk_object = malloc(sizeof *c->chunk_object * (size_t)(chunks + 1));
    c->tri_normal = malloc(sizeof *c->tri_normal * (size_t)(tris + 1));
    c->tri_light_side = malloc((size_t)(tris + 1));
    return c->tri && c->chunk_first && c->chunk_ball && c->object_first && c->object_ball && c->object_closed &&
           c->tri_chunk && c->chunk_object && c->tri_normal && c->tri_light_side;
}

static bool object_closed(const Silhouette *sil, int object)
{
    for (int i = 0; i < sil->num_objects; i++)
        if (sil->objects[i].object == object) return sil->objects[i].closed;
    return false;
}

static bool collect_casters(const Scene *scene, const Silhouette *sil, const Ball *light, bool edges, ExactCasters *c,
                            Error *err)
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
            if (t % EXACT_CHUNK == 0) {
                c->chunk_object[c->num_chunks] = c->num_objects;
                c->chunk_first[c->num_chunks++] = c->num_tris;
            }
            c->tri_chunk[c->num_tris] = c->num_chunks - 1;
            for (int k = 0; k < 3; k++) c->tri[3 * c->num_tris + k] = m->positions[m->indices[3 * t + k]];
        }
        c->object_closed[c->num_objects] = object_closed(sil, i);
        c->object_ball[c->num_objects++] = bound_corners(c->tri, 3 * first, 3 * c->num_tris);
    }
    c->chunk_first[c->num_chunks] = c->num_tris;
    c->object_first[c->num_objects] = c->num_chunks;
    for (int k = 0; k < c->num_chunks; k++)
        c->chunk_ball[k] = bound_corners(c->tri, 3 * c->chunk_first[k], 3 * c->chunk_first[k + 1]);
    return build_edges(c, light, edges) || error_set(err, "out of memory for the edges of %ld caster triangles", n);
}

void exact_casters_free(ExactCasters *c)
{
    free(c->tri_chunk);
    free(c->tri_normal);
    free(c->tri_light_side);
    free(c->chunk_object);
    free(c->chunk_edges);
    free(c->listing);
    free(c->edge_ball);
    free(c->tri);
    free(c->chunk_first);
    free(c->chunk_ball);
    free(c->object_first);
    free(c->object_ball);
    free(c->object_closed);
}

bool exact_casters_init(const TechContext *ctx, bool edges, ExactCasters *c, Error *err)
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
    Ball light = light_ball(ctx->light);
    if (collect_casters(ctx->scene, sil, &light, edges, c, err)) return true;
    exact_casters_free(c);
    return false;
}

Cone exact_cone(double cos_cone, double margin)
{
    double t = fmin(acos(fmax(-1.0, fmin(1.0, cos_cone))) + margin, M_PI);
    return (Cone){cos(t), sin(t)};
}

/* Can ball b reach the cone from org about f->c? The angle between b's
 * centre and c at most the half-angle t plus the ball's angular radius
 * p = asin(r / |w|): cos(angle) >= cos(t + p), by the sum formula, unless
 * t + p passes pi (sin(t + p) < 0), where every direction is in. */
static bool ball_in_cone(const Ball *b, const Frame *f, const Cone *cone)
{
    dvec3 w = d3_sub(b->centre, f->org);
    double d2 = d3_dot(w, w);
    if (d2 <= b->radius * b->radius) return true;
    double d = sqrt(d2), sin_p = b->radius / d, cos_p = sqrt(1.0 - sin_p * sin_p);
    if (cone->sin_t * cos_p + cone->cos_t * sin_p < 0.0) return true;
    return d3_dot(w, f->c) >= d * (cone->cos_t * cos_p - cone->sin_t * sin_p);
}

/* Are org and the whole light (ball) strictly on one side of triangle t's
 * plane? Then their convex hull, which holds every segment toward a light
 * sample, misses it (a receiver's own ground under a light above it). */
static bool plane_separates(const ExactCasters *c, int t, const Frame *f)
{
    int side = c->tri_light_side[t];
    if (side == LIGHT_NONE) return true; /* zero area: blocks nothing */
    double so = d3_dot(c->tri_normal[t], d3_sub(f->org, d3_from(c->tri[3 * t])));
    return (so > 0.0 && side == LIGHT_FRONT) || (so < 0.0 && side == LIGHT_BACK);
}

static bool outside_closed(const ExactCasters *c, int o, const Frame *f)
{
    return c->object_closed[o] && d3_len(d3_sub(c->object_ball[o].centre, f->org)) > c->object_ball[o].radius;
}

/* Visits (fn) or finds (fn NULL) the triangles reaching the cone. */
static bool visit_casters(const ExactCasters *c, const Frame *f, const Cone *cone, ExactTriangleFn fn,
                          void *user)
{
    bool any = false;
    for (int o = 0; o < c->num_objects; o++) {
        if (!ball_in_cone(&c->object_ball[o], f, cone)) continue;
        bool front_only = outside_closed(c, o, f);
        for (int k = c->object_first[o]; k < c->object_first[o + 1]; k++) {
            if (!ball_in_cone(&c->chunk_ball[k], f, cone)) continue;
            for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++) {
                if (plane_separates(c, t, f)) continue;
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
    visit_casters(c, &lp->f, &lp->cone, fn, user);
}

bool exact_object_reaches(const ExactCasters *c, int o, const LightPoints *lp)
{
    return ball_in_cone(&c->object_ball[o], &lp->f, &lp->cone);
}

bool exact_front_faces_suffice(const ExactCasters *c, int o, const LightPoints *lp)
{
    return outside_closed(c, o, &lp->f);
}

bool exact_chunk_reaches(const ExactCasters *c, int k, const LightPoints *lp)
{
    return ball_in_cone(&c->chunk_ball[k], &lp->f, &lp->cone);
}

bool exact_triangle_reaches(const ExactCasters *c, int t, const LightPoints *lp)
{
    return !plane_separates(c, t, &lp->f);
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
    Cone cone = exact_cone(cos_light, EXACT_CONE_MARGIN);
    return visit_casters(c, f, &cone, NULL, NULL);
}

void exact_draw(LightPoints *lp, const TechContext *ctx, int s)
{
    vec3 p = ctx->vs->p_world[s], ng = ctx->vs->n_geom_world[s];
    SamplingPattern pat = (SamplingPattern)ctx->params[EXACT_P_PATTERN];
    uint32_t stream = sampling_set_stream((uint32_t)ctx->params[EXACT_P_SEED],
                                          ctx->params[EXACT_P_SAMPLE_SET] == EXACT_SET_SHARED, (uint32_t)s);
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
    lp->cone = exact_cone(lp->cos_cone, EXACT_CONE_MARGIN);
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

/* Corners relative to org, their heights h along c, and the facing from
 * org: the sign of n . (org - corner 0). */
static int relative_corners(const Frame *f, const vec3 *t, dvec3 q[3], double h[3])
{
    work_raster(1, 0); /* a triangle set up against the light frame (core/counters.h) */
    for (int k = 0; k < 3; k++) {
        q[k] = d3_sub(d3_from(t[k]), f->org);
        h[k] = d3_dot(q[k], f->c);
    }
    dvec3 n = d3_cross(d3_sub(q[1], q[0]), d3_sub(q[2], q[0]));
    double s = -d3_dot(n, q[0]);
    return s > 0.0 ? 1 : s < 0.0 ? -1 : 0;
}

/* Where edge qi -> qo crosses the clip plane d.c = EXACT_CLIP_EPS, from its
 * inside corner qi (so both triangles of the edge get the same point). */
static dvec3 clip_crossing(dvec3 qi, dvec3 qo, double hi, double ho)
{
    return d3_madd(qi, d3_sub(qo, qi), (hi - EXACT_CLIP_EPS) / (hi - ho));
}

int exact_clip(const Frame *f, const vec3 *t, dvec3 poly[4], int *facing, int edge_of[4])
{
    dvec3 q[3];
    double h[3];
    *facing = relative_corners(f, t, q, h);
    if (h[0] < EXACT_CLIP_EPS && h[1] < EXACT_CLIP_EPS && h[2] < EXACT_CLIP_EPS) return 0;
    int np = 0;
    for (int k = 0; k < 3; k++) {
        int j = (k + 1) % 3;
        bool in_k = h[k] >= EXACT_CLIP_EPS, in_j = h[j] >= EXACT_CLIP_EPS;
        if (in_k) {
            if (edge_of) edge_of[np] = k; /* q[k] -> the next corner lies on edge k */
            poly[np++] = q[k];
        }
        if (in_k != in_j) {
            int i = in_k ? k : j, o = in_k ? j : k;
            if (edge_of) edge_of[np] = in_k ? -1 : k; /* leaving: along the clip plane; entering: on to q[j] */
            poly[np++] = clip_crossing(q[i], q[o], h[i], h[o]);
        }
    }
    return np;
}

/* ---- silhouette edges from org (exact_soft.h) ----------------------------------- */

/* The part of triangle t's edge k (corner k -> k + 1) in front of the clip
 * plane, as exact_clip cuts it; false when none is. */
static bool clipped_edge(const dvec3 q[3], const double h[3], int k, dvec3 *a, dvec3 *b)
{
    int j = (k + 1) % 3;
    bool in_k = h[k] >= EXACT_CLIP_EPS, in_j = h[j] >= EXACT_CLIP_EPS;
    if (!in_k && !in_j) return false;
    *a = in_k ? q[k] : clip_crossing(q[j], q[k], h[j], h[k]);
    *b = in_j ? q[j] : clip_crossing(q[k], q[j], h[k], h[j]);
    return true;
}

/* reached[k] for each chunk (and reached[num_chunks + o] = front_only + 1
 * for each object reaching the cone, 0 otherwise): visit_casters's culls. */
static void mark_reached(const ExactCasters *c, const LightPoints *lp, uint8_t *reached)
{
    uint8_t *object = reached + c->num_chunks;
    for (int o = 0; o < c->num_objects; o++) {
        bool in = ball_in_cone(&c->object_ball[o], &lp->f, &lp->cone);
        object[o] = in ? (uint8_t)(1 + outside_closed(c, o, &lp->f)) : 0;
        for (int k = c->object_first[o]; k < c->object_first[o + 1]; k++)
            reached[k] = in && ball_in_cone(&c->chunk_ball[k], &lp->f, &lp->cone);
    }
}

/* Triangle t's weight from org as visit_casters and the per-triangle edges
 * count it: 0 when culled (chunk, plane), edge-on, or a back face where
 * front faces suffice; else its facing. Cached per org in scratch. */
static int triangle_weight(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, int t, int k)
{
    if (sc->stamp[t] == sc->org) return sc->weight[t];
    int w = 0;
    if (sc->reached[k] && !plane_separates(c, t, &lp->f)) {
        dvec3 q[3];
        double h[3];
        w = relative_corners(&lp->f, &c->tri[3 * t], q, h);
        if (w < 0 && sc->reached[c->num_chunks + c->chunk_object[k]] == 2) w = 0; /* front_only */
    }
    sc->stamp[t] = sc->org;
    sc->weight[t] = (int8_t)w;
    return w;
}

/* The samples' cone widened by EDGE_CONE_MARGIN radians, for the edges'
 * spheres: an edge outside it crosses no segment between two kept samples'
 * projections (they lie in the cone, which is convex) and is farther than
 * EXACT_AMBIGUOUS_TAN from every sample, so leaving it out changes neither
 * the counts nor near_edge. */
#define EDGE_CONE_MARGIN 1e-4

/* One entry's edge summed over its sides, if `chunk`, the chunk it is
 * listed under, is the first reached chunk of its sides and its sphere
 * reaches the cone; returns the entry's size. */
static int sum_edge(const ExactCasters *c, const LightPoints *lp, const Cone *cone, ExactScratch *sc,
                    const int *entry, int chunk, ExactEdgeFn fn, void *user)
{
    int ns = entry[0], weight = 0, size = 2 + 2 * ns;
    const int *side = entry + 2;
    for (int i = 0; i < ns; i++)
        if (side[2 * i + 1] < chunk && sc->reached[side[2 * i + 1]]) return size; /* summed there */
    if (!ball_in_cone(&c->edge_ball[entry[1]], &lp->f, cone)) return size;
    dvec3 a = {0}, b = {0};
    for (int i = 0; i < ns; i++) {
        int t = side[2 * i] / 3, w = triangle_weight(c, lp, sc, t, side[2 * i + 1]);
        if (w == 0) continue;
        dvec3 q[3];
        double h[3];
        for (int j = 0; j < 3; j++) { /* exact_clip's corners */
            q[j] = d3_sub(d3_from(c->tri[3 * t + j]), lp->f.org);
            h[j] = d3_dot(q[j], lp->f.c);
        }
        if (!clipped_edge(q, h, side[2 * i] % 3, &a, &b)) continue;
        weight += exact_canonical(&a, &b) ? -w : w;
    }
    if (weight != 0) fn(user, a, b, weight);
    return size;
}

/* Does triangle t cross the clip plane (corners on both sides)? */
static bool crosses_clip_plane(const vec3 *t, const Frame *f)
{
    int in = 0;
    for (int k = 0; k < 3; k++) in += d3_dot(d3_sub(d3_from(t[k]), f->org), f->c) >= EXACT_CLIP_EPS;
    return in == 1 || in == 2;
}

/* The edges along the clip plane of chunk k's visited triangles that cross
 * it, if its sphere comes near org: the plane h = EXACT_CLIP_EPS meets the
 * widened cone (half-angle t < pi/2) within EXACT_CLIP_EPS / cos t of org,
 * so a clip edge farther away is outside it (as an edge's sphere, above). */
static void clip_plane_edges(const ExactCasters *c, const LightPoints *lp, const Cone *cone, ExactScratch *sc, int k,
                             ExactEdgeFn fn, void *user)
{
    const Ball *ball = &c->chunk_ball[k];
    double reach = cone->cos_t > 0.0 ? 2.0 * EXACT_CLIP_EPS / cone->cos_t + 1e-12 : INFINITY;
    if (d3_len(d3_sub(ball->centre, lp->f.org)) - ball->radius > reach) return;
    for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++) {
        if (!crosses_clip_plane(&c->tri[3 * t], &lp->f)) continue;
        int w = triangle_weight(c, lp, sc, t, k);
        if (w == 0) continue;
        dvec3 poly[4];
        int facing, edge_of[4], np = exact_clip(&lp->f, &c->tri[3 * t], poly, &facing, edge_of);
        for (int e = 0; e < np; e++)
            if (edge_of[e] < 0) fn(user, poly[e], poly[(e + 1) % np], w);
    }
}

bool exact_scratch_init(ExactScratch *sc, const ExactCasters *c)
{
    *sc = (ExactScratch){.reached = malloc((size_t)c->num_chunks + (size_t)c->num_objects + 1),
                         .stamp = calloc((size_t)c->num_tris + 1, sizeof *sc->stamp),
                         .weight = malloc((size_t)c->num_tris + 1)};
    return sc->reached && sc->stamp && sc->weight;
}

void exact_scratch_free(ExactScratch *sc)
{
    free(sc->reached);
    free(sc->stamp);
    free(sc->weight);
}

void exact_for_silhouette(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, ExactEdgeFn fn, void *user)
{
    if (++sc->org == 0) { /* stamps wrapped: every cached weight is stale */
        memset(sc->stamp, 0, sizeof *sc->stamp * (size_t)(c->num_tris + 1));
        sc->org = 1;
    }
    mark_reached(c, lp, sc->reached);
    Cone cone = exact_cone(lp->cos_cone, EDGE_CONE_MARGIN);
    for (int k = 0; k < c->num_chunks; k++) {
        if (!sc->reached[k]) continue;
        for (long i = c->chunk_edges[k]; i < c->chunk_edges[k + 1];)
            i += sum_edge(c, lp, &cone, sc, &c->listing[i], k, fn, user);
        clip_plane_edges(c, lp, &cone, sc, k, fn, user);
    }
}
