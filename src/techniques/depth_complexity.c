/* depth_complexity.c -- `depth_complexity`: depth-complexity sampling (Laine
 * et al. 2005, "Soft shadow volumes for ray tracing"; course §5.3.2.3). Per
 * view sample p, a counter per light sample x_i holds the depth complexity
 * D(x_i), the number of caster surfaces the segment p -> x_i crosses, known
 * up to one constant from the silhouette edges alone; one reference ray fixes
 * the constant, and the visibility is the fraction of samples with D = 0.
 *
 * Light samples are the reference's own (rt/reference.c): the same pattern,
 * seed, count and stream per view sample, mapped by light_sample from p, rays
 * from p lifted by rt_ray_offset along the geometric normal (`org`), and only
 * the samples above the geometric tangent plane counted (docs/architecture.md,
 * *Sample classes*); a light sliver above the plane that none reaches gets the
 * reference's one ray toward the light's highest point.
 *
 * Projection: each direction d from org maps to the gnomonic plane of the
 * axis c toward the light's centre, x(d) = (d.u / d.c, d.v / d.c) with
 * (u, v, c) a right-handed orthonormal frame, where segments are straight
 * lines. Casters are clipped to d.c >= CLIP_EPS (the part behind org's plane
 * cannot block a segment toward the light). D changes only where x crosses
 * the projection of an edge that is a silhouette from org (Laine et al. 2005
 * §3: the depth complexity function is piecewise constant, its steps the
 * projected silhouette edges; an edge shared by two triangles facing the
 * same way from org steps nothing). Relative counts: the signed crossings of
 * the light-plane segment x_ref -> x_i with the projected edges, each
 * triangle's edges counted with its facing from org (+1 front, -1 back) and
 * its traversal, so the two triangles of an edge that is not a silhouette
 * cancel exactly (the crossing predicate is evaluated on the edge's
 * canonical endpoint order) and an open edge steps once: Laine's per-edge
 * update with the edge's multiplicity, summed over the triangles that carry
 * it. Crossing into a front-facing triangle's projection raises D by 1.
 *
 * The constant (Laine et al. 2005 §3.2; catalogue: "one reference ray toward
 * a sample away from all projected edges"): the reference sample is the one
 * whose relative count is least, and one Embree occlusion ray toward it (the
 * reference's own ray) decides: unblocked, its D is 0 and D(x_i) = rel_i -
 * min; blocked, every sample's D >= 1 and the view sample is dark. So a
 * boolean ray suffices and no depth-complexity count along a ray is needed.
 *
 * Assumption (Laine et al. 2005's): the casters lie between the receivers and
 * the light; geometry beyond a light sample is counted as if in front.
 * `near_edge` (aux) counts the light samples whose projection lies within
 * AMBIGUOUS_TAN of a projected edge: there the float ray test and the
 * projected predicate may disagree. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/mat4.h"
#include "core/sampling.h"
#include "resources/standard.h"
#include "scene/light.h"
#include "techniques/technique.h"

#define DC_MAX_SAMPLES 1024
#define CLIP_EPS 1e-9        /* world units along c: the clip plane just in front of org */
#define AMBIGUOUS_TAN 1e-5   /* gnomonic-plane distance (~radians near the axis) counted as near an edge */

static const char *const pattern_names[] = {"r2", "stratified", "random", NULL}; /* SamplingPattern order */
enum { DC_SAMPLES, DC_PATTERN, DC_SEED };

static const ParamDesc dc_params[] = {
    {"samples", PARAM_INT, 256, 16, DC_MAX_SAMPLES, "light samples",
     "N: depth-complexity counters per view sample (Laine et al. 2005 used 256-1024); the reference's --samples "
     "gives the same points",
     NULL},
    {"pattern", PARAM_ENUM, SAMPLING_R2, 0, 2, "",
     "the light samples' 2D pattern, the reference's own (--pattern): r2, stratified (N a square) or random",
     pattern_names},
    {"seed", PARAM_INT, 1, 0, 2147483647, "",
     "the light samples' seed, the reference's own (--seed): with the same N, pattern and seed the samples are the "
     "reference's rays",
     NULL},
};

static const char *const dc_resources[] = {"embree_bvh", NULL};
static const char *const dc_aux[] = {"near_edge", NULL};

#define CHUNK 32 /* triangles per bounding sphere */

/* A bounding sphere (world space). */
typedef struct Ball {
    dvec3 centre;
    double radius;
} Ball;

/* Caster triangles in chunks of at most CHUNK, each within one object. */
typedef struct DcState {
    RTCScene rtc;
    float extent;
    int num_tris, num_chunks, num_objects;
    vec3 *tri;         /* caster triangles, world space, 3 corners each */
    int *chunk_first;  /* per chunk: its first triangle; num_chunks + 1 */
    Ball *chunk_ball;
    int *object_first; /* per caster object: its first chunk; num_objects + 1 */
    Ball *object_ball;
} DcState;

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

static bool alloc_casters(DcState *st, long tris, long chunks, int objects)
{
    st->tri = malloc(sizeof *st->tri * 3 * (size_t)(tris + 1));
    st->chunk_first = malloc(sizeof *st->chunk_first * (size_t)(chunks + 1));
    st->chunk_ball = malloc(sizeof *st->chunk_ball * (size_t)(chunks + 1));
    st->object_first = malloc(sizeof *st->object_first * (size_t)(objects + 1));
    st->object_ball = malloc(sizeof *st->object_ball * (size_t)(objects + 1));
    return st->tri && st->chunk_first && st->chunk_ball && st->object_first && st->object_ball;
}

static bool collect_casters(const Scene *scene, DcState *st, Error *err)
{
    long n = 0, chunks = 0;
    int objects = 0;
    for (int i = 0; i < scene->num_objects; i++) {
        int t = scene->objects[i].mesh.num_triangles;
        if (!scene->objects[i].caster || t == 0) continue;
        n += t;
        chunks += (t + CHUNK - 1) / CHUNK;
        objects++;
    }
    if (n > INT32_MAX / 3) return error_set(err, "depth_complexity: %ld caster triangles (at most %d)", n, INT32_MAX / 3);
    if (!alloc_casters(st, n, chunks, objects)) return error_set(err, "out of memory for %ld caster triangles", n);
    for (int i = 0; i < scene->num_objects; i++) {
        const Mesh *m = &scene->objects[i].mesh;
        if (!scene->objects[i].caster || m->num_triangles == 0) continue;
        int first = st->num_tris;
        st->object_first[st->num_objects] = st->num_chunks;
        for (int t = 0; t < m->num_triangles; t++, st->num_tris++) {
            if (t % CHUNK == 0) st->chunk_first[st->num_chunks++] = st->num_tris;
            for (int k = 0; k < 3; k++) st->tri[3 * st->num_tris + k] = m->positions[m->indices[3 * t + k]];
        }
        st->object_ball[st->num_objects++] = bound_corners(st->tri, 3 * first, 3 * st->num_tris);
    }
    st->chunk_first[st->num_chunks] = st->num_tris;
    st->object_first[st->num_objects] = st->num_chunks;
    for (int c = 0; c < st->num_chunks; c++)
        st->chunk_ball[c] = bound_corners(st->tri, 3 * st->chunk_first[c], 3 * st->chunk_first[c + 1]);
    return true;
}

static void dc_release(void *state)
{
    DcState *st = state;
    if (!st) return;
    free(st->tri);
    free(st->chunk_first);
    free(st->chunk_ball);
    free(st->object_first);
    free(st->object_ball);
    free(st);
}

static bool dc_prepare(const TechContext *ctx, void **state, Error *err)
{
    if (!sampling_check_count((SamplingPattern)ctx->params[DC_PATTERN], (int)ctx->params[DC_SAMPLES], err))
        return false;
    const RtScene *bvh = res_bvh(ctx->rm, ctx->scene, RT_CASTERS, err);
    if (!bvh) return false;
    DcState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    if (!collect_casters(ctx->scene, st, err)) {
        dc_release(st);
        return false;
    }
    st->rtc = rt_scene_handle(bvh);
    st->extent = scene_extent(ctx->scene);
    *state = st;
    return true;
}

/* The gnomonic frame at org: axis c, and u, v with u x v = c. */
typedef struct Frame {
    dvec3 org, u, v, c;
} Frame;

typedef struct P2 {
    double x, y;
} P2;

static P2 project_dir(const Frame *f, dvec3 d)
{
    double dc = d3_dot(d, f->c);
    return (P2){d3_dot(d, f->u) / dc, d3_dot(d, f->v) / dc};
}

static double orient2(P2 a, P2 b, P2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

/* The light samples of one view sample: their projections, and the lanes
 * above the tangent plane. */
typedef struct Samples {
    int n, kept;
    P2 x[DC_MAX_SAMPLES];
    LightSample ls[DC_MAX_SAMPLES];
    bool above[DC_MAX_SAMPLES];
    int rel[DC_MAX_SAMPLES];   /* relative depth complexity, Laine's counters */
    int near[DC_MAX_SAMPLES];  /* 1: within AMBIGUOUS_TAN of a projected edge */
    P2 lo, hi;                 /* bounds of the kept samples' projections */
    double cos_cone;           /* the kept directions' least cosine to the axis c */
} Samples;

/* Signed steps of the edge a -> b (clipped, world space relative to org)
 * added to every kept sample whose segment from the reference point r
 * crosses its projection, with weight w (the triangle's facing). The
 * predicate runs on the lexicographically smaller endpoint first, so the
 * reversed edge of a neighbour gives exactly the opposite steps. */
static void add_edge(Samples *sm, const Frame *f, dvec3 a, dvec3 b, int w, P2 r)
{
    bool swap = a.x > b.x || (a.x == b.x && (a.y > b.y || (a.y == b.y && a.z > b.z)));
    if (swap) {
        dvec3 t = a;
        a = b;
        b = t;
        w = -w;
    }
    P2 qa = project_dir(f, a), qb = project_dir(f, b);
    if (fmax(qa.x, qb.x) < sm->lo.x || fmin(qa.x, qb.x) > sm->hi.x || fmax(qa.y, qb.y) < sm->lo.y ||
        fmin(qa.y, qb.y) > sm->hi.y)
        return;
    double len = hypot(qb.x - qa.x, qb.y - qa.y);
    bool r_left = orient2(qa, qb, r) > 0.0;
    for (int i = 0; i < sm->n; i++) {
        if (!sm->above[i]) continue;
        double o = orient2(qa, qb, sm->x[i]);
        if (fabs(o) <= AMBIGUOUS_TAN * len) {
            double t = ((sm->x[i].x - qa.x) * (qb.x - qa.x) + (sm->x[i].y - qa.y) * (qb.y - qa.y)) / (len * len);
            sm->near[i] |= t >= 0.0 && t <= 1.0;
        }
        bool x_left = o > 0.0;
        if (x_left == r_left) continue;
        /* the segment r -> x_i crosses the edge's line; it crosses the edge
         * where qa and qb lie on either side of the segment's line */
        bool a_left = orient2(r, sm->x[i], qa) > 0.0, b_left = orient2(r, sm->x[i], qb) > 0.0;
        if (a_left == b_left) continue;
        /* a front-facing triangle (w = +1) projects clockwise in (u, v), its
         * inside on the right of each edge: entering it (left -> right) adds 1 */
        sm->rel[i] += x_left ? -w : w;
    }
}

/* Clip triangle t to d.c >= CLIP_EPS (Sutherland-Hodgman, the crossing
 * point computed from the edge's inside corner so both triangles of an edge
 * clip it alike) and add its edges. */
static void add_triangle(Samples *sm, const Frame *f, const vec3 *t, P2 r)
{
    dvec3 q[3];
    double h[3];
    for (int k = 0; k < 3; k++) {
        q[k] = d3_sub(d3_from(t[k]), f->org);
        h[k] = d3_dot(q[k], f->c);
    }
    if (h[0] < CLIP_EPS && h[1] < CLIP_EPS && h[2] < CLIP_EPS) return;
    dvec3 n = d3_cross(d3_sub(q[1], q[0]), d3_sub(q[2], q[0]));
    double s = -d3_dot(n, q[0]); /* n . (org - corner): > 0 front-facing from org */
    if (s == 0.0) return;        /* edge-on from org: it blocks no segment */
    int w = s > 0.0 ? 1 : -1;
    dvec3 poly[4];
    int np = 0;
    for (int k = 0; k < 3; k++) {
        int j = (k + 1) % 3;
        bool in_k = h[k] >= CLIP_EPS, in_j = h[j] >= CLIP_EPS;
        if (in_k) poly[np++] = q[k];
        if (in_k != in_j) {
            int i = in_k ? k : j, o = in_k ? j : k;
            poly[np++] = d3_madd(q[i], d3_sub(q[o], q[i]), (h[i] - CLIP_EPS) / (h[i] - h[o]));
        }
    }
    for (int k = 0; k < np; k++) add_edge(sm, f, poly[k], poly[(k + 1) % np], w, r);
}

static bool occluded(RTCScene rtc, vec3 org, const LightSample *ls)
{
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    struct RTCRay ray = {.org_x = org.x, .org_y = org.y, .org_z = org.z, .tnear = 0.0f,
                         .dir_x = ls->dir_world.x, .dir_y = ls->dir_world.y, .dir_z = ls->dir_world.z,
                         .tfar = isinf(ls->dist) ? INFINITY : ls->dist * (1.0f - 1e-5f), .mask = 0xFFFFFFFFu};
    rtcOccluded1(rtc, &ictx, &ray);
    return ray.tfar == -INFINITY;
}

/* The reference's samples for view sample s (rt/reference.c fill_batch). */
static void draw_samples(Samples *sm, const TechContext *ctx, int s, const Frame *f)
{
    vec3 p = ctx->vs->p_world[s], ng = ctx->vs->n_geom_world[s];
    SamplingPattern pat = (SamplingPattern)ctx->params[DC_PATTERN];
    uint32_t stream = sampling_stream((uint32_t)ctx->params[DC_SEED], (uint32_t)s);
    sm->n = (int)ctx->params[DC_SAMPLES];
    sm->kept = 0;
    sm->lo = (P2){INFINITY, INFINITY};
    sm->hi = (P2){-INFINITY, -INFINITY};
    sm->cos_cone = 1.0;
    for (int i = 0; i < sm->n; i++) {
        float u, v;
        sample_2d(pat, stream, i, sm->n, &u, &v);
        sm->ls[i] = light_sample(ctx->light, p, u, v);
        dvec3 d = d3_from(sm->ls[i].dir_world);
        sm->above[i] = v3_dot(ng, sm->ls[i].dir_world) > 0.0f && d3_dot(d, f->c) > 0.0;
        sm->rel[i] = sm->near[i] = 0;
        if (!sm->above[i]) continue;
        sm->kept++;
        sm->x[i] = project_dir(f, d);
        sm->cos_cone = fmin(sm->cos_cone, d3_dot(d, f->c) / d3_len(d));
        sm->lo = (P2){fmin(sm->lo.x, sm->x[i].x), fmin(sm->lo.y, sm->x[i].y)};
        sm->hi = (P2){fmax(sm->hi.x, sm->x[i].x), fmax(sm->hi.y, sm->x[i].y)};
    }
}

static Frame frame_at(const TechContext *ctx, vec3 org, vec3 p)
{
    LightSample centre = light_sample_center(ctx->light, p);
    Frame f = {d3_from(org), d3(0, 0, 0), d3(0, 0, 0), d3_normalize_or(d3_from(centre.dir_world), d3(0, 0, 1))};
    dvec3 helper = fabs(f.c.x) < 0.6 ? d3(1, 0, 0) : d3(0, 1, 0);
    f.u = d3_normalize_or(d3_cross(helper, f.c), d3(1, 0, 0));
    f.v = d3_cross(f.c, f.u);
    return f;
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

/* The cosine of the cone from org around the light's centre holding the
 * whole light (its bounding sphere): every light sample lies inside. */
static double light_cone(const Ball *light, const Frame *f)
{
    double r = light->radius, dist = d3_len(d3_sub(light->centre, f->org));
    return dist <= r ? -1.0 : sqrt(1.0 - (r / dist) * (r / dist));
}

static Ball light_ball(const Light *l)
{
    double r = l->kind == LIGHT_RECT ? 0.5 * hypot(l->width, l->height) : l->radius;
    return (Ball){d3_from(l->position), r * (1.0 + 1e-6)};
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

/* Does any caster triangle reach the cone? With counts: add them all. */
static bool add_casters(const DcState *st, Samples *sm, const Frame *f, const Ball *light, double cos_cone, P2 r,
                        bool add)
{
    bool any = false;
    for (int o = 0; o < st->num_objects; o++) {
        if (!ball_in_cone(&st->object_ball[o], f, cos_cone)) continue;
        for (int c = st->object_first[o]; c < st->object_first[o + 1]; c++) {
            if (!ball_in_cone(&st->chunk_ball[c], f, cos_cone)) continue;
            for (int t = st->chunk_first[c]; t < st->chunk_first[c + 1]; t++) {
                if (plane_separates(&st->tri[3 * t], f, light)) continue;
                if (!add) return true;
                any = true;
                add_triangle(sm, f, &st->tri[3 * t], r);
            }
        }
    }
    return any;
}

/* Visibility of one view sample; *near counts its ambiguous light samples. */
static float sample_visibility(const DcState *st, const TechContext *ctx, int s, Samples *sm, int *near)
{
    vec3 p = ctx->vs->p_world[s], ng = ctx->vs->n_geom_world[s];
    vec3 org = v3_madd(p, ng, rt_ray_offset(st->extent, p));
    Frame f = frame_at(ctx, org, p);
    *near = 0;
    Ball light = light_ball(ctx->light);
    if (!add_casters(st, NULL, &f, &light, light_cone(&light, &f), (P2){0, 0}, false))
        return 1.0f; /* no caster reaches the light's cone: every ray the reference traces is unblocked */
    draw_samples(sm, ctx, s, &f);
    if (sm->kept == 0) { /* a sliver above the horizon: the reference's one ray */
        LightSample hi = light_sample_highest(ctx->light, p, ng);
        return occluded(st->rtc, org, &hi) ? 0.0f : 1.0f;
    }
    int first = 0;
    while (!sm->above[first]) first++;
    P2 r = sm->x[first]; /* counters relative to the first kept sample */
    add_casters(st, sm, &f, &light, sm->cos_cone, r, true);
    int best = first;
    for (int i = first; i < sm->n; i++)
        if (sm->above[i] && sm->rel[i] < sm->rel[best]) best = i;
    for (int i = 0; i < sm->n; i++) *near += sm->above[i] && sm->near[i];
    if (occluded(st->rtc, org, &sm->ls[best])) return 0.0f; /* the least count is >= 1: all blocked */
    int lit = 0;
    for (int i = 0; i < sm->n; i++) lit += sm->above[i] && sm->rel[i] == sm->rel[best];
    return (float)lit / (float)sm->kept;
}

static void dc_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const DcState *st = state;
    Samples *sm = malloc(sizeof *sm);
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        int near = 0;
        float v = sm ? sample_visibility(st, ctx, s, sm, &near) : NAN; /* out of memory: no value */
        tech_store(ctx, out, begin, s, v);
        if (ctx->aux) ctx->aux[s] = (float)near;
    }
    free(sm);
}

const Technique tech_depth_complexity = {
    .name = "depth_complexity",
    .family = "geometry",
    .source = "course §5.3.2.3 (Laine et al. 2005, depth-complexity sampling)",
    .summary = "a depth-complexity counter per light sample, stepped by the projected silhouette edges, and one "
               "reference ray that fixes the constant: exact soft shadows with the reference's own light samples",
    .params = dc_params,
    .num_params = (int)(sizeof dc_params / sizeof dc_params[0]),
    .resources = dc_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK),
    .main_param = "samples",
    .prepare = dc_prepare,
    .evaluate = dc_evaluate,
    .release = dc_release,
    .aux = dc_aux,
};
