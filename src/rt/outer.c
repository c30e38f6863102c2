/* outer.c -- seed 002's outer objects (see outer.h). The occluders sit in a
 * binary BVH built by Embree's rtcBuildBVH, each node holding a ball around
 * each child. A ray walks it nearest first: a ball bounds from below the tau
 * of everything inside it, so with min (the paper's combination) the walk
 * drops whatever cannot beat the best tau so far, and with product or sum
 * whatever has tau >= 1. The appendix's alternative, Embree user geometry
 * with every bound grown by the largest b ("R + b_max"), makes each ray near
 * a 69k-triangle bunny visit nearly every triangle: one 480x360 bunny image
 * ran over 8 minutes (stopped) against 0.3-1.3 s with this walk. */
#include "rt/outer.h"
#include <embree3/rtcore_builder.h>
#include <math.h>
#include <stdlib.h>

#define PI_F 3.14159265358979323846f
#define MAX_DEPTH 48 /* Embree's builder fails past it; the walk's stack holds one entry per level */
#define MAX_LEAF 8

typedef struct Ball {
    vec3 c;
    float r;
} Ball;

/* An occluder: a triangle p[0..2] (normal n = (p1 - p0) x (p2 - p0)) with a
 * ball around it, or an analytic sphere, which is its own ball. */
typedef struct OuterPrim {
    vec3 p[3], n;
    Ball ball;
    bool is_sphere;
} OuterPrim;

typedef struct BvhNode {
    bool leaf;
    unsigned count;                 /* leaf: primitives in prim[] */
    Ball ball[2];                   /* inner: around each child */
    const struct BvhNode *child[2]; /* inner */
    unsigned prim[];                /* leaf: indices into OuterScene.prims */
} BvhNode;

struct OuterScene {
    RTCBVH bvh; /* owns the nodes */
    const BvhNode *root;
    Ball root_ball;
    OuterPrim *prims;
    int num_prims, num_spheres, num_triangles;
    size_t bytes;
};

/* ---- the per-object formulas ------------------------------------------- */

/* [OWN] For a rectangle, its mean width over edge directions, perimeter / pi
 * (Cauchy's formula), since a straight occluder edge's true penumbra is as
 * wide as the light across it; for a disk this is its diameter. */
float outer_light_diameter(const Light *l)
{
    if (l->kind == LIGHT_RECT) return 2.0f * (l->width + l->height) / 3.14159265358979323846f;
    return 2.0f * l->radius;
}

/* Without -ffast-math fminf/fmaxf are library calls; these inline (NaN -> lo). */
static inline float min_f(float a, float b) { return a < b ? a : b; }
static inline float clamp01(float x) { return x > 0.0f ? min_f(x, 1.0f) : 0.0f; }

float outer_falloff(float tau, OuterFalloff falloff)
{
    float t = clamp01(tau);
    float s = falloff == OUTER_SINUSOID ? 0.5f * (1.0f + sinf(PI_F * t - 0.5f * PI_F)) /* seed 002 §3 */
                                        : t * t * (3.0f - 2.0f * t);                    /* 3t^2 - 2t^3 */
    return clamp01(s);
}

float outer_combine(float a, float b, OuterCombine combine)
{
    switch (combine) {
    case OUTER_PRODUCT: return a * b;
    case OUTER_SUM: return a + b > 1.0f ? a + b - 1.0f : 0.0f; /* 1 - ((1 - a) + (1 - b)), clamped */
    default: return min_f(a, b);
    }
}

/* Seed 002 appendix: t0 = (c - o) . v, s = 1 when t0 < 0; b = D t0 / ||l - o||;
 * d = ||t0 v - c + o||; s = 0 for d < R, tau = (d - R) / b for R <= d < R + b,
 * s = 1 beyond. The appendix leaves out a sphere whose closest approach lies
 * beyond the light (t0 >= ||l - o||): it casts nothing here (a ray that truly
 * crosses it meets the inner objects). With 0 < t0 < ||l - o||, b < D, and
 * d < R + b implies b > 0. */
float outer_sphere_tau(vec3 c_world, float radius, const OuterRay *r)
{
    vec3 oc = v3_sub(c_world, r->org_world);
    float t0 = v3_dot(oc, r->dir_world);
    if (!(t0 > 0.0f) || !(t0 < r->light_dist)) return INFINITY;
    float d = v3_len(v3_madd(oc, r->dir_world, -t0));
    if (d < radius) return 0.0f;
    float b = r->light_diameter * parker_ratio(t0, r->light_dist);
    return d < radius + b ? (d - radius) / b : INFINITY;
}

/* Closest approach of the line o + t v (v unit, t unbounded) to the segment
 * a + u e, u in [0, 1]: minimising |w + u e|^2 - ((w + u e) . v)^2 with
 * w = a - o gives u = (ve vw - ew) / (ee - ve^2), clamped (the objective is a
 * convex quadratic in u); ee - ve^2 = |e x v|^2 is 0 only for an edge parallel
 * to the ray or of zero length, where any u serves. */
static void line_segment_approach(vec3 o, vec3 v, vec3 a, vec3 e, float *t, float *d)
{
    vec3 w = v3_sub(a, o);
    float ve = v3_dot(v, e), ee = v3_dot(e, e), vw = v3_dot(v, w), ew = v3_dot(e, w);
    float denom = ee - ve * ve;
    float u = denom > 0.0f ? (ve * vw - ew) / denom : 0.0f;
    vec3 q = v3_madd(w, e, clamp01(u)); /* nearest segment point, relative to o */
    *t = v3_dot(q, v);
    *d = v3_len(v3_madd(q, v, -*t));
}

/* Is q (in the triangle's plane) inside it? Same side of every edge as n. */
static bool inside_triangle(const vec3 a[3], const vec3 e[3], vec3 n, vec3 q)
{
    for (int k = 0; k < 3; k++)
        if (v3_dot(n, v3_cross(e[k], v3_sub(q, a[k]))) < 0.0f) return false;
    return true;
}

/* Where the ray crosses the triangle's plane, if it does between o and l
 * (else +inf); the test before the one division rejects most triangles. */
static float plane_crossing(const vec3 p[3], vec3 n, const OuterRay *r)
{
    float den = v3_dot(r->dir_world, n), num = v3_dot(v3_sub(p[0], r->org_world), n);
    /* 0 < num / den < L, and den = 0 (parallel, or a degenerate triangle) fails */
    if (!(num * den > 0.0f) || !(fabsf(num) < r->light_dist * fabsf(den))) return INFINITY;
    return num / den;
}

static float triangle_tau_at(const vec3 p[3], vec3 n, float t_plane, const OuterRay *r)
{
    const vec3 *a = p, e[3] = {v3_sub(p[1], p[0]), v3_sub(p[2], p[1]), v3_sub(p[0], p[2])};
    if (inside_triangle(a, e, n, v3_madd(r->org_world, r->dir_world, t_plane))) return 0.0f;
    float tau = INFINITY;
    for (int k = 0; k < 3; k++) {
        float t, d;
        line_segment_approach(r->org_world, r->dir_world, a[k], e[k], &t, &d);
        if (!(t > 0.0f) || !(t < r->light_dist)) continue;
        float b = r->light_diameter * parker_ratio(t, r->light_dist);
        if (d < b) tau = min_f(tau, d / b);
    }
    return tau;
}

/* Seed 002 appendix, triangles: "the outer object is a triangle with rounded
 * corners; the offset is different for each side". [OWN] The outer triangle
 * is planar, so the ray must cross the triangle's plane between o and l;
 * crossing inside the triangle, it meets the inner object (tau = 0). Else it
 * passes the triangle at the ray-to-edge distance d_e, reached at t_e along
 * the ray (the analogue of the sphere's t0, and likewise kept to
 * 0 < t_e < ||l - o||), so tau = d_e / b_e with b_e = D t_e / ||l - o||, the
 * smallest over the edges. In the plane this is a strip of half-width
 * b_e / cos_e beside each edge, cos_e being the cosine between the normal and
 * v projected across the edge, with elliptic corners: the rounded triangle. */
float outer_triangle_tau(vec3 p0, vec3 p1, vec3 p2, const OuterRay *r)
{
    const vec3 p[3] = {p0, p1, p2};
    vec3 n = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
    float t_plane = plane_crossing(p, n, r);
    return t_plane < INFINITY ? triangle_tau_at(p, n, t_plane, r) : INFINITY;
}

/* A lower bound on the tau of anything in the ball, or +inf once it cannot
 * be below `cut`: such a point has t <= t_c + r (and t < ||l - o|| to count),
 * so b <= b_max = min(k (t_c + r), D) with k = D / ||l - o||, and lies at
 * least |c - line| - r from the ray. The cut is tested on squares first, so
 * a ball out of reach costs no root or division. */
static float ball_tau_bound(const Ball *ball, const OuterRay *r, float k, float cut)
{
    vec3 w = v3_sub(ball->c, r->org_world);
    float t_c = v3_dot(w, r->dir_world);
    if (!(t_c + ball->r > 0.0f) || !(t_c - ball->r < r->light_dist)) return INFINITY;
    float b_max = min_f(k * (t_c + ball->r), r->light_diameter);
    vec3 perp = v3_madd(w, r->dir_world, -t_c);
    float d2 = v3_dot(perp, perp), reach = ball->r + cut * b_max;
    if (!(d2 < reach * reach)) return INFINITY;
    float gap = sqrtf(d2) - ball->r;
    return gap > 0.0f && b_max > 0.0f ? gap / b_max : 0.0f;
}

/* ---- the walk -------------------------------------------------------------- */

typedef struct Walk {
    const OuterRay *ray;
    float k;       /* D / ||l - o|| */
    float tau_min; /* min: the best tau so far */
    float s;       /* product, sum: the combined attenuation so far */
} Walk;

/* Nothing whose tau bound reaches this can change the result. */
static float walk_cutoff(const Walk *w) { return w->ray->combine == OUTER_MIN ? min_f(w->tau_min, 1.0f) : 1.0f; }

/* Fold one occluder in; true once the result is 0 (nothing can lighten it). */
static bool walk_prim(Walk *w, const OuterPrim *p)
{
    float tau;
    if (p->is_sphere) {
        tau = outer_sphere_tau(p->ball.c, p->ball.r, w->ray);
    } else {
        float t_plane = plane_crossing(p->p, p->n, w->ray), cut = walk_cutoff(w);
        if (!(t_plane < INFINITY) || !(ball_tau_bound(&p->ball, w->ray, w->k, cut) < cut)) return false;
        tau = triangle_tau_at(p->p, p->n, t_plane, w->ray);
    }
    if (!(tau < 1.0f)) return false;
    if (w->ray->combine == OUTER_MIN) {
        w->tau_min = min_f(w->tau_min, tau);
        return w->tau_min <= 0.0f;
    }
    w->s = outer_combine(w->s, outer_falloff(tau, w->ray->falloff), w->ray->combine);
    return w->s <= 0.0f;
}

static float walk_result(const Walk *w)
{
    return w->ray->combine == OUTER_MIN ? outer_falloff(w->tau_min, w->ray->falloff) : w->s;
}

typedef struct StackEntry {
    const BvhNode *node;
    float bound;
} StackEntry;

float outer_scene_attenuation(const OuterScene *os, const OuterRay *ray)
{
    if (!os->root || !(ray->light_dist > 0.0f) || !(ray->light_diameter > 0.0f)) return 1.0f;
    Walk w = {ray, ray->light_diameter / ray->light_dist, INFINITY, 1.0f};
    StackEntry stack[MAX_DEPTH + 2];
    int sp = 0;
    const BvhNode *node = ball_tau_bound(&os->root_ball, ray, w.k, 1.0f) < 1.0f ? os->root : NULL;
    while (node) {
        if (node->leaf) {
            for (unsigned i = 0; i < node->count; i++)
                if (walk_prim(&w, &os->prims[node->prim[i]])) return 0.0f;
            node = NULL;
        } else {
            float cut = walk_cutoff(&w), bound[2];
            for (int c = 0; c < 2; c++)
                bound[c] = node->child[c] ? ball_tau_bound(&node->ball[c], ray, w.k, cut) : INFINITY;
            int near = bound[1] < bound[0], far = 1 - near;
            if (bound[far] < cut) stack[sp++] = (StackEntry){node->child[far], bound[far]};
            node = bound[near] < cut ? node->child[near] : NULL;
        }
        while (!node && sp > 0) {
            StackEntry e = stack[--sp];
            if (e.bound < walk_cutoff(&w)) node = e.node;
        }
    }
    return walk_result(&w);
}

/* ---- the build ------------------------------------------------------------- */

static void *create_node(RTCThreadLocalAllocator alloc, unsigned child_count, void *user)
{
    (void)child_count, (void)user;
    BvhNode *n = rtcThreadLocalAlloc(alloc, sizeof *n, 16);
    if (n) *n = (BvhNode){.leaf = false};
    return n;
}

static void set_children(void *node, void **children, unsigned count, void *user)
{
    (void)user;
    BvhNode *n = node;
    for (unsigned c = 0; c < 2; c++) n->child[c] = c < count ? children[c] : NULL;
}

static Ball ball_around(vec3 lo, vec3 hi)
{
    return (Ball){v3_scale(v3_add(lo, hi), 0.5f), 0.5f * v3_len(v3_sub(hi, lo)) * (1.0f + 1e-5f)};
}

static void set_bounds(void *node, const struct RTCBounds **bounds, unsigned count, void *user)
{
    (void)user;
    BvhNode *n = node;
    for (unsigned c = 0; c < count && c < 2; c++)
        n->ball[c] = ball_around(v3(bounds[c]->lower_x, bounds[c]->lower_y, bounds[c]->lower_z),
                                 v3(bounds[c]->upper_x, bounds[c]->upper_y, bounds[c]->upper_z));
}

static void *create_leaf(RTCThreadLocalAllocator alloc, const struct RTCBuildPrimitive *prims, size_t count,
                         void *user)
{
    (void)user;
    BvhNode *n = rtcThreadLocalAlloc(alloc, sizeof *n + count * sizeof(unsigned), 16);
    if (!n) return NULL;
    *n = (BvhNode){.leaf = true, .count = (unsigned)count};
    for (size_t i = 0; i < count; i++) n->prim[i] = prims[i].primID;
    return n;
}

static bool uses_sphere(const Object *o, bool analytic) { return analytic && o->is_sphere; }

/* The farthest point of an occluder, and of a subtree's, from c. */
static float prim_reach(const OuterPrim *p, vec3 c)
{
    if (p->is_sphere) return v3_len(v3_sub(p->ball.c, c)) + p->ball.r;
    float r = 0.0f;
    for (int k = 0; k < 3; k++) r = fmaxf(r, v3_len(v3_sub(p->p[k], c)));
    return r;
}

static float subtree_reach(const BvhNode *n, vec3 c, const OuterPrim *prims)
{
    float r = 0.0f;
    if (n->leaf)
        for (unsigned i = 0; i < n->count; i++) r = fmaxf(r, prim_reach(&prims[n->prim[i]], c));
    else
        for (int k = 0; k < 2; k++)
            if (n->child[k]) r = fmaxf(r, subtree_reach(n->child[k], c, prims));
    return r;
}

/* Shrink each ball from its box's half-diagonal to the farthest vertex the
 * box holds: tighter bounds, fewer nodes visited. */
static void tighten_balls(BvhNode *n, const OuterPrim *prims)
{
    if (n->leaf) return;
    for (int k = 0; k < 2; k++) {
        if (!n->child[k]) continue;
        n->ball[k].r = fminf(n->ball[k].r, subtree_reach(n->child[k], n->ball[k].c, prims) * (1.0f + 1e-5f));
        tighten_balls((BvhNode *)n->child[k], prims);
    }
}

static vec3 triangle_lo(const OuterPrim *p) { return v3_min(p->p[0], v3_min(p->p[1], p->p[2])); }
static vec3 triangle_hi(const OuterPrim *p) { return v3_max(p->p[0], v3_max(p->p[1], p->p[2])); }

static OuterPrim triangle_prim(const Mesh *m, int t)
{
    OuterPrim p = {.is_sphere = false};
    for (int k = 0; k < 3; k++) p.p[k] = m->positions[m->indices[3 * t + k]];
    p.n = v3_cross(v3_sub(p.p[1], p.p[0]), v3_sub(p.p[2], p.p[0]));
    p.ball.c = ball_around(triangle_lo(&p), triangle_hi(&p)).c;
    p.ball.r = prim_reach(&p, p.ball.c) * (1.0f + 1e-5f);
    return p;
}

static bool gather_prims(OuterScene *os, const Scene *scene, bool analytic, Error *err)
{
    long n = 0;
    for (int i = 0; i < scene->num_objects; i++)
        if (scene->objects[i].caster) n += uses_sphere(&scene->objects[i], analytic) ? 1 : scene->objects[i].mesh.num_triangles;
    os->prims = malloc(sizeof *os->prims * (size_t)(n + 1));
    if (!os->prims) return error_set(err, "out of memory for %ld outer objects", n);
    for (int i = 0; i < scene->num_objects; i++) {
        const Object *o = &scene->objects[i];
        if (!o->caster) continue;
        if (uses_sphere(o, analytic)) {
            os->prims[os->num_prims++] = (OuterPrim){.ball = {o->sphere_center_world, o->sphere_radius_world},
                                                     .is_sphere = true};
            os->num_spheres++;
            continue;
        }
        for (int t = 0; t < o->mesh.num_triangles; t++) os->prims[os->num_prims++] = triangle_prim(&o->mesh, t);
        os->num_triangles += o->mesh.num_triangles;
    }
    return true;
}

/* Build primitives (AABBs) for Embree's builder; the root's ball around all. */
static struct RTCBuildPrimitive *build_inputs(OuterScene *os, Error *err)
{
    struct RTCBuildPrimitive *in = aligned_alloc(32, sizeof *in * (size_t)os->num_prims);
    if (!in) {
        error_set(err, "out of memory for %d build primitives", os->num_prims);
        return NULL;
    }
    vec3 all_lo = v3(INFINITY, INFINITY, INFINITY), all_hi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < os->num_prims; i++) {
        const OuterPrim *p = &os->prims[i];
        vec3 r = v3(p->ball.r, p->ball.r, p->ball.r);
        vec3 lo = p->is_sphere ? v3_sub(p->ball.c, r) : triangle_lo(p), hi = p->is_sphere ? v3_add(p->ball.c, r) : triangle_hi(p);
        in[i] = (struct RTCBuildPrimitive){lo.x, lo.y, lo.z, 0, hi.x, hi.y, hi.z, (unsigned)i};
        all_lo = v3_min(all_lo, lo);
        all_hi = v3_max(all_hi, hi);
    }
    os->root_ball = ball_around(all_lo, all_hi);
    return in;
}

static bool build_bvh(OuterScene *os, RTCDevice dev, Error *err)
{
    if (os->num_prims == 0) return true;
    struct RTCBuildPrimitive *in = build_inputs(os, err);
    if (!in) return false;
    os->bvh = rtcNewBVH(dev);
    struct RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM; /* no spatial splits: each occluder in one leaf */
    args.maxDepth = MAX_DEPTH;
    args.maxLeafSize = MAX_LEAF;
    args.bvh = os->bvh;
    args.primitives = in;
    args.primitiveCount = args.primitiveArrayCapacity = (size_t)os->num_prims;
    args.createNode = create_node;
    args.setNodeChildren = set_children;
    args.setNodeBounds = set_bounds;
    args.createLeaf = create_leaf;
    os->root = rtcBuildBVH(&args);
    free(in);
    enum RTCError code = rtcGetDeviceError(dev);
    if (!os->root || code != RTC_ERROR_NONE)
        return error_set(err, "Embree could not build the outer objects' BVH (error %d)", (int)code);
    tighten_balls((BvhNode *)os->root, os->prims);
    os->root_ball.r = fminf(os->root_ball.r, subtree_reach(os->root, os->root_ball.c, os->prims) * (1.0f + 1e-5f));
    return true;
}

OuterScene *outer_scene_create(const Scene *scene, bool analytic_spheres, Error *err)
{
    RTCDevice dev = rt_device(err);
    if (!dev) return NULL;
    OuterScene *os = calloc(1, sizeof *os);
    if (!os) {
        error_set(err, "out of memory");
        return NULL;
    }
    if (!gather_prims(os, scene, analytic_spheres, err) || !build_bvh(os, dev, err)) {
        outer_scene_release(os);
        return NULL;
    }
    /* nodes: about 2 per MAX_LEAF / 2 primitives, each a BvhNode */
    os->bytes = sizeof *os->prims * (size_t)os->num_prims + sizeof(BvhNode) * (size_t)(os->num_prims / 2 + 1);
    return os;
}

void outer_scene_release(OuterScene *os)
{
    if (!os) return;
    if (os->bvh) rtcReleaseBVH(os->bvh);
    free(os->prims);
    free(os);
}

size_t outer_scene_bytes(const OuterScene *os) { return os->bytes; }
int outer_scene_spheres(const OuterScene *os) { return os->num_spheres; }
int outer_scene_triangles(const OuterScene *os) { return os->num_triangles; }
