/* exact_soft.h -- what the exact soft-shadow techniques share
 * (`depth_complexity`, Laine et al. 2005; `view_sample_mapping`, Eisemann &
 * Décoret 2007 / Sintorn et al. 2008; course §5.3.2.3, §5.3.3): the
 * reference's own light samples for a view sample (rt/reference.c: same
 * pattern, seed, count and stream, mapped by light_sample, rays from p lifted
 * by rt_ray_offset along the geometric normal, samples on or below the
 * geometric tangent plane left out), their projection into the normalised
 * light frame of that sample, and the caster triangles grouped under
 * bounding spheres, culled against the cone from the sample to the light.
 *
 * The normalised light frame: each direction d from the ray origin `org`
 * maps to the gnomonic plane of the axis c toward the light's centre,
 * x(d) = (d.u / d.c, d.v / d.c) with (u, v, c) right-handed and orthonormal;
 * segments and triangles stay straight there. Geometry is clipped to
 * d.c >= EXACT_CLIP_EPS first: the part behind org's plane perpendicular to
 * c blocks no segment toward a light sample (every kept sample has d.c > 0;
 * one that has not is left out and counted, `off_axis`). */
#ifndef SL_EXACT_SOFT_H
#define SL_EXACT_SOFT_H
#include <stdint.h>
#include "core/mat4.h"
#include "core/sampling.h"
#include "rt/rt.h"
#include "scene/light.h"
#include "techniques/technique.h"

#define EXACT_MAX_SAMPLES 1024
#define EXACT_CLIP_EPS 1e-9      /* world units along c: the clip plane just in front of org */
#define EXACT_AMBIGUOUS_TAN 1e-5 /* normalised-frame distance (~radians near the axis) counted as on an edge */
#define EXACT_CHUNK 32           /* triangles per bounding sphere */

/* The parameters both techniques start with (the reference's sampling). */
enum { EXACT_P_SAMPLES, EXACT_P_PATTERN, EXACT_P_SEED, EXACT_P_SAMPLE_SET, EXACT_NUM_SAMPLE_PARAMS };
enum { EXACT_SET_PER_VIEW_SAMPLE, EXACT_SET_SHARED }; /* sample_set: ReferenceParams.shared_set */
extern const char *const exact_pattern_names[];
extern const char *const exact_sample_set_names[];
#define EXACT_SAMPLE_PARAMS(min_samples, def_samples, samples_doc)                                                  \
    {"samples", PARAM_INT, def_samples, min_samples, EXACT_MAX_SAMPLES, "light samples", samples_doc, NULL},         \
        {"pattern", PARAM_ENUM, SAMPLING_R2, 0, 2, "",                                                              \
         "the light samples' 2D pattern, the reference's own (--pattern): r2, stratified (N a square) or random",  \
         exact_pattern_names},                                                                                      \
        {"seed", PARAM_INT, 1, 0, 2147483647, "",                                                                   \
         "the light samples' seed, the reference's own (--seed): with the same N, pattern and seed the samples "   \
         "are the reference's rays",                                                                                \
         NULL},                                                                                                     \
        {"sample_set", PARAM_ENUM, EXACT_SET_PER_VIEW_SAMPLE, 0, 1, "",                                             \
         "per_view_sample (each view sample its own stream) or shared (one set for the frame: the same points on "  \
         "a rect or disk light for every view sample), the reference's own (--sample-set)",                         \
         exact_sample_set_names}

typedef struct Ball {
    dvec3 centre; /* world space */
    double radius;
} Ball;

/* A bounding-sphere hierarchy over items (edges, chunks): node 0 the root;
 * an inner node's children are the next node and node `first`, a leaf's
 * items item[first .. first + count). Each node's sphere holds its
 * children's with a margin (exact_soft.c), so a cone or distance test that
 * passes an item passes every node above it, in floating point too. */
typedef struct BallNode {
    Ball ball;
    int first, count; /* count 0: inner */
} BallNode;

typedef struct BallTree {
    int num_nodes;
    BallNode *node;
    int *item;
} BallTree;
#define EXACT_TREE_DEPTH 96 /* deepest node + 1 (exact_soft.c's build bounds it) */

/* The possible silhouette edges of the light's ball (exact_for_silhouette,
 * stage one): undirected edges of the welded casters (equal positions, -0 =
 * +0, across objects) that can be a silhouette from some light point, each
 * with its sides (3 t + k for each triangle t that traverses it from corner
 * k to k + 1, in triangle order) and its sphere, under a sphere hierarchy
 * (Laine et al. 2005 §4 bin them in a hemicube about the light; Lehtinen et
 * al. 2006's 3D tree is the hierarchy used here, see exact_soft.c). */
typedef struct ExactEdges {
    int num_welded;    /* every welded edge */
    int num_listed;    /* the possible silhouette edges */
    int *side_first;   /* per listed edge: its first side in side; num_listed + 1 */
    int *side;
    Ball *edge_ball;
    BallTree edge_tree;
} ExactEdges;

/* Caster triangles in chunks of at most EXACT_CHUNK, each within one object. */
typedef struct ExactCasters {
    RTCScene rtc;      /* the casters' BVH: the techniques' one ray */
    float extent;      /* scene_extent, for rt_ray_offset */
    int num_tris, num_chunks, num_objects;
    vec3 *tri;         /* world space, 3 corners each */
    int *chunk_first;  /* per chunk: its first triangle; num_chunks + 1 */
    Ball *chunk_ball;
    int *object_first; /* per caster object: its first chunk; num_objects + 1 */
    Ball *object_ball;
    bool *object_closed; /* a closed 2-manifold (resources/geometry/silhouette.h's adjacency) */
    int *tri_chunk;      /* per triangle: its chunk */
    dvec3 *tri_normal;   /* per triangle: (t1 - t0) x (t2 - t0), world */
    int8_t *tri_light_side; /* per triangle: which side of its plane the light's ball lies on (exact_soft.c) */
    int *chunk_object;   /* per chunk: its object */
    BallTree chunk_tree; /* over chunk_ball: exact_begin's cull, the clip plane's edges near org */
    const struct ExactEdges *edges; /* exact_for_silhouette's, a resource of the light; NULL unless asked for */
} ExactCasters;

/* Checks the sample parameters, acquires the casters' BVH and their
 * silhouette resource (for each object's closedness) and gathers them, with
 * the possible silhouette edges of exact_for_silhouette if `edges`. */
bool exact_casters_init(const TechContext *ctx, bool edges, ExactCasters *c, Error *err);
void exact_casters_free(ExactCasters *c);

/* The normalised light frame at org. */
typedef struct Frame {
    dvec3 org, u, v, c;
} Frame;

typedef struct P2 {
    double x, y;
} P2;

static inline P2 exact_project(const Frame *f, dvec3 d)
{
    double dc = d3_dot(d, f->c);
    return (P2){d3_dot(d, f->u) / dc, d3_dot(d, f->v) / dc};
}

/* Twice the signed area of (a, b, p): > 0 with p left of a -> b. */
static inline double exact_orient(P2 a, P2 b, P2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

/* A cone about the frame's c from org: its half-angle t's cosine and sine. */
typedef struct Cone {
    double cos_t, sin_t;
} Cone;
#define EXACT_CONE_MARGIN 1e-9 /* radians the casters' culls widen a cone by */
/* The samples' cone widened by this many radians, for the edges' spheres
 * (exact_for_silhouette): an edge outside it crosses no segment between two
 * kept samples' projections (they lie in the cone, which is convex) and is
 * farther than EXACT_AMBIGUOUS_TAN from every sample, so leaving it out
 * changes neither the counts nor near_edge. */
#define EXACT_EDGE_CONE_MARGIN 1e-4
/* The cone of half-angle acos(cos_cone) + margin (at most pi). */
Cone exact_cone(double cos_cone, double margin);

/* One view sample's light samples. */
typedef struct LightPoints {
    vec3 org;                          /* ray origin, world */
    Frame f;
    Ball light;                        /* the light's bounding sphere */
    int n, kept, off_axis;             /* drawn; above the tangent plane; of those left out with d.c <= 0 */
    P2 x[EXACT_MAX_SAMPLES];           /* kept samples' projections */
    LightSample ls[EXACT_MAX_SAMPLES];
    bool above[EXACT_MAX_SAMPLES];     /* kept */
    P2 lo, hi;                         /* bounds of the kept projections */
    double cos_cone;                   /* the kept directions' least cosine to c */
    Cone cone;                         /* theirs, widened by EXACT_CONE_MARGIN: the casters' culls */
} LightPoints;

/* The frame and the light's bounding sphere for view sample s; false when
 * no caster can reach the light's cone from it (every ray is unblocked). */
bool exact_begin(const ExactCasters *c, const TechContext *ctx, int s, LightPoints *lp);
/* The reference's samples for view sample s (after exact_begin). */
void exact_draw(LightPoints *lp, const TechContext *ctx, int s);

/* The reference's one ray, occluded or not (rt/reference.c aim_lane). */
bool exact_occluded(const ExactCasters *c, vec3 org, const LightSample *ls);
/* A sliver above the horizon no sample reaches: the reference's ray toward
 * the light's highest point. */
float exact_sliver_visibility(const ExactCasters *c, const TechContext *ctx, int s, const LightPoints *lp);

/* Calls fn for every caster triangle that can block a segment from org to a
 * kept sample (the chunks' spheres against the samples' cone, the plane of
 * each triangle against org and the light), with front_only set where its
 * object's back faces may be skipped (exact_front_faces_suffice). */
typedef void (*ExactTriangleFn)(void *user, const vec3 *tri, bool front_only);
void exact_for_casters(const ExactCasters *c, const LightPoints *lp, ExactTriangleFn fn, void *user);
/* The same tests one at a time: can caster object o or chunk k reach the
 * samples' cone, can triangle t block a segment toward the light at all? */
bool exact_object_reaches(const ExactCasters *c, int o, const LightPoints *lp);
bool exact_chunk_reaches(const ExactCasters *c, int k, const LightPoints *lp);
bool exact_triangle_reaches(const ExactCasters *c, int t, const LightPoints *lp);
/* May object o's back faces (from org) be skipped? On a closed object with
 * org outside its bounding sphere, a segment that crosses a back face
 * crossed a front face first. */
bool exact_front_faces_suffice(const ExactCasters *c, int o, const LightPoints *lp);

/* Triangle t (world) relative to org, clipped to d.c >= EXACT_CLIP_EPS
 * (Sutherland-Hodgman; each crossing point computed from the edge's inside
 * corner, so both triangles of an edge clip it alike): up to 4 corners, 0
 * when nothing is left. *facing: +1 front-facing from org, -1 back-facing,
 * 0 edge-on. */
int exact_clip(const Frame *f, const vec3 *t, dvec3 poly[4], int *facing, int edge_of[4]);

/* The lexicographic order of an edge's endpoints (relative to org) that the
 * crossing predicates run on, so the two triangles of an edge evaluate them
 * alike: true when a -> b had to be swapped into it. */
static inline bool exact_canonical(dvec3 *a, dvec3 *b)
{
    bool swap = a->x > b->x || (a->x == b->x && (a->y > b->y || (a->y == b->y && a->z > b->z)));
    if (swap) {
        dvec3 t = *a;
        *a = *b;
        *b = t;
    }
    return swap;
}

/* The edges that step a depth-complexity count from org (Laine et al.
 * 2005 §4, "Soft shadow volumes for ray tracing": the silhouette edges from
 * the point to be shaded that overlap the light, found in two stages). Stage
 * one, once per light (the `exact_edges` resource, ExactEdges): the possible
 * silhouette edges of the light's bounding ball, every edge except a
 * consistently oriented edge of two triangles that both have the whole ball
 * strictly on one side and the same side (then from no light point is it a
 * silhouette), each with its bounding sphere, under a sphere hierarchy. An
 * edge's wedge holds org iff the edge meets the cone from org to the light,
 * so stage two, per org, descends the hierarchy with that cone (the samples'
 * cone widened by EXACT_EDGE_CONE_MARGIN, so neither the counts nor near_edge lose
 * anything) and tests the spheres of the edges it reaches (work.edges counts
 * them); each edge whose sphere reaches the cone is summed over its
 * triangles as exact_for_casters visits them (culling, facing from org,
 * front_only, the clip to d.c >= EXACT_CLIP_EPS from the inside corner,
 * canonical order), and fn called with the sum where it is not 0; also fn
 * for each visited clipped triangle's edge along the clip plane (its own),
 * for the chunks the second hierarchy finds near org. An edge left out in
 * stage one never crosses a
 * segment between two light samples' projections: from org it is no
 * silhouette (both triangles culled, or cancelling), or one of its planes
 * has org and the light strictly on one side, so no line from org through
 * the edge meets the light before it (geometry beyond the light, which the
 * techniques assume away, is the exception). So the counts are those of
 * visiting every triangle's edges, bit for bit (tests/unit/test_exact_soft.c). */
typedef void (*ExactEdgeFn)(void *user, dvec3 a, dvec3 b, int weight);

/* One thread's scratch for exact_for_silhouette: 9 bytes per caster
 * triangle. Each entry holds for the org whose stamp it carries. */
typedef struct ExactScratch {
    uint32_t org;            /* the current org's stamp */
    uint32_t *chunk_stamp;   /* per chunk, then per object */
    uint8_t *reached;        /* per chunk: it reaches the cone; per object: 0 no, 1 yes, 2 yes and front faces suffice */
    uint32_t *stamp;         /* per triangle: the org its weight was found for */
    int8_t *weight;          /* per triangle: its weight from that org */
} ExactScratch;

bool exact_scratch_init(ExactScratch *sc, const ExactCasters *c);
void exact_scratch_free(ExactScratch *sc);
void exact_for_silhouette(const ExactCasters *c, const LightPoints *lp, ExactScratch *sc, ExactEdgeFn fn, void *user);

/* Does ball b meet the cone about f->c of half-angle cone from f->org? */
bool exact_ball_in_cone(const Ball *b, const Frame *f, const Cone *cone);
/* Calls fn with each item of t whose node path passes `in` (a test that
 * passes a node whenever it passes a sphere inside it): a superset of the
 * items whose own sphere passes. */
typedef bool (*BallTestFn)(const Ball *b, const void *query);
/* An item found; true stops the query, which then returns true. */
typedef bool (*BallItemFn)(void *user, int item);
bool exact_tree_query(const BallTree *t, BallTestFn in, const void *query, BallItemFn fn, void *user);
/* The cone test as a BallTestFn: query is an ExactConeQuery. */
typedef struct ExactConeQuery {
    const Frame *f;
    Cone cone;
} ExactConeQuery;
bool exact_cone_test(const Ball *b, const void *query);

#endif
