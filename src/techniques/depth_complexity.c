/* depth_complexity.c -- `depth_complexity`: depth-complexity sampling (Laine
 * et al. 2005, "Soft shadow volumes for ray tracing"; course §5.3.2.3). Per
 * view sample p, a counter per light sample x_i holds the depth complexity
 * D(x_i), the number of caster surfaces the segment p -> x_i crosses, known
 * up to one constant from the silhouette edges alone; one reference ray fixes
 * the constant, and the visibility is the fraction of samples with D = 0.
 *
 * Light samples are the reference's own, projected into the normalised
 * light frame (exact_soft.h); a light sliver above the tangent plane that no
 * sample reaches gets the reference's one ray toward the light's highest
 * point. D changes only where x crosses
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
 * it. With edges=silhouette (exact_for_silhouette, Laine et al. 2005 §4's
 * two stages) only the light's possible silhouette edges that reach the
 * samples' cone are summed, and only those whose sum is not 0 run over the
 * light samples: the same counts as edges=all's every triangle. Stage two
 * descends a sphere tree over the listed edges (the `exact_edges` resource):
 * bunny, 160x120, 256 samples, 35 edges tested per lit candidate where
 * scanning the listed edges of the reached chunks tested 4,260; evaluation
 * 2.03G instructions (callgrind) against the reference's 2.51G for the same
 * rays, 14.67G before the tree. Crossing into a
 * front-facing triangle's projection raises D by 1. A
 * closed caster (silhouette.h) seen from outside its bounding sphere counts
 * its front faces only: D halves there, and is 0 where it was.
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
 * EXACT_AMBIGUOUS_TAN of a projected edge that steps the counts (a silhouette
 * edge from org, or a clipped triangle's edge on the clip plane), and those left out off the frame's axis: there the float ray test and the
 * projected predicate may disagree. On a coloured (textured rect) light the
 * lit samples, those of the least count, weigh by their colours
 * (light_bitmask_visibility, the reference's ratio). */
#include <math.h>
#include <stdlib.h>
#include "techniques/exact_soft.h"

enum { DC_P_EDGES = EXACT_NUM_SAMPLE_PARAMS };
enum { DC_EDGES_SILHOUETTE, DC_EDGES_ALL };
static const char *const dc_edge_names[] = {"silhouette", "all", NULL};

static const ParamDesc dc_params[] = {
    EXACT_SAMPLE_PARAMS(16, 256,
                        "N: depth-complexity counters per view sample (Laine et al. 2005 used 256-1024); the "
                        "reference's --samples gives the same points"),
    {"edges", PARAM_ENUM, DC_EDGES_SILHOUETTE, 0, 1, "",
     "which edges step the counters: silhouette (Laine et al. 2005 §4's two stages: the light's possible "
     "silhouette edges whose spheres reach the samples' cone, summed over their triangles from the view sample, "
     "the sums not 0 stepping) or all (every visited triangle's edges, the brute force): the same visibility bit "
     "for bit; all is ~20x slower on the bunny at 160x120 and its near_edge also counts edges inside a surface",
     dc_edge_names},
};

static const char *const dc_resources[] = {"embree_bvh", "silhouette", "exact_edges", NULL};
static const char *const dc_aux[] = {"near_edge", NULL};

/* Laine's counters for one view sample. */
typedef struct Counters {
    bool silhouette;               /* edges=silhouette: exact_for_silhouette, else every visited triangle's edges */
    ExactScratch scratch;          /* exact_for_silhouette's */
    LightPoints lp;
    P2 r;                          /* the point the counts are relative to */
    int rel[EXACT_MAX_SAMPLES];    /* relative depth complexity */
    bool near[EXACT_MAX_SAMPLES];  /* within EXACT_AMBIGUOUS_TAN of a projected edge that steps them */
} Counters;

/* Signed steps of the edge a -> b (clipped, relative to org) added to every
 * kept sample whose segment from the reference point r crosses its
 * projection, with weight w (the triangle's facing). The predicate runs on
 * the lexicographically smaller endpoint first, so the reversed edge of a
 * neighbour gives exactly the opposite steps. */
static void add_edge(void *user, dvec3 a, dvec3 b, int w)
{
    Counters *k = user;
    const LightPoints *lp = &k->lp;
    if (exact_canonical(&a, &b)) w = -w;
    P2 qa = exact_project(&lp->f, a), qb = exact_project(&lp->f, b);
    if (fmax(qa.x, qb.x) < lp->lo.x || fmin(qa.x, qb.x) > lp->hi.x || fmax(qa.y, qb.y) < lp->lo.y ||
        fmin(qa.y, qb.y) > lp->hi.y)
        return;
    double len = hypot(qb.x - qa.x, qb.y - qa.y);
    bool r_left = exact_orient(qa, qb, k->r) > 0.0;
    for (int i = 0; i < lp->n; i++) {
        if (!lp->above[i]) continue;
        double o = exact_orient(qa, qb, lp->x[i]);
        if (fabs(o) <= EXACT_AMBIGUOUS_TAN * len) {
            double t = ((lp->x[i].x - qa.x) * (qb.x - qa.x) + (lp->x[i].y - qa.y) * (qb.y - qa.y)) / (len * len);
            k->near[i] |= t >= 0.0 && t <= 1.0;
        }
        bool x_left = o > 0.0;
        if (x_left == r_left) continue;
        /* the segment r -> x_i crosses the edge's line; it crosses the edge
         * where qa and qb lie on either side of the segment's line */
        bool a_left = exact_orient(k->r, lp->x[i], qa) > 0.0, b_left = exact_orient(k->r, lp->x[i], qb) > 0.0;
        if (a_left == b_left) continue;
        /* a front-facing triangle (w = +1) projects clockwise in (u, v), its
         * inside on the right of each edge: entering it (left -> right) adds 1 */
        k->rel[i] += x_left ? -w : w;
    }
}

/* On a closed object seen from outside, a segment crosses as many back
 * faces as front faces, so counting the front faces alone (front_only: their
 * region's boundary is the silhouette, each edge stepping once) leaves D = 0
 * exactly where it was: the visibility does not change. */
static void add_triangle(void *user, const vec3 *tri, bool front_only)
{
    dvec3 poly[4];
    int w, np = exact_clip(&((Counters *)user)->lp.f, tri, poly, &w, NULL);
    if (w == 0 || (front_only && w < 0)) return; /* edge-on from org: it blocks no segment */
    for (int k = 0; k < np; k++) add_edge(user, poly[k], poly[(k + 1) % np], w);
}

/* The visibility per channel of the kept samples whose count is the least
 * (the lit ones): light_bitmask_visibility of the others as blocked. */
static void lit_at_least(const Counters *k, int best, int channels, float *out)
{
    const LightPoints *lp = &k->lp;
    uint64_t kept[EXACT_MAX_SAMPLES / 64] = {0}, blocked[EXACT_MAX_SAMPLES / 64] = {0};
    vec3 colour[EXACT_MAX_SAMPLES];
    for (int i = 0; i < lp->n; i++) {
        kept[i / 64] |= (uint64_t)lp->above[i] << (i % 64);
        blocked[i / 64] |= (uint64_t)(k->rel[i] != k->rel[best]) << (i % 64);
        colour[i] = lp->ls[i].vis_weight;
    }
    light_bitmask_visibility(colour, kept, blocked, lp->n, channels, out);
}

static void store_all(float *out, int channels, float v)
{
    for (int c = 0; c < channels; c++) out[c] = v;
}

/* Visibility of one view sample into out[0..channels); *near counts its
 * ambiguous light samples. */
static void sample_visibility(const ExactCasters *cs, const TechContext *ctx, int s, Counters *k, int *near,
                              float *out)
{
    LightPoints *lp = &k->lp;
    *near = 0;
    if (!exact_begin(cs, ctx, s, lp)) { store_all(out, ctx->channels, 1.0f); return; } /* nothing reaches the cone */
    exact_draw(lp, ctx, s);
    if (lp->kept == 0) { store_all(out, ctx->channels, exact_sliver_visibility(cs, ctx, s, lp)); return; }
    int first = 0;
    while (!lp->above[first]) first++;
    k->r = lp->x[first]; /* counters relative to the first kept sample */
    for (int i = 0; i < lp->n; i++) {
        k->rel[i] = 0;
        k->near[i] = false;
    }
    if (k->silhouette) exact_for_silhouette(cs, lp, &k->scratch, add_edge, k);
    else exact_for_casters(cs, lp, add_triangle, k);
    int best = first;
    for (int i = first; i < lp->n; i++)
        if (lp->above[i] && k->rel[i] < k->rel[best]) best = i;
    for (int i = 0; i < lp->n; i++) *near += lp->above[i] && k->near[i];
    *near += lp->off_axis;
    if (exact_occluded(cs, lp->org, &lp->ls[best])) store_all(out, ctx->channels, 0.0f); /* least count >= 1 */
    else lit_at_least(k, best, ctx->channels, out); /* a sample is lit where its count is the least, 0 */
}

static bool dc_prepare(const TechContext *ctx, void **state, Error *err)
{
    ExactCasters *cs = malloc(sizeof *cs);
    if (!cs) return error_set(err, "out of memory");
    if (!exact_casters_init(ctx, ctx->params[DC_P_EDGES] == DC_EDGES_SILHOUETTE, cs, err)) {
        free(cs);
        return false;
    }
    *state = cs;
    return true;
}

static void dc_release(void *state)
{
    if (state) exact_casters_free(state);
    free(state);
}

static void dc_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const ExactCasters *cs = state;
    Counters *k = malloc(sizeof *k);
    if (k) k->silhouette = ctx->params[DC_P_EDGES] == DC_EDGES_SILHOUETTE;
    if (k && !exact_scratch_init(&k->scratch, cs)) {
        exact_scratch_free(&k->scratch);
        free(k);
        k = NULL;
    }
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        int near = 0;
        if (k) sample_visibility(cs, ctx, s, k, &near, out + (size_t)(s - begin) * (size_t)ctx->channels);
        else tech_store(ctx, out, begin, s, NAN); /* out of memory: no value */
        if (ctx->aux) ctx->aux[s] = (float)near;
    }
    if (k) exact_scratch_free(&k->scratch);
    free(k);
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
    .rgb = true,
    .lights = LIGHTS_AREA,
    .main_param = "samples",
    .prepare = dc_prepare,
    .evaluate = dc_evaluate,
    .release = dc_release,
    .aux = dc_aux,
};
