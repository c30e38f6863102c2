/* exact_soft.c -- the exact soft-shadow techniques' shared light samples,
 * normalised light frame and caster culling (see exact_soft.h).
 *
 * Stage one's structure. Laine et al. 2005 §4 bin the possible silhouette
 * edges' wedges in a hemicube about the light and look a point's cell up;
 * a cell must hold every edge whose wedge reaches any point seen through it,
 * and a wedge seen from the light spans the light's angular size at the edge
 * (its half-angle about asin((r_light + r_edge) / distance)) however close
 * behind the edge the point lies, where the cone from the point to the
 * light meets only a sliver of the casters. Measured at 160x120 (per lit
 * candidate, cells of no size, the best a hemicube can do): bunny 847 of
 * its 13,854 listed edges against the 30.8 that reach the cone,
 * sphere-on-plane 26.8 of 1,176 against 1.5. As
 * Lehtinen et al. 2006 (course §5.3.2.3: a 3D kd-tree, "significantly less
 * conservative" than the 2D grid), the edges' spheres go into a 3D
 * hierarchy instead, descended per point with the very cone test stage two
 * applies to each edge, so it returns exactly the edges that test passes. */
#include "techniques/exact_soft.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "core/counters.h"
#include "resources/geometry/silhouette.h"
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

/* ---- stage one: the possible silhouette edges under a sphere tree --------- */

/* The sphere around side 3 t + k's edge (corner k -> k + 1 of t). */
static Ball bound_edge(const vec3 *tri, int side)
{
    dvec3 a = d3_from(tri[side]), b = d3_from(tri[side - side % 3 + (side + 1) % 3]);
    return (Ball){d3_scale(d3_add(a, b), 0.5), 0.5 * d3_len(d3_sub(b, a)) * (1.0 + 1e-6)};
}

#define TREE_LEAF 4         /* items per leaf at most */
#define TREE_SPLIT_DEPTH 64 /* below it, ranges are halved by count: depth < 64 + 32 < EXACT_TREE_DEPTH */

typedef struct TreeBuild {
    const Ball *ball; /* per item */
    BallTree *t;
    double slack;     /* world units every enclosing sphere is widened by */
} TreeBuild;

/* A sphere holding a and b (the smallest, then widened by a relative 1e-9
 * and `slack`: the margin that keeps a parent's tests passing wherever a
 * child's pass, through their rounding). */
static Ball enclose(Ball a, Ball b, double slack)
{
    dvec3 ab = d3_sub(b.centre, a.centre);
    double d = d3_len(ab);
    Ball r = a;
    if (d + a.radius <= b.radius) r = b;
    else if (d + b.radius > a.radius) {
        double radius = 0.5 * (d + a.radius + b.radius); /* d > 0 here */
        r = (Ball){d3_madd(a.centre, ab, (radius - a.radius) / d), radius};
    }
    r.radius = r.radius * (1.0 + 1e-9) + slack;
    return r;
}

/* Moves the items of [first, first + count) whose centre lies below `mid`
 * along axis to the front; returns how many they are. */
static int partition_items(TreeBuild *b, int first, int count, int axis, double mid)
{
    int *it = b->t->item + first, lo = 0, hi = count;
    while (lo < hi) {
        const double *c = &b->ball[it[lo]].centre.x;
        if (c[axis] < mid) lo++;
        else {
            int tmp = it[lo];
            it[lo] = it[--hi];
            it[hi] = tmp;
        }
    }
    return lo;
}

/* The node over items [first, first + count): split at the middle of the
 * centres' box along its longest axis (by count where that leaves a side
 * empty, or deep down); returns its index. */
static int build_node(TreeBuild *b, int first, int count, int depth)
{
    BallTree *t = b->t;
    int id = t->num_nodes++;
    if (count <= TREE_LEAF) {
        Ball ball = b->ball[t->item[first]];
        for (int i = 1; i < count; i++) ball = enclose(ball, b->ball[t->item[first + i]], b->slack);
        t->node[id] = (BallNode){enclose(ball, ball, b->slack), first, count};
        return id;
    }
    dvec3 lo = b->ball[t->item[first]].centre, hi = lo;
    for (int i = 1; i < count; i++) {
        dvec3 c = b->ball[t->item[first + i]].centre;
        lo = d3(fmin(lo.x, c.x), fmin(lo.y, c.y), fmin(lo.z, c.z));
        hi = d3(fmax(hi.x, c.x), fmax(hi.y, c.y), fmax(hi.z, c.z));
    }
    dvec3 size = d3_sub(hi, lo);
    int axis = size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2;
    const double *l = &lo.x, *h = &hi.x;
    int m = depth < TREE_SPLIT_DEPTH ? partition_items(b, first, count, axis, 0.5 * (l[axis] + h[axis])) : 0;
    if (m == 0 || m == count) m = count / 2;
    build_node(b, first, m, depth + 1);
    int right = build_node(b, first + m, count - m, depth + 1);
    t->node[id] = (BallNode){enclose(t->node[id + 1].ball, t->node[right].ball, b->slack), right, 0};
    return id;
}

/* The tree over n spheres; slack as in TreeBuild. */
static bool build_tree(BallTree *t, const Ball *ball, int n, double slack)
{
    *t = (BallTree){0, malloc(sizeof *t->node * (2 * (size_t)n + 1)), malloc(sizeof *t->item * ((size_t)n + 1))};
    if (!t->node || !t->item) return false;
    for (int i = 0; i < n; i++) t->item[i] = i;
    TreeBuild b = {ball, t, slack};
    if (n > 0) build_node(&b, 0, n, 0);
    BallNode *fit = realloc(t->node, sizeof *t->node * ((size_t)t->num_nodes + 1)); /* about n / 2 of the 2 n */
    if (fit) t->node = fit;
    return true;
}

/* The trees' slack: 1e-9 of the casters' largest coordinate and the scene's
 * extent, far above the cone and distance tests' rounding there. */
static double tree_slack(const ExactCasters *c)
{
    double scale = c->extent;
    for (size_t k = 0; k < 3 * (size_t)c->num_tris; k++)
        scale = fmax(scale, fmax(fabs(c->tri[k].x), fmax(fabs(c->tri[k].y), fabs(c->tri[k].z))));
    return 1e-9 * scale;
}

static void free_tree(BallTree *t)
{
    free(t->node);
    free(t->item);
}

/* The sides of every welded edge (counting sort by edge id), then each
 * possible silhouette edge's sides and sphere. */
static bool list_edges(const ExactCasters *c, const int32_t *edge, ExactEdges *e)
{
    size_t n = 3 * (size_t)c->num_tris;
    int *first = calloc((size_t)e->num_welded + 2, sizeof *first), *side = malloc(sizeof *side * (n + 1));
    e->side_first = malloc(sizeof *e->side_first * ((size_t)e->num_welded + 1));
    e->side = malloc(sizeof *e->side * (n + 1));
    e->edge_ball = malloc(sizeof *e->edge_ball * ((size_t)e->num_welded + 1));
    bool ok = first && side && e->side_first && e->side && e->edge_ball;
    for (size_t k = 0; ok && k < n; k++) first[edge[k] + 2]++;
    for (int w = 0; ok && w < e->num_welded; w++) first[w + 2] += first[w + 1];
    for (size_t k = 0; ok && k < n; k++) side[first[edge[k] + 1]++] = (int)k; /* first[w] .. first[w + 1]: w's */
    int used = 0;
    for (int w = 0; ok && w < e->num_welded; w++) {
        const int *sw = &side[first[w]];
        int ns = first[w + 1] - first[w];
        if (!possible_silhouette(c, sw, ns)) continue;
        e->side_first[e->num_listed] = used;
        e->edge_ball[e->num_listed++] = bound_edge(c->tri, sw[0]);
        for (int i = 0; i < ns; i++) e->side[used++] = sw[i];
    }
    if (ok) e->side_first[e->num_listed] = used;
    free(first);
    free(side);
    return ok;
}

static void free_edges(ExactEdges *e)
{
    free(e->side_first);
    free(e->side);
    free(e->edge_ball);
    free_tree(&e->edge_tree);
    free(e);
}

/* The welded edges, the possible silhouette ones listed and their tree. */
static ExactEdges *build_edges(const ExactCasters *c)
{
    size_t n = 3 * (size_t)c->num_tris;
    ExactEdges *e = calloc(1, sizeof *e);
    int32_t *edge = malloc(sizeof *edge * (n + 1));
    long welded = e && edge ? number_edges(c->tri, n, edge) : -1;
    bool ok = welded >= 0;
    if (ok) e->num_welded = (int)welded;
    ok = ok && list_edges(c, edge, e) && build_tree(&e->edge_tree, e->edge_ball, e->num_listed, tree_slack(c));
    free(edge);
    if (ok || !e) return e && ok ? e : NULL;
    free_edges(e);
    return NULL;
}

static size_t edges_bytes(const void *res)
{
    const ExactEdges *e = res;
    size_t sides = e->side_first ? (size_t)e->side_first[e->num_listed] : 0;
    return sizeof *e + ((size_t)e->num_listed + 1) * (sizeof *e->side_first + sizeof *e->edge_ball) +
           sides * sizeof *e->side +
           (size_t)e->edge_tree.num_nodes * sizeof(BallNode) + (size_t)e->num_listed * sizeof(int);
}

static void edges_destroy(void *res) { free_edges(res); }

static const ResourceKind kind_exact_edges = {"exact_edges", edges_bytes, edges_destroy, RES_FRAME};

static void *build_edges_res(const void *args, Error *err)
{
    const ExactCasters *c = args;
    ExactEdges *e = build_edges(c);
    if (!e) error_set(err, "out of memory for the edges of %d caster triangles", c->num_tris);
    return e;
}

/* The light's possible silhouette edges, keyed by the casters and the light
 * (the listing depends on the light's ball, the chunks on the casters). */
static const ExactEdges *res_exact_edges(const TechContext *ctx, const ExactCasters *c, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, "exact_edges 1");
    hash_u64(&h, ctx->scene->hash_casters);
    hash_u64(&h, ctx->scene->hash_lights[ctx->light_index]);
    char desc[160];
    snprintf(desc, sizeof desc, "possible silhouette edges of light %d, %d caster triangles", ctx->light_index + 1,
             c->num_tris);
    return rm_acquire(ctx->rm, &kind_exact_edges, hash_final(&h), desc, build_edges_res, c, err);
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

/* A triangle's place on a Morton curve through its object's box. */
typedef struct TriKey {
    uint32_t code;
    int t;
} TriKey;

static int by_code(const void *a, const void *b)
{
    const TriKey *p = a, *q = b;
    return p->code != q->code ? (p->code > q->code) - (p->code < q->code) : (p->t > q->t) - (p->t < q->t);
}

/* The low 10 bits of x, two zero bits after each. */
static uint32_t spread_bits(uint32_t x)
{
    x &= 0x3ffu;
    x = (x | x << 16) & 0x30000ffu;
    x = (x | x << 8) & 0x300f00fu;
    x = (x | x << 4) & 0x30c30c3u;
    return (x | x << 2) & 0x9249249u;
}

/* m's triangles in the Morton order of their centroids (10 bits an axis of
 * the mesh's box), so EXACT_CHUNK consecutive ones are close together and
 * their chunk's sphere is tight (a scan's file order is not); NULL when out
 * of memory. */
static TriKey *morton_order(const Mesh *m)
{
    TriKey *key = malloc(sizeof *key * (size_t)m->num_triangles);
    if (!key) return NULL;
    vec3 lo = m->positions[m->indices[0]], hi = lo;
    for (int k = 0; k < 3 * m->num_triangles; k++) {
        lo = v3_min(lo, m->positions[m->indices[k]]);
        hi = v3_max(hi, m->positions[m->indices[k]]);
    }
    const float *l = &lo.x, *h = &hi.x;
    for (int t = 0; t < m->num_triangles; t++) {
        vec3 p0 = m->positions[m->indices[3 * t]], p1 = m->positions[m->indices[3 * t + 1]],
             p2 = m->positions[m->indices[3 * t + 2]];
        const float *a = &p0.x, *b = &p1.x, *c = &p2.x;
        key[t] = (TriKey){0, t};
        for (int axis = 0; axis < 3; axis++) {
            double size = (double)h[axis] - l[axis];
            double u = size > 0.0 ? (((double)a[axis] + b[axis] + c[axis]) / 3.0 - l[axis]) / size : 0.0;
            key[t].code |= spread_bits((uint32_t)fmin(1023.0, fmax(0.0, 1024.0 * u))) << axis;
        }
    }
    qsort(key, (size_t)m->num_triangles, sizeof *key, by_code);
    return key;
}

static bool collect_casters(const Scene *scene, const Silhouette *sil, const Ball *light, ExactCasters *c, Error *err)
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
        TriKey *order = morton_order(m);
        if (!order) return error_set(err, "out of memory for %ld caster triangles", n);
        int first = c->num_tris;
        c->object_first[c->num_objects] = c->num_chunks;
        for (int i = 0; i < m->num_triangles; i++, c->num_tris++) {
            if (i % EXACT_CHUNK == 0) {
                c->chunk_object[c->num_chunks] = c->num_objects;
                c->chunk_first[c->num_chunks++] = c->num_tris;
            }
            c->tri_chunk[c->num_tris] = c->num_chunks - 1;
            for (int k = 0; k < 3; k++) c->tri[3 * c->num_tris + k] = m->positions[m->indices[3 * order[i].t + k]];
        }
        free(order);
        c->object_closed[c->num_objects] = object_closed(sil, i);
        c->object_ball[c->num_objects++] = bound_corners(c->tri, 3 * first, 3 * c->num_tris);
    }
    c->chunk_first[c->num_chunks] = c->num_tris;
    c->object_first[c->num_objects] = c->num_chunks;
    for (int k = 0; k < c->num_chunks; k++)
        c->chunk_ball[k] = bound_corners(c->tri, 3 * c->chunk_first[k], 3 * c->chunk_first[k + 1]);
    for (int t = 0; t < c->num_tris; t++) plane_and_side(&c->tri[3 * t], light, &c->tri_normal[t], &c->tri_light_side[t]);
    return build_tree(&c->chunk_tree, c->chunk_ball, c->num_chunks, tree_slack(c)) ||
           error_set(err, "out of memory for %ld caster triangles", n);
}

void exact_casters_free(ExactCasters *c)
{
    free_tree(&c->chunk_tree);
    free(c->tri_chunk);
    free(c->tri_normal);
    free(c->tri_light_side);
    free(c->chunk_object);
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
    if (collect_casters(ctx->scene, sil, &light, c, err) && (!edges || (c->edges = res_exact_edges(ctx, c, err))))
        return true;
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
bool exact_ball_in_cone(const Ball *b, const Frame *f, const Cone *cone)
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

/* Calls fn for the triangles reaching the cone. */
static void visit_casters(const ExactCasters *c, const Frame *f, const Cone *cone, ExactTriangleFn fn, void *user)
{
    for (int o = 0; o < c->num_objects; o++) {
        if (!exact_ball_in_cone(&c->object_ball[o], f, cone)) continue;
        bool front_only = outside_closed(c, o, f);
        for (int k = c->object_first[o]; k < c->object_first[o + 1]; k++) {
            if (!exact_ball_in_cone(&c->chunk_ball[k], f, cone)) continue;
            for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++)
                if (!plane_separates(c, t, f)) fn(user, &c->tri[3 * t], front_only);
        }
    }
}

/* Does a triangle of chunk k reach the cone (visit_casters's tests)? */
typedef struct ReachQuery {
    const ExactCasters *c;
    ExactConeQuery q;
} ReachQuery;

static bool chunk_has_reaching(void *user, int k)
{
    const ReachQuery *r = user;
    const ExactCasters *c = r->c;
    if (!exact_ball_in_cone(&c->chunk_ball[k], r->q.f, &r->q.cone) ||
        !exact_ball_in_cone(&c->object_ball[c->chunk_object[k]], r->q.f, &r->q.cone))
        return false;
    for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++)
        if (!plane_separates(c, t, r->q.f)) return true; /* found: stop */
    return false;
}

void exact_for_casters(const ExactCasters *c, const LightPoints *lp, ExactTriangleFn fn, void *user)
{
    visit_casters(c, &lp->f, &lp->cone, fn, user);
}

bool exact_object_reaches(const ExactCasters *c, int o, const LightPoints *lp)
{
    return exact_ball_in_cone(&c->object_ball[o], &lp->f, &lp->cone);
}

bool exact_front_faces_suffice(const ExactCasters *c, int o, const LightPoints *lp)
{
    return outside_closed(c, o, &lp->f);
}

bool exact_chunk_reaches(const ExactCasters *c, int k, const LightPoints *lp)
{
    return exact_ball_in_cone(&c->chunk_ball[k], &lp->f, &lp->cone);
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
    ReachQuery reach = {c, {f, cone}};
    return exact_tree_query(&c->chunk_tree, exact_cone_test, &reach.q, chunk_has_reaching, &reach);
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

/* Does chunk k reach the samples' cone (its object's sphere and its own,
 * visit_casters's culls)? Found once per org, with its object's state:
 * reached[num_chunks + o] = 0 (out), 1 (in), 2 (in, front faces suffice). */
static bool chunk_reached(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, int k)
{
    if (sc->chunk_stamp[k] == sc->org) return sc->reached[k];
    int o = c->num_chunks + c->chunk_object[k];
    if (sc->chunk_stamp[o] != sc->org) {
        bool in = exact_ball_in_cone(&c->object_ball[o - c->num_chunks], &lp->f, &lp->cone);
        sc->reached[o] = in ? (uint8_t)(1 + outside_closed(c, o - c->num_chunks, &lp->f)) : 0;
        sc->chunk_stamp[o] = sc->org;
    }
    sc->reached[k] = sc->reached[o] && exact_ball_in_cone(&c->chunk_ball[k], &lp->f, &lp->cone);
    sc->chunk_stamp[k] = sc->org;
    return sc->reached[k];
}

/* Triangle t's weight from org as visit_casters and the per-triangle edges
 * count it: 0 when culled (chunk, plane), edge-on, or a back face where
 * front faces suffice; else its facing. Cached per org in scratch. */
static int triangle_weight(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, int t)
{
    if (sc->stamp[t] == sc->org) return sc->weight[t];
    int w = 0, k = c->tri_chunk[t];
    if (chunk_reached(c, lp, sc, k) && !plane_separates(c, t, &lp->f)) {
        dvec3 q[3];
        double h[3];
        w = relative_corners(&lp->f, &c->tri[3 * t], q, h);
        if (w < 0 && sc->reached[c->num_chunks + c->chunk_object[k]] == 2) w = 0; /* front_only */
    }
    sc->stamp[t] = sc->org;
    sc->weight[t] = (int8_t)w;
    return w;
}

bool exact_cone_test(const Ball *b, const void *query)
{
    const ExactConeQuery *q = query;
    return exact_ball_in_cone(b, q->f, &q->cone);
}

bool exact_tree_query(const BallTree *t, BallTestFn in, const void *query, BallItemFn fn, void *user)
{
    int stack[EXACT_TREE_DEPTH + 1], top = 0;
    if (t->num_nodes > 0) stack[top++] = 0;
    while (top > 0) {
        int id = stack[--top];
        const BallNode *n = &t->node[id];
        if (!in(&n->ball, query)) continue;
        if (n->count > 0) {
            for (int i = 0; i < n->count; i++)
                if (fn(user, t->item[n->first + i])) return true;
            continue;
        }
        stack[top++] = n->first; /* the right child, after the left */
        stack[top++] = id + 1;
    }
    return false;
}

/* One org's stage two (exact_for_silhouette). */
typedef struct SilhouetteVisit {
    const ExactCasters *c;
    const LightPoints *lp;
    ExactScratch *sc;
    ExactConeQuery edge_cone; /* the samples' cone widened by EXACT_EDGE_CONE_MARGIN */
    double reach;             /* clip_plane_edges's distance from org */
    ExactEdgeFn fn;
    void *user;
} SilhouetteVisit;

/* Listed edge e summed over its sides, if its sphere reaches the cone. */
static bool sum_edge(void *user, int e)
{
    const SilhouetteVisit *v = user;
    const ExactEdges *edges = v->c->edges;
    work_edges(1);
    if (!exact_ball_in_cone(&edges->edge_ball[e], &v->lp->f, &v->edge_cone.cone)) return false;
    dvec3 a = {0}, b = {0};
    int weight = 0;
    for (int i = edges->side_first[e]; i < edges->side_first[e + 1]; i++) {
        int side = edges->side[i], t = side / 3, w = triangle_weight(v->c, v->lp, v->sc, t);
        if (w == 0) continue;
        dvec3 q[3];
        double h[3];
        for (int j = 0; j < 3; j++) { /* exact_clip's corners */
            q[j] = d3_sub(d3_from(v->c->tri[3 * t + j]), v->lp->f.org);
            h[j] = d3_dot(q[j], v->lp->f.c);
        }
        if (!clipped_edge(q, h, side % 3, &a, &b)) continue;
        weight += exact_canonical(&a, &b) ? -w : w;
    }
    if (weight != 0) v->fn(v->user, a, b, weight);
    return false;
}

/* Does triangle t cross the clip plane (corners on both sides)? */
static bool crosses_clip_plane(const vec3 *t, const Frame *f)
{
    int in = 0;
    for (int k = 0; k < 3; k++) in += d3_dot(d3_sub(d3_from(t[k]), f->org), f->c) >= EXACT_CLIP_EPS;
    return in == 1 || in == 2;
}

/* Can ball b come within reach of org? */
static bool near_org(const Ball *b, const void *query)
{
    const SilhouetteVisit *v = query;
    return d3_len(d3_sub(b->centre, v->lp->f.org)) - b->radius <= v->reach;
}

/* The edges along the clip plane of chunk k's visited triangles that cross
 * it, if k reaches the cone and its sphere comes near org: the plane h =
 * EXACT_CLIP_EPS meets the widened cone (half-angle t < pi/2) within
 * EXACT_CLIP_EPS / cos t of org, so a clip edge farther away is outside it
 * (as an edge's sphere, above). */
static bool clip_plane_edges(void *user, int k)
{
    const SilhouetteVisit *v = user;
    const ExactCasters *c = v->c;
    if (!near_org(&c->chunk_ball[k], v) || !chunk_reached(c, v->lp, v->sc, k)) return false;
    for (int t = c->chunk_first[k]; t < c->chunk_first[k + 1]; t++) {
        if (!crosses_clip_plane(&c->tri[3 * t], &v->lp->f)) continue;
        int w = triangle_weight(c, v->lp, v->sc, t);
        if (w == 0) continue;
        dvec3 poly[4];
        int facing, edge_of[4], np = exact_clip(&v->lp->f, &c->tri[3 * t], poly, &facing, edge_of);
        for (int e = 0; e < np; e++)
            if (edge_of[e] < 0) v->fn(v->user, poly[e], poly[(e + 1) % np], w);
    }
    return false;
}

bool exact_scratch_init(ExactScratch *sc, const ExactCasters *c)
{
    size_t chunks = (size_t)c->num_chunks + (size_t)c->num_objects + 1;
    *sc = (ExactScratch){.chunk_stamp = calloc(chunks, sizeof *sc->chunk_stamp),
                         .reached = malloc(chunks),
                         .stamp = calloc((size_t)c->num_tris + 1, sizeof *sc->stamp),
                         .weight = malloc((size_t)c->num_tris + 1)};
    return sc->chunk_stamp && sc->reached && sc->stamp && sc->weight;
}

void exact_scratch_free(ExactScratch *sc)
{
    free(sc->chunk_stamp);
    free(sc->reached);
    free(sc->stamp);
    free(sc->weight);
}

void exact_for_silhouette(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, ExactEdgeFn fn, void *user)
{
    if (++sc->org == 0) { /* stamps wrapped: every cached entry is stale */
        memset(sc->stamp, 0, sizeof *sc->stamp * (size_t)(c->num_tris + 1));
        memset(sc->chunk_stamp, 0, sizeof *sc->chunk_stamp * ((size_t)c->num_chunks + (size_t)c->num_objects + 1));
        sc->org = 1;
    }
    Cone cone = exact_cone(lp->cos_cone, EXACT_EDGE_CONE_MARGIN);
    SilhouetteVisit v = {c, lp, sc, {&lp->f, cone}, cone.cos_t > 0.0 ? 2.0 * EXACT_CLIP_EPS / cone.cos_t + 1e-12 : INFINITY,
                         fn, user};
    exact_tree_query(&c->edges->edge_tree, exact_cone_test, &v.edge_cone, sum_edge, &v);
    exact_tree_query(&c->chunk_tree, near_org, &v, clip_plane_edges, &v);
}
