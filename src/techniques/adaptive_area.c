/* adaptive_area.c -- `adaptive_area`: Chun & Oh's soft shadow mapping for
 * rectangular lights of any shape and colour (seed 001 §3). A depth map from
 * the light's centre; per receiver the filter region is the cone from the
 * receiver to the light's four corners cut at the nearest possible blocker
 * (search_depth), refined to the plane of the average blocker depth found
 * there; the region's mean
 * visibility E and variance V = E - E^2 (Eq. 1) decide a quad-tree split
 * (V above the threshold, or the light image's colour variance over that
 * part of the light above its own threshold, never in umbra or full light),
 * down to max_level (the paper: 2, 4 x 4 sub-regions); each leaf's
 * visibility times the mean colour of the corresponding part of the light
 * image, averaged over the light (Fig. 3). The level reached is the aux
 * channel `level` (Table 2, Fig. 2). */
#include <stdlib.h>
#include "resources/maps/prefilter.h"
#include "resources/maps/lightimage.h"
#include "techniques/smap.h"

enum { P_THRESHOLD = SMAP_NUM_PARAMS, P_MAX_LEVEL, P_COLOR_THRESHOLD, P_FIXED, P_TAPS, P_SEARCH_TAPS };

#define AA_MAX_LEVEL 4
#define AA_MAX_TAPS 16
#define AA_MAX_SEARCH_TAPS 32
/* Nodes of a full quad tree down to AA_MAX_LEVEL: (4^(L+1) - 1) / 3. */
#define AA_MAX_NODES 341
/* Cuts of the search cone at the nearest possible blocker (search_depth). */
#define AA_SEARCH_REFINEMENTS 3

/* Plain perspective maps along the light's normal (light_axes): no warps or
 * face splits; auto is perspective for its rect lights, so projection has
 * the one value auto and is not offered (registry.h). */
static const ParamDesc aa_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_AUTO, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    {"threshold", PARAM_FLOAT, 0.2244, 0, 0.25, "",
     "visibility variance E - E^2 above which a region splits into 4 (seed 001 §3: 0.2244; Fig. 2: 0.10, 0.22, 0.24)",
     NULL},
    {"max_level", PARAM_INT, 2, 0, AA_MAX_LEVEL, "levels",
     "deepest subdivision: level L has 2^L x 2^L sub-regions (the paper stops at 2: 4 x 4)", NULL},
    {"color_threshold", PARAM_FLOAT, 0.01, 0, 0.25, "x peak^2",
     "colour variance of the light image over a region's part of the light (mean of R, G, B, in units of the "
     "image's peak squared) above which a penumbra region splits even when its visibility varies little",
     NULL},
    {"fixed", PARAM_BOOL, 0, 0, 1, "",
     "split every region down to max_level, thresholds ignored (Table 1's 'Fixed' rows)", NULL},
    {"taps", PARAM_INT, 4, 1, AA_MAX_TAPS, "taps per side",
     "shadow tests per region and level: taps x taps points on a regular grid over the region", NULL},
    {"search_taps", PARAM_INT, 8, 1, AA_MAX_SEARCH_TAPS, "taps per side",
     "blocker-search tests: search_taps x search_taps points over the cone's region at the nearest possible blocker",
     NULL},
};

/* Subdivision stops at max_level; fixed splits every region, thresholds unread. */
static const ParamCondition aa_conditions[] = {
    {"threshold", "fixed=false and max_level!=0"},
    {"color_threshold", "fixed=false and max_level!=0"},
    {"fixed", "max_level!=0"},
    {NULL, NULL},
};

static const char *const aa_resources[] = {"shadow_map", "minmax_pyramid", "light_image_sat", "view_samples", NULL};
/* level: the deepest subdivision reached (Table 2, Fig. 2); tests: the
 * shadow-map tests the sample took (search and regions), the work that
 * Table 1's frame rates measure, independent of the machine's load. */
static const char *const aa_aux[] = {"level", "tests", NULL};

/* Per map face: the light's width and height vectors in texel units per
 * unit of k = 1/z - 1/z_p (seed 001 §3's cone: a light point q maps through
 * the receiver onto the plane at depth z at tangent T_p + q_view.xy k), and
 * the face's near plane (world units). */
typedef struct FaceAxes {
    double right_s, right_t, up_s, up_t;
    double near_depth;
} FaceAxes;

typedef struct AaState {
    const ShadowMap *map;
    const MinMaxPyramid *pyramid;
    SmapBias bias;
    double threshold, color_threshold;
    int max_level, taps, search_taps;
    bool fixed;
    FaceAxes face[LIGHTVIEW_MAX_FACES];
    /* Per quad-tree node (level L, cell x, y at index (4^L - 1)/3 + y 2^L + x):
     * the mean colour of its part of the light and its colour variance. */
    float node_color[AA_MAX_NODES][3];
    float node_variance[AA_MAX_NODES];
    float light_color[3];           /* the whole light's mean (node 0) */
} AaState;

static int node_index(int level, int x, int y) { return ((1 << (2 * level)) - 1) / 3 + (y << level) + x; }

/* Mean colours and colour variances of every node: from the emission image's
 * tables for textured lights, white and uniform otherwise. */
static bool node_colors(const TechContext *ctx, AaState *st, Error *err)
{
    const LightImageSat *sat = NULL;
    if (ctx->light->kind == LIGHT_TEXTURED_RECT) {
        sat = res_light_image_sat(ctx->rm, ctx->scene, ctx->light_index, err);
        if (!sat) return false;
    }
    for (int level = 0; level <= st->max_level; level++) {
        int n = 1 << level;
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                int k = node_index(level, x, y);
                double mean[3] = {1, 1, 1}, var = 0.0;
                if (sat) light_image_box(sat, (double)x / n, (double)(x + 1) / n, (double)y / n, (double)(y + 1) / n, mean, &var);
                for (int c = 0; c < 3; c++) st->node_color[k][c] = (float)mean[c];
                st->node_variance[k] = (float)var;
            }
    }
    for (int c = 0; c < 3; c++) st->light_color[c] = st->node_color[0][c];
    return true;
}

/* The light's edges in each face's texel units per unit k (see FaceAxes).
 * Every face must be a plain perspective frustum from the light's centre
 * looking along its normal (one map, or cascades of it): then the light lies
 * in the plane of depth 0 and its back-projections are affine in (u, v). */
static bool light_axes(const TechContext *ctx, AaState *st, Error *err)
{
    const LightView *lv = &st->map->view;
    const Light *l = ctx->light;
    dvec3 c = d3_from(l->position), right = d3_from(v3_cross(l->up, l->direction)), up = d3_from(l->up);
    for (int k = 0; k < lv->num_faces; k++) {
        const MapFace *f = &lv->face[k];
        bool plain = lv->projection == MAP_PROJ_PERSPECTIVE && f->perspective && f->warp == MAP_WARP_NONE &&
                     d3_dot(f->axis_world, d3_from(l->direction)) > 1.0 - 1e-6; /* float normals */
        if (!plain)
            return error_set(err, "the filter region is the light's cone on perspective maps looking along the "
                                  "light's normal; projection %s is not one (use auto or perspective)",
                             map_projection_name(lv->projection));
        dvec4 r_view = m4_apply(&f->view_from_world, d3_madd(c, right, l->width));
        dvec4 u_view = m4_apply(&f->view_from_world, d3_madd(c, up, l->height));
        double s_per_tan = lv->res / (f->r - f->l), t_per_tan = lv->res / (f->t - f->b);
        st->face[k] = (FaceAxes){r_view.x * s_per_tan, r_view.y * t_per_tan, u_view.x * s_per_tan,
                                 u_view.y * t_per_tan, f->raster.depth_near};
    }
    return true;
}

static bool aa_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    AaState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    st->map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    st->bias = smap_bias(p, ctx->scene);
    st->threshold = p[P_THRESHOLD];
    st->color_threshold = p[P_COLOR_THRESHOLD];
    st->max_level = (int)p[P_MAX_LEVEL];
    st->fixed = p[P_FIXED] != 0.0;
    st->taps = (int)p[P_TAPS];
    st->search_taps = (int)p[P_SEARCH_TAPS];
    if (st->map) st->pyramid = res_minmax_pyramid(ctx->rm, st->map, err);
    if (!st->pyramid || !light_axes(ctx, st, err) || !node_colors(ctx, st, err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* One receiver's region: the light's (u, v) square mapped to texels at k. */
typedef struct Region {
    const AaState *st;
    const SmapReceiver *r;
    const FaceAxes *ax; /* of the receiver's face */
    double k;
} Region;

/* Texel of light point (u, v) through the region; false outside the map. */
static bool region_texel(const Region *g, double u, double v, int *i, int *j)
{
    const FaceAxes *a = g->ax;
    double du = (u - 0.5) * g->k, dv = (v - 0.5) * g->k;
    double s = g->r->mc.s + du * a->right_s + dv * a->up_s, t = g->r->mc.t + du * a->right_t + dv * a->up_t;
    *i = (int)floor(s);
    *j = (int)floor(t);
    return *i >= 0 && *j >= 0 && *i < g->st->map->res && *j < g->st->map->res;
}

/* The depth where the blocker search cuts the cone (seed 001 §3: "the
 * intersection [of the cone] on the shadow map is the initial filter area").
 * Cut at the map's near plane the cone is needlessly wide wherever the near
 * plane lies far in front of the casters (a ground plane reaching toward
 * the light), so it is cut again at the nearest caster inside its bounding
 * box, read from the min-max pyramid (resources/maps/prefilter.h), a few times (course §5.2.3.4's
 * search area refined through z_min, Fig. 5.9): no blocker can lie in front
 * of that plane, so the region stays conservative. 0: nothing in front of
 * the receiver, lit. */
static double search_depth(const AaState *st, const SmapReceiver *r, double z_receiver)
{
    int face = r->mc.face;
    const FaceAxes *a = &st->face[face];
    double z = a->near_depth;
    for (int it = 0; it < AA_SEARCH_REFINEMENTS; it++) {
        double k = 1.0 / z - 1.0 / z_receiver;
        double hs = 0.5 * k * (fabs(a->right_s) + fabs(a->up_s)), ht = 0.5 * k * (fabs(a->right_t) + fabs(a->up_t));
        float lo, hi;
        minmax_query(st->pyramid, face, (int)floor(r->mc.s - hs), (int)floor(r->mc.t - ht), (int)floor(r->mc.s + hs),
                     (int)floor(r->mc.t + ht), &lo, &hi);
        double z_min = smap_linear_depth(st->map, face, lo);
        if (isnan(z_min)) return NAN; /* a NaN texel in the box: where blockers lie is unknown */
        if (!(z_min < z_receiver)) return 0.0;
        if (!(z_min > z)) break;
        z = z_min;
    }
    return z;
}

/* Average linear depth of the blockers the search taps find over the cone's
 * region at the search depth (seed 001 §3, after Annen et al.); 0 when none,
 * NaN when a NaN depth was read. */
static double average_blocker_depth(const AaState *st, const SmapReceiver *r, double z_receiver, int *tests)
{
    double z_search = search_depth(st, r, z_receiver);
    if (isnan(z_search)) return NAN;
    if (!(z_search > 0.0)) return 0.0;
    *tests = st->search_taps * st->search_taps;
    Region g = {st, r, &st->face[r->mc.face], 1.0 / z_search - 1.0 / z_receiver};
    int n = st->search_taps, found = 0;
    double sum = 0.0;
    for (int b = 0; b < n; b++)
        for (int a = 0; a < n; a++) {
            int i, j;
            float lit = region_texel(&g, (a + 0.5) / n, (b + 0.5) / n, &i, &j) ? smap_lit(st->map, r, i, j) : 1.0f;
            if (lit == 1.0f) continue;
            sum += isnan(lit) ? NAN : smap_linear_depth(st->map, r->mc.face, shadowmap_texel(st->map, r->mc.face, i, j));
            found++;
        }
    return found ? sum / found : 0.0;
}

/* Mean visibility E of the node at (x, y) of `level`: taps x taps tests. */
static double node_visibility(const Region *g, int level, int x, int y)
{
    int n = g->st->taps;
    double size = 1.0 / (1 << level), lit = 0.0;
    for (int b = 0; b < n; b++)
        for (int a = 0; a < n; a++) {
            int i, j;
            double u = (x + (a + 0.5) / n) * size, v = (y + (b + 0.5) / n) * size;
            lit += region_texel(g, u, v, &i, &j) ? smap_lit(g->st->map, g->r, i, j) : 1.0f;
        }
    return lit / (n * n);
}

/* Seed 001 §3: never split umbra or full light (V = 0: the product with the
 * light image is then exact at any level); split when the visibility varies
 * (V = E - E^2 above the threshold) or the light's part varies in colour. */
static bool should_split(const AaState *st, int level, int node, double e)
{
    if (level >= st->max_level) return false;
    if (st->fixed) return true;
    double v = e - e * e;
    return v > 0.0 && (v > st->threshold || st->node_variance[node] > st->color_threshold);
}

/* The quad tree, depth first: accumulate leaf area x E x leaf colour into
 * sum[3]; returns the deepest level reached, and the nodes tested. */
static int subdivide(const Region *g, double sum[3], int *nodes)
{
    const AaState *st = g->st;
    int stack[3 * (3 * AA_MAX_LEVEL + 1)], top = 0, deepest = 0;
    *nodes = 0;
    stack[top++] = 0; stack[top++] = 0; stack[top++] = 0; /* level, x, y */
    while (top > 0) {
        int y = stack[--top], x = stack[--top], level = stack[--top];
        int node = node_index(level, x, y);
        double e = node_visibility(g, level, x, y);
        (*nodes)++;
        if (should_split(st, level, node, e)) {
            for (int c = 3; c >= 0; c--) {
                stack[top++] = level + 1;
                stack[top++] = 2 * x + (c & 1);
                stack[top++] = 2 * y + (c >> 1);
            }
            continue;
        }
        double area = 1.0 / (double)(1 << (2 * level));
        for (int c = 0; c < 3; c++) sum[c] += area * e * st->node_color[node][c];
        if (level > deepest) deepest = level;
    }
    return deepest;
}

/* Visibility of one receiver per channel (out[0..channels)); the level
 * reached, and the shadow tests taken into *tests. */
static int shade_receiver(const AaState *st, const SmapReceiver *r, int channels, float *out, int *tests)
{
    for (int c = 0; c < channels; c++) out[c] = 1.0f;
    *tests = 0;
    double z_p = r->mc.depth_linear;
    if (!(z_p > 0.0)) return 0;
    double z_avg = average_blocker_depth(st, r, z_p, tests);
    if (isnan(z_avg)) { /* unknown blockers: no region to split, the visibility is unknown */
        for (int c = 0; c < channels; c++) out[c] = NAN;
        return 0;
    }
    if (!(z_avg > 0.0)) return 0; /* no blocker in the cone: lit */
    /* The plane of the average blocker: z_avg >= near > 0 and z_avg < z_p
     * (blockers lie in front of the biased receiver), so k >= 0; k -> 0 at
     * contact, where the region shrinks to the receiver's own texel. */
    Region g = {st, r, &st->face[r->mc.face], fmax(1.0 / z_avg - 1.0 / z_p, 0.0)};
    double sum[3] = {0, 0, 0};
    int nodes, level = subdivide(&g, sum, &nodes);
    *tests += nodes * st->taps * st->taps;
    for (int c = 0; c < channels; c++) /* a channel the light does not emit has nothing to block */
        out[c] = st->light_color[c] > 0.0f ? (float)nan_clamp(sum[c] / st->light_color[c], 0.0, 1.0) : 1.0f;
    return level;
}

static void aa_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const AaState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float *o = out + (size_t)(s - begin) * (size_t)ctx->channels;
        SmapReceiver r;
        int level = 0, tests = 0;
        if (smap_receiver(st->map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            level = shade_receiver(st, &r, ctx->channels, o, &tests);
        else
            tech_store(ctx, out, begin, s, 1.0f); /* outside the map nothing is known to block: lit */
        if (ctx->aux) {
            ctx->aux[2 * (size_t)s] = (float)level;
            ctx->aux[2 * (size_t)s + 1] = (float)tests;
        }
    }
}

const Technique tech_adaptive_area = {
    .name = "adaptive_area",
    .family = "soft",
    .source = "seed 001 §3 (Chun & Oh 2016: Eq. 1, Figs. 2-4)",
    .summary = "filter region from the light's cone and average blocker depth, quad-tree split by visibility and "
               "light-colour variance, sub-regions times the light image",
    .params = aa_params,
    .num_params = (int)(sizeof aa_params / sizeof aa_params[0]),
    .resources = aa_resources,
    .rgb = true,
    .lights = LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_TEXTURED_RECT),
    .main_param = "threshold",
    .conditions = aa_conditions,
    .prepare = aa_prepare,
    .evaluate = aa_evaluate,
    .release = free,
    .aux = aa_aux,
};
