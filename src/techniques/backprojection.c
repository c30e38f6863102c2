/* backprojection.c -- `backprojection`: soft shadow mapping by
 * backprojection (Guennebaud et al. 2006; Bavoil & Silva 2006; course
 * §5.2.3.1-3) with occlusion bitmasks (Schwarz & Stamminger 2007, course
 * §5.2.3.2). One shadow map from the light's centre. For a receiver p:
 *  1. the search area: the light's footprint on the near plane, narrowed
 *     through the min-max pyramid's z_min (course Fig. 5.9,
 *     backproject_search), read at the finest pyramid level whose window
 *     is at most `budget` lexels a side (course §5.2.3.5: a coarser level's
 *     min channel; aux `level`);
 *  2. every lexel of it that passes the shadow test (its closest texel
 *     lies in front of p) is an occluder sample, turned into a polygon:
 *       micropatch  the lexel's square at its depth (a rectangle parallel to
 *                   the near plane, course §5.2.3.1), its left and bottom
 *                   edges extended to meet its neighbours' (Guennebaud 2006)
 *                   and, optionally, its bottom-left corner to its diagonal
 *                   neighbour's (Bavoil 2008): gap filling (§5.2.3.3);
 *       microquad   the quad of the unprojected centres of 2 x 2 lexels,
 *                   used only when all four pass (§5.2.3.3);
 *       microtri    the same quad, or the triangle of three of the four;
 *       contour     (Guennebaud et al. 2007) the outline of the blocking
 *                   lexels, one closed loop per connected region, from a
 *                   16-case edge table (contour_visibility);
 *     and projected back from p onto the light's plane
 *     (backproject_light_scale, L = k (x - u));
 *  3. accumulated over the light's N samples (4 tiles^2 on the RGSS
 *     tiling, backproject_light_sample): bitmask = the union of the
 *     samples each polygon covers, V = 1 - popcount / N, per channel the
 *     unset samples' colours over all samples' on a textured light
 *     (light_bitmask_visibility; accumulate=area, which cannot say which
 *     samples are covered, refuses it) (§5.2.3.2, fusion
 *     exact up to the sample count); area = each polygon's covered share
 *     summed, V = 1 - min(1, sum) (§5.2.3.1's summed areas, measured by the
 *     same samples: over-occludes where polygons overlap); contour's loops
 *     take the bitmask by the crossing parity of their edges and the area
 *     exactly, by Green's theorem (radial_area.h).
 * With layers = 1 only casters seen from the light's centre exist (course
 * Fig. 1.8); layers = N adds the map's depth-peeled layers 1 .. N - 1
 * (resources/maps/peeled.h: the k-th surface from the centre per texel),
 * each layer's occluders built and projected as above and accumulated with
 * the others' (bitmask: united, so a caster seen in two layers counts once;
 * area: summed, over-occluding more). The light is the scene's (sphere:
 * its central cross-section).
 *
 * The multiscale variants of course §5.2.3.4-5 run the same loop on other
 * min-max structures, which give the search area's bounds and the coarse
 * lexels the texel budget reads:
 *   hsm   (Guennebaud et al. 2006) the min-max mip pyramid: bounds from the
 *         finest level whose nodes cover the area with at most 2 x 2;
 *         coarse lexels are the pyramid's aligned nodes;
 *   mssm  (Schwarz & Stamminger 2008) level i the min-max over the 2^i x 2^i
 *         window at every texel, full resolution (res_minmax_levels): exact
 *         bounds from 4 windows; coarse lexels are windows centred on the
 *         receiver's texel, so they move with it (no quadtree seams);
 *   ysm   the pyramid's first n levels, then an MSSM built on level n - 1.
 * Each adds to `backprojection`'s lit early out an umbra early out, stated
 * exactly (course §5.2.3.4 writes "z_p > z_max -> umbra"): the maximum
 * stored depth over the whole search area lies in front of the smallest
 * shadow-test reference over it, i.e. every texel of the area passes the
 * test. Every ray from p to the light leaves the area's pyramid only
 * nearer the light than the plane z_b, where no caster is; the casters
 * seen from the centre over the area, all in front of p, then form a
 * height field that each such ray must cross. Aux `class` records which
 * path a receiver took (0 lit early out, 1 umbra early out, 2
 * backprojected); `blend` mixes two budget levels. */
#include <stdlib.h>
#include "core/counters.h"
#include "core/nanmath.h"
#include "resources/maps/peeled.h"
#include "techniques/backproject.h"
#include "techniques/radial_area.h"

enum { OCC_MICROPATCH, OCC_MICROQUAD, OCC_MICROTRI, OCC_CONTOUR };
static const char *const occluder_names[] = {"micropatch", "microquad", "microtri", "contour", NULL};
enum { GAPS_NONE, GAPS_GUENNEBAUD, GAPS_DIAGONAL };
static const char *const gaps_names[] = {"none", "guennebaud", "diagonal", NULL};
enum { ACC_BITMASK, ACC_AREA };
static const char *const accumulate_names[] = {"bitmask", "area", NULL};

enum {
    P_OCCLUDER = SMAP_NUM_PARAMS, P_GAPS, P_ACCUMULATE, P_TILES, P_BUDGET, P_LAYERS, P_EARLY_OUT, P_BLEND, P_HSM_LEVELS
};
enum { EARLY_BOTH, EARLY_LIT, EARLY_NONE };
static const char *const early_out_names[] = {"both", "lit", "none", NULL};
enum { CLASS_LIT, CLASS_UMBRA, CLASS_BACKPROJECTED }; /* aux `class` */

#define BP_MAX_BUDGET 256
#define BP_WORDS BACKPROJECT_WORDS
#define BP_MAX_HSM_LEVELS 15 /* a 16384^2 map's pyramid */

/* Plain perspective faces only (softmap.h): no warps or frustum-face splits. */
#define BP_PARAMS                                                                                                 \
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT), SMAP_BIAS_PARAMS_PLANE(1),        \
    {"occluder", PARAM_ENUM, OCC_MICROQUAD, 0, 3, "",                                                              \
     "occluder representation (course §5.2.3.3): micropatch (each lexel's square at its depth: over-occludes, "   \
     "keeps one-texel twigs), microquad (quads of 2 x 2 lexel centres, all four in front: no gaps, misses "        \
     "one-texel twigs; the course's recommendation with bitmasks), microtri (also triangles of three of four) "   \
     "or contour (Guennebaud 2007: the blocking lexels' outline by a 16-case edge table, each edge's signed "      \
     "radial area about the light's centre summed; no overlaps, no gaps; pops where the outline changes)",        \
     occluder_names},                                                                                              \
    {"gaps", PARAM_ENUM, GAPS_DIAGONAL, 0, 2, "",                                                                  \
     "occluder=micropatch: gap filling (course §5.2.3.3): none (neighbouring patches at different depths leave "   \
     "slits that leak light), guennebaud (each patch extended to its left and bottom neighbours', Guennebaud "     \
     "2006) or diagonal (also its bottom-left corner to the diagonal neighbour's, Bavoil 2008)",                   \
     gaps_names},                                                                                                  \
    {"accumulate", PARAM_ENUM, ACC_BITMASK, 0, 1, "",                                                              \
     "bitmask (Schwarz & Stamminger 2007: one bit per light sample, the union of the occluders' masks, V = 1 - "   \
     "popcount / N) or area (course §5.2.3.1: each occluder's share of the light summed, over-occluding where "    \
     "occluders overlap; shares measured with the same samples; occluder=contour: the loops' exact share by "    \
     "signed radial areas, bitmask their enclosed samples)",                                                       \
     accumulate_names},                                                                                            \
    {"tiles", PARAM_INT, 8, 1, 16, "tiles",                                                                        \
     "light samples: a tiles x tiles tiling of the 2 x 2 rotated grid (RGSS), N = 4 tiles^2 (8: the course's "     \
     "256; 16: 1024)",                                                                                             \
     NULL},                                                                                                        \
    {"budget", PARAM_INT, 32, 2, BP_MAX_BUDGET, "lexels",                                                          \
     "texel budget T (course §5.2.3.5, Fig. 5.11): the search area is read at the finest level (min-pyramid "      \
     "nodes; in mssm and ysm MSSM windows above their base) whose window is at most T lexels a side (cost "        \
     "O(T^2) per receiver; aux `level`)",                                                                          \
     NULL},                                                                                                        \
    {"layers", PARAM_INT, 1, 1, PEELED_MAX_LAYERS, "layers",                                                       \
     "depth-peeled layers from the light's centre (course §5.2.3.3, Fig. 1.8): occluders of every layer nearer "   \
     "than the receiver are backprojected, each layer's polygons built on its own (bitmask: united; area: "        \
     "summed, over-occluding more); 1: the map alone (the centre's first surfaces); layers past 1 are peeled "    \
     "maps built by the rasterizer (resources/maps/peeled.h); search area and early outs read layer 0",            \
     NULL}

/* The multiscale variants' own (course §5.2.3.4-5). */
#define MS_PARAMS                                                                                                 \
    {"early_out", PARAM_ENUM, EARLY_BOTH, 0, 2, "",                                                                \
     "course §5.2.3.4's early outs before any backprojection: both (lit where z_p <= z_min over the search area; " \
     "umbra where every texel of it passes the shadow test, z_max in front of the smallest reference), lit only, " \
     "or none (every receiver backprojected: the early outs' effect measured against it; aux `class`)",            \
     early_out_names},                                                                                             \
    {"blend", PARAM_BOOL, 0, 0, 1, "",                                                                             \
     "level blending (course §5.2.3.5: level switches show, Fig. 5.11f): mix the budget's level L with L + 1 by "  \
     "t = log2(span / T) - (L - 1), span the area's width in texels: V is continuous where L switches as span "   \
     "grows continuously, not where span jumps (a nearer blocker entering the area; measured in "                  \
     "experiments/course-fig5.10-5.11-multiscale.lua); at most 1.25 x the cost, within the budget",                \
     NULL}

static const ParamDesc bp_params[] = {BP_PARAMS};
static const ParamDesc ms_params[] = {BP_PARAMS, MS_PARAMS};
static const ParamDesc ysm_params[] = {
    BP_PARAMS,
    MS_PARAMS,
    {"hsm_levels", PARAM_INT, 3, 1, BP_MAX_HSM_LEVELS, "levels",
     "n of course §5.2.3.4's YSM: the min-max pyramid's levels 0 .. n - 1 as in hsm, an MSSM built on level n - 1 "
     "for every coarser query (1: mssm; the map's level count or more: the MSSM of the top level's one node, "
     "i.e. hsm); the MSSM's level at most 1024^2 nodes",
     NULL},
};

static const char *const bp_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};
static const char *const ms_resources[] = {"shadow_map", "minmax_pyramid", "minmax_levels", "view_samples", NULL};
static const char *const bp_aux[] = {"level", NULL};
static const char *const ms_aux[] = {"class", "level", NULL};

/* The light's samples on one face's light plane (world units, face axes),
 * bucketed on a G x G grid over the light's bounding box, so a polygon
 * tests only the samples under its bounding box; and sorted by x and by y
 * with prefix masks (backproject.h), so an axis-aligned rectangle (a
 * micropatch's image) takes its mask by arithmetic alone. */
#define BP_GRID 16
typedef struct FaceSamples {
    float x[BACKPROJECT_MAX_SAMPLES], y[BACKPROJECT_MAX_SAMPLES];
    vec3 colour[BACKPROJECT_MAX_SAMPLES]; /* light_sample_colour: a textured rect's texel, else white */
    short start[BP_GRID * BP_GRID + 1];
    short index[BACKPROJECT_MAX_SAMPLES];
    double x0, y0, cell_x, cell_y; /* the grid's corner and cell size */
    BackprojectPrefix prefix;
} FaceSamples;

/* One depth layer's min-depth structures (layer 0: the map's own): the
 * pyramid, and the MSSM on its level `base` (mssm, ysm; NULL otherwise). */
typedef struct BpLayer {
    const MinMaxPyramid *pyramid;
    const MinMaxLevels *mssm;
} BpLayer;

typedef struct BpState {
    SoftMap sm;
    SmapBias bias;
    int occluder, gaps, accumulate, budget, samples;
    int early_out;
    int channels;             /* ctx->channels: 3 for a textured light's colours */
    uint64_t all[BP_WORDS];   /* every light sample's bit */
    bool blend, classify;     /* classify: aux `class` precedes `level` */
    const MinMaxLevels *mssm; /* NULL: the pyramid's aligned nodes only (backprojection, hsm) */
    int base;                 /* the pyramid level mssm is built on */
    int layers;               /* depth-peeled layers backprojected, layer[0] the map's own */
    BpLayer layer[PEELED_MAX_LAYERS];
    FaceSamples face[LIGHTVIEW_MAX_FACES];
} BpState;

/* Which min-max structure a technique reads. */
typedef enum Variant { VAR_BACKPROJECTION, VAR_HSM, VAR_MSSM, VAR_YSM } Variant;

static int grid_cell(double v, double v0, double cell)
{
    double c = floor((v - v0) / cell);
    return c >= 0.0 ? (int)fmin(c, BP_GRID - 1) : 0; /* NaN compares false: 0 */
}

static void face_samples(const Light *light, const SoftLight *L, int tiles, int n, FaceSamples *fs)
{
    int count[BP_GRID * BP_GRID] = {0}, cell[BACKPROJECT_MAX_SAMPLES];
    fs->x0 = -L->half_x;
    fs->y0 = -L->half_y;
    fs->cell_x = fmax(2.0 * L->half_x / BP_GRID, 1e-300); /* an edge-on light: every sample in cell 0 */
    fs->cell_y = fmax(2.0 * L->half_y / BP_GRID, 1e-300);
    for (int k = 0; k < n; k++) {
        double a, b;
        backproject_light_sample(tiles, k, L->square, &a, &b);
        /* xi = (a, b) spans the rect's half-axes right and up (softmap.c light_axes): the texel at
         * light_sample's (u, v) = ((a + 1) / 2, (b + 1) / 2) */
        fs->colour[k] = light_sample_colour(light, (float)((a + 1.0) / 2.0), (float)((b + 1.0) / 2.0));
        fs->x[k] = (float)(L->M[0][0] * a + L->M[0][1] * b);
        fs->y[k] = (float)(L->M[1][0] * a + L->M[1][1] * b);
        cell[k] = grid_cell(fs->y[k], fs->y0, fs->cell_y) * BP_GRID + grid_cell(fs->x[k], fs->x0, fs->cell_x);
        count[cell[k]]++;
    }
    fs->start[0] = 0;
    for (int c = 0; c < BP_GRID * BP_GRID; c++) fs->start[c + 1] = (short)(fs->start[c] + count[c]);
    int fill[BP_GRID * BP_GRID];
    for (int c = 0; c < BP_GRID * BP_GRID; c++) fill[c] = fs->start[c];
    for (int k = 0; k < n; k++) fs->index[fill[cell[k]]++] = (short)k;
    backproject_prefix_init(&fs->prefix, fs->x, fs->y, n);
}

/* Nodes per side of pyramid level `level` over a res^2 map, and the
 * pyramid's level count (res_minmax_pyramid: sizes halve, rounding up, to 1). */
static int pyramid_size(int res, int level)
{
    while (level-- > 0) res = (res + 1) / 2;
    return res;
}

static int pyramid_levels(int res)
{
    int n = 1;
    for (; res > 1; n++) res = (res + 1) / 2;
    return n;
}

/* The MSSM's base level (course §5.2.3.4: 0 for mssm, n - 1 for ysm, at
 * most the pyramid's top level, where the MSSM of one node is hsm),
 * refused, before any map is drawn, where it leaves more than
 * MINMAX_LEVELS_MAX_RES^2 nodes; -1: none (backprojection, hsm). */
static bool mssm_base(Variant var, const double *p, int *base, Error *err)
{
    int res = (int)p[SMAP_P_MAP_SIZE], levels = pyramid_levels(res);
    *base = var == VAR_MSSM ? 0 : var == VAR_YSM ? (int)p[P_HSM_LEVELS] - 1 : -1;
    if (*base < 0) return true;
    if (*base > levels - 1) *base = levels - 1;
    if (pyramid_size(res, *base) <= MINMAX_LEVELS_MAX_RES) return true;
    if (var == VAR_MSSM)
        return error_set(err,
                         "map_size %d above %d: the MSSM's full-resolution levels are 'too expensive for ... "
                         "greater than 1024^2' (course §5.2.3.4); map_size range [1, %d] here (ysm reads larger maps)",
                         res, MINMAX_LEVELS_MAX_RES, MINMAX_LEVELS_MAX_RES);
    int need = *base + 1;
    while (pyramid_size(res, need - 1) > MINMAX_LEVELS_MAX_RES) need++;
    return error_set(err,
                     "hsm_levels %d builds the MSSM on %d^2 nodes (map_size %d), above %d^2 (course §5.2.3.4); "
                     "range [%d, %d] at this map size",
                     *base + 1, pyramid_size(res, *base), res, MINMAX_LEVELS_MAX_RES, need, levels);
}

/* Layers 1 .. layers - 1, peeled behind the map (built only when layers > 1),
 * each with the structures layer 0 has: its pyramid, and its MSSM where
 * one is read. Only the budget's coarse lexels read them: the search area
 * and the early outs read layer 0 (see visibility). */
static bool acquire_layers(const TechContext *ctx, const ShadowMap *map, BpState *st, Error *err)
{
    st->layer[0] = (BpLayer){st->sm.pyramid, st->mssm};
    for (int k = 1; k < st->layers; k++) {
        const ShadowMap *peeled = res_peeled_layer(ctx->rm, ctx->scene, map, k, err);
        BpLayer *L = &st->layer[k];
        L->pyramid = peeled ? res_minmax_pyramid(ctx->rm, peeled, err) : NULL;
        if (!L->pyramid) return false;
        if (st->base >= 0 && !(L->mssm = res_minmax_levels(ctx->rm, L->pyramid, st->base, err))) return false;
    }
    return true;
}

static bool prepare_variant(const TechContext *ctx, Variant var, const char *tech, void **state, Error *err)
{
    const double *p = ctx->params;
    int base;
    if (!mssm_base(var, p, &base, err)) return false;
    if (ctx->light->kind == LIGHT_TEXTURED_RECT && p[P_ACCUMULATE] == ACC_AREA)
        return error_set(err, "accumulate=area cannot colour light %d (textured_rect): summed areas do not say which "
                              "light samples are covered, so not which texels; use accumulate=bitmask",
                         ctx->light_index + 1);
    BpState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->base = base;
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    bool ok = map && softmap_init(&st->sm, ctx->rm, map, ctx->light, tech, err);
    if (ok && st->base >= 0) ok = (st->mssm = res_minmax_levels(ctx->rm, st->sm.pyramid, st->base, err)) != NULL;
    st->layers = (int)p[P_LAYERS];
    if (ok) ok = acquire_layers(ctx, map, st, err);
    if (!ok) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->occluder = (int)p[P_OCCLUDER];
    st->gaps = (int)p[P_GAPS];
    st->accumulate = (int)p[P_ACCUMULATE];
    st->budget = (int)p[P_BUDGET];
    st->classify = var != VAR_BACKPROJECTION;
    st->early_out = st->classify ? (int)p[P_EARLY_OUT] : EARLY_LIT;
    st->blend = st->classify && p[P_BLEND] != 0.0;
    int tiles = (int)p[P_TILES];
    st->samples = 4 * tiles * tiles;
    st->channels = ctx->channels;
    for (int k = 0; k < st->samples; k++) st->all[k / 64] |= 1ull << (k % 64);
    for (int k = 0; k < map->num_faces; k++)
        face_samples(ctx->light, &st->sm.face[k].light, tiles, st->samples, &st->face[k]);
    *state = st;
    return true;
}

static bool bp_prepare(const TechContext *ctx, void **state, Error *err)
{
    return prepare_variant(ctx, VAR_BACKPROJECTION, "backprojection", state, err);
}
static bool hsm_prepare(const TechContext *ctx, void **state, Error *err)
{
    return prepare_variant(ctx, VAR_HSM, "hsm", state, err);
}
static bool mssm_prepare(const TechContext *ctx, void **state, Error *err)
{
    return prepare_variant(ctx, VAR_MSSM, "mssm", state, err);
}
static bool ysm_prepare(const TechContext *ctx, void **state, Error *err)
{
    return prepare_variant(ctx, VAR_YSM, "ysm", state, err);
}

static int clamp_texel(int v, int res) { return v < 0 ? 0 : v >= res ? res - 1 : v; }

/* Bounds (stored depth) over texels [i0, i1] x [j0, j1] (BackprojectBounds):
 * the pyramid's 2 x 2 nodes of the finest level that covers them (HSM),
 * unless an MSSM is built on a level no finer than that one: then its
 * exact bounds over the base-level nodes the texels lie in (course
 * §5.2.3.4's YSM switch; mssm: always). Either bounds every texel. */
static void ms_bounds(const void *state, int face, int i0, int j0, int i1, int j1, float *zmin, float *zmax)
{
    const BpState *st = state;
    const MinMaxPyramid *pyr = st->sm.pyramid;
    if (!st->mssm || minmax_query_level(pyr, i0, j0, i1, j1) < st->base) {
        minmax_query(pyr, face, i0, j0, i1, j1, zmin, zmax);
        return;
    }
    int b = st->base, res = pyr->res;
    minmax_levels_query(st->mssm, face, clamp_texel(i0, res) >> b, clamp_texel(j0, res) >> b,
                        clamp_texel(i1, res) >> b, clamp_texel(j1, res) >> b, zmin, zmax);
}

/* The umbra early out, exactly: every texel of [i - wi, i + wi] x [j - wj,
 * j + wj] passes the shadow test, i.e. the area's largest stored depth lies
 * in front of its smallest reference (affine in (s, t) or reciprocally so:
 * at a corner). NaN or an empty texel (+INFINITY): no early out. */
static bool area_occludes(const BpState *st, const SmapReceiver *r, int wi, int wj)
{
    int i, j;
    smap_texel(r, &i, &j);
    float zmin, zmax;
    ms_bounds(st, r->mc.face, i - wi, j - wj, i + wi, j + wj, &zmin, &zmax);
    double ref = nan_min(nan_min(smap_ref_at(r, i - wi, j - wj), smap_ref_at(r, i + wi, j - wj)),
                         nan_min(smap_ref_at(r, i - wi, j + wj), smap_ref_at(r, i + wi, j + wj)));
    return smap_test(ref, zmax) == 0.0f;
}

/* The lexel grid of budget level L (lexels 2^L texels wide): the
 * pyramid's aligned nodes (no MSSM, or L <= its base), or MSSM windows of
 * 2^k base nodes, k = L - base, the grid's lexel 0 centred on the
 * receiver's base node (course §5.2.3.4: windows "centred on each texel"),
 * so it moves with the receiver and has no quadtree seams. */
typedef struct Grid {
    int level, k;  /* k: MSSM level, -1 for pyramid nodes */
    int oi, oj;    /* base node where lexel 0 starts (MSSM); 0 for pyramid nodes */
} Grid;

static Grid lexel_grid(const BpState *st, int level, int i, int j)
{
    Grid g = {level, -1, 0, 0};
    if (!st->mssm || level <= st->base) return g;
    g.k = level - st->base;
    g.oi = (i >> st->base) - (1 << (g.k - 1)); /* i, j on the face: a receiver's texel */
    g.oj = (j >> st->base) - (1 << (g.k - 1));
    return g;
}

/* The minimum stored depth of one layer over lexel (*i, *j) of the grid,
 * and in *i, *j the level-0 texel that holds it (seed 000's closest caster
 * of a coarse lexel, tested at that texel's own reference). */
static float lexel_min(const BpState *st, const BpLayer *L, int face, const Grid *g, int *i, int *j)
{
    if (g->k < 0) return minmax_node_min(L->pyramid, face, g->level, i, j);
    *i = g->oi + *i * (1 << g->k);
    *j = g->oj + *j * (1 << g->k);
    float lo = minmax_levels_min(L->mssm, face, g->k, i, j); /* *i, *j: the base node */
    minmax_node_min(L->pyramid, face, st->base, i, j);        /* the same minimum, down to its texel */
    return lo;
}

/* The occluder samples of one receiver in one layer: the search window at
 * one budget level, with a border of one lexel (gap filling and quads read their
 * neighbours), each lexel's caster depth (world units), +INFINITY where
 * its closest texel does not lie in front of p, NaN where the test reads a
 * NaN (an unknown caster, issue 13 §1). */
typedef struct Window {
    int level, i0, j0, w, h; /* first lexel (border included) and size */
    double dx, dy;           /* lexel size, tangent units */
    double l, b;             /* tangent of lexel 0's low edge */
    double u, v, p_z;        /* the receiver's tangents and depth */
    double z[BP_MAX_BUDGET + 3][BP_MAX_BUDGET + 3];
} Window;

static double win_z(const Window *w, int a, int b) { return w->z[b][a]; }

/* The finest level whose window of span = 2 max(wi, wj) + 1 texels fits the
 * budget T (span < T 2^L: at most T lexels, one more where the grid cuts a
 * lexel at each end), and, for blending, the weight t of level L + 1:
 * lambda = log2(span / T) lies in [L - 1, L) (L > 0), t = lambda - (L - 1),
 * so t -> 1 as L is about to switch to L + 1 and is 0 just after: V is
 * continuous across a switch where span is (course §5.2.3.5); span itself
 * jumps where z_min over the area does. 0 at the top level. */
static int budget_level(const BpState *st, int wi, int wj, double *t)
{
    int level = 0, top = st->sm.pyramid->levels - 1, span = 2 * (wi > wj ? wi : wj) + 1;
    while (level < top && (span >> level) + 1 > st->budget) level++;
    double frac = log2((double)span / st->budget) - (level - 1);
    *t = level < top ? fmin(fmax(frac, 0.0), 1.0) : 0.0; /* span, budget >= 1: frac finite */
    return level;
}

static void load_window(const BpState *st, const BpLayer *L, const SmapReceiver *r, int wi, int wj, int level,
                        Window *w)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    int scale = 1 << level;
    int i, j;
    smap_texel(r, &i, &j);
    Grid g = lexel_grid(st, level, i, j);
    int oi = g.k < 0 ? 0 : g.oi * (1 << st->base), oj = g.k < 0 ? 0 : g.oj * (1 << st->base); /* lexel 0's texel */
    int i0 = (int)floor((double)(i - wi - oi) / scale), i1 = (int)floor((double)(i + wi - oi) / scale);
    int j0 = (int)floor((double)(j - wj - oj) / scale), j1 = (int)floor((double)(j + wj - oj) / scale);
    w->level = level;
    w->i0 = i0 - 1;
    w->j0 = j0 - 1;
    w->w = i1 - i0 + 3;
    w->h = j1 - j0 + 3;
    w->dx = f->dx * scale;
    w->dy = f->dy * scale;
    w->l = f->l + oi * f->dx;
    w->b = f->b + oj * f->dy;
    w->u = f->l + r->mc.s * f->dx;
    w->v = f->b + r->mc.t * f->dy;
    w->p_z = r->mc.depth_linear;
    for (int b = 0; b < w->h; b++)
        for (int a = 0; a < w->w; a++) {
            int ti = w->i0 + a, tj = w->j0 + b; /* off the face: edge-clamped, as every window of the map */
            float stored = lexel_min(st, L, r->mc.face, &g, &ti, &tj); /* keeps NaN; empty: +INFINITY, lit */
            float lit = smap_test(smap_ref_at(r, ti, tj), stored);
            w->z[b][a] = lit == 0.0f ? smap_linear_depth(st->sm.map, r->mc.face, stored) : lit == 1.0f ? INFINITY : NAN;
        }
}

/* A polygon on the light's plane (world units, face axes), at most 4 vertices. */
typedef struct Poly { double x[4], y[4]; int n; } Poly;

/* Crossing-number test (any simple or non-convex polygon; half-open edges). */
static bool poly_contains(const Poly *p, double x, double y)
{
    bool in = false;
    for (int a = 0, b = p->n - 1; a < p->n; b = a++)
        if ((p->y[a] > y) != (p->y[b] > y) &&
            x < p->x[b] + (p->x[a] - p->x[b]) * (y - p->y[b]) / (p->y[a] - p->y[b]))
            in = !in;
    return in;
}

/* Mark the samples the polygon covers in mask (NULL: count only; rect: an
 * axis-aligned box, corners (x[0], y[0]) and (x[1], y[1]), half-open
 * [xlo, xhi) x [ylo, yhi), its mask from the prefix masks with no sample
 * tested, course §5.2.3.2); returns how many it covers. Each call is one
 * occluder polygon backprojected (work.micropatches). */
static int cover(const FaceSamples *fs, const Poly *p, bool rect, uint64_t *mask)
{
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    int n = rect ? 2 : p->n;
    for (int k = 0; k < n; k++) {
        if (p->x[k] < xlo) xlo = p->x[k];
        if (p->x[k] > xhi) xhi = p->x[k];
        if (p->y[k] < ylo) ylo = p->y[k];
        if (p->y[k] > yhi) yhi = p->y[k];
    }
    work_micropatches(1);
    if (!(xlo <= -fs->x0 && xhi >= fs->x0 && ylo <= -fs->y0 && yhi >= fs->y0)) return 0; /* off the light, or NaN */
    if (rect) return backproject_rect_mask(&fs->prefix, xlo, xhi, ylo, yhi, mask);
    int c0 = grid_cell(xlo, fs->x0, fs->cell_x), c1 = grid_cell(xhi, fs->x0, fs->cell_x);
    int r0 = grid_cell(ylo, fs->y0, fs->cell_y), r1 = grid_cell(yhi, fs->y0, fs->cell_y);
    int marked = 0;
    for (int row = r0; row <= r1; row++)
        for (int k = fs->start[row * BP_GRID + c0]; k < fs->start[row * BP_GRID + c1 + 1]; k++) {
            int s = fs->index[k];
            double x = fs->x[s], y = fs->y[s];
            if (!poly_contains(p, x, y)) continue;
            if (mask) mask[s >> 6] |= 1ull << (s & 63);
            marked++;
        }
    return marked;
}

/* Tangent of lexel a's edge (a) or centre (a + 1/2) along x, y. */
static double win_x(const Window *w, double a) { return w->l + (w->i0 + a) * w->dx; }
static double win_y(const Window *w, double b) { return w->b + (w->j0 + b) * w->dy; }

/* The point at tangents (x, y), depth z, projected from p onto the light's
 * plane; an unknown caster (z NaN) has an unknown image (NaN), so the
 * polygon it is part of is unknown (issue 13 §1). */
static bool project(const Window *w, double x, double y, double z, double *lx, double *ly)
{
    double k = NAN;
    if (!isnan(z) && !backproject_light_scale(w->p_z, z, &k)) return false;
    *lx = k * (x - w->u);
    *ly = k * (y - w->v);
    return true;
}

/* Micropatch of lexel (a, b): its square at its depth, the low edges
 * reaching the farther of their own and the neighbours' images of them
 * (gap filling, course §5.2.3.3). A patch image is axis-aligned. */
static bool micropatch(const BpState *st, const Window *w, int a, int b, Poly *p)
{
    double z = win_z(w, a, b);
    double x0 = win_x(w, a), x1 = win_x(w, a + 1), y0 = win_y(w, b), y1 = win_y(w, b + 1);
    if (!project(w, x0, y0, z, &p->x[0], &p->y[0]) || !project(w, x1, y1, z, &p->x[1], &p->y[1])) return false;
    if (st->gaps == GAPS_NONE) return true;
    double lx, ly;
    /* nan_min: a neighbour of unknown depth leaves the edge unknown */
    if (project(w, x0, y0, win_z(w, a - 1, b), &lx, &ly)) p->x[0] = nan_min(p->x[0], lx); /* left's x1 edge */
    if (project(w, x0, y0, win_z(w, a, b - 1), &lx, &ly)) p->y[0] = nan_min(p->y[0], ly); /* bottom's y1 */
    if (st->gaps == GAPS_DIAGONAL && project(w, x0, y0, win_z(w, a - 1, b - 1), &lx, &ly)) {
        p->x[0] = nan_min(p->x[0], lx);
        p->y[0] = nan_min(p->y[0], ly);
    }
    return true;
}

/* The quad (or, microtri, triangle) of the centres of lexels (a, b) to
 * (a + 1, b + 1) in counter-clockwise order, those in front of p. */
static bool microquad(const BpState *st, const Window *w, int a, int b, Poly *p)
{
    static const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p->n = 0;
    for (int k = 0; k < 4; k++) {
        int ca = a + corner[k][0], cb = b + corner[k][1];
        if (project(w, win_x(w, ca + 0.5), win_y(w, cb + 0.5), win_z(w, ca, cb), &p->x[p->n], &p->y[p->n])) p->n++;
    }
    return p->n == 4 || (st->occluder == OCC_MICROTRI && p->n == 3);
}

/* Does a vertex of the polygon (rect: its two corners) lie at an unknown place? */
static bool poly_unknown(const Poly *p, bool rect)
{
    for (int k = 0; k < (rect ? 2 : p->n); k++)
        if (isnan(p->x[k]) || isnan(p->y[k])) return true;
    return false;
}

/* What a receiver's occluders cover, over its polygons and layers. */
typedef struct Occlusion {
    uint64_t mask[BP_WORDS]; /* bitmask: the light samples covered, united */
    long count;              /* area, polygons: samples covered, summed */
    double share;            /* area, contour: exact shares of the light, summed */
    bool unknown;            /* an occluder that may exist has an unknown place */
} Occlusion;

/* V = 1 - the covered share of the light, clamped to [0, 1]; NaN when an
 * occluder that may exist is unknown (issue 13 §1), unless the known ones
 * already cover the whole light (occluders only add: V = 0 either way). */
static double share_visibility(double covered, bool unknown)
{
    if (covered >= 1.0) return 0.0;
    return unknown ? NAN : 1.0 - nan_clamp(covered, 0.0, 1.0);
}

/* accumulate=area: the covered share's V in every channel. */
static void area_visibility(const BpState *st, double covered, bool unknown, double *v)
{
    for (int c = 0; c < st->channels; c++) v[c] = share_visibility(covered, unknown);
}

/* accumulate=bitmask: V per channel of the samples left unset in mask, their
 * colours over all samples' (light_bitmask_visibility, the reference's
 * ratio; 1 - popcount / N on a white light), with share_visibility's rules. */
static void mask_visibility(const BpState *st, const FaceSamples *fs, const uint64_t *mask, bool unknown, double *v)
{
    int marked = 0;
    for (int k = 0; k < BP_WORDS; k++) marked += __builtin_popcountll(mask[k]);
    if (st->channels == 1) { /* an untextured light: every sample white, V = 1 - popcount / N */
        v[0] = share_visibility((double)marked / st->samples, unknown); /* samples = 4 tiles^2 >= 4 */
        return;
    }
    float lit[3];
    light_bitmask_visibility(fs->colour, st->all, mask, st->samples, st->channels, lit);
    for (int c = 0; c < st->channels; c++) v[c] = marked >= st->samples ? 0.0 : unknown ? NAN : lit[c];
}

/* ---- contour occluders (Guennebaud et al. 2007, course §5.2.3.3) ----------
 * The binary mask "blocks the receiver" over the search area's lexels is
 * outlined by marching squares (course §5.2.3.3: "a 2x2 binary window
 * indexes a table of oriented edges"; [OWN] the 16 cases below). Cell
 * (a, b) joins the centres of lexels (a, b), (a + 1, b), (a + 1, b + 1),
 * (a, b + 1), corners 0 to 3 counter-clockwise; side s runs from corner s
 * to corner s + 1 and, where the mask changes along it, holds a contour
 * vertex on the two lexels' shared boundary, at the depth of the blocking
 * one. [OWN] the table: walking the cell's boundary counter-clockwise, an
 * edge runs from each side where the mask goes from in to out to the next
 * side where it goes from out to in, so the blocking lexels lie on the
 * edge's left and every loop turns counter-clockwise about them; the
 * saddles (cases 5 and 10) join the two blocking corners (no slit between
 * diagonal neighbours, as Bavoil's diagonal gap filling). Each vertex is
 * projected back from p onto the light's plane; the loops' covered share
 * of the light K is the sum of the signed areas of the triangles (light
 * centre, a, b) cut by K (Green's theorem, radial_area.h): each region
 * counted once (no micropatch overlaps, no gaps), but the outline is drawn
 * in 2D on the map: depth steps inside a region are not in it, and its
 * image changes by whole lexels as lexels enter or leave the mask
 * (popping, course §5.2.3.3). */
static const signed char contour_table[16][4] = {
    {-1, -1, -1, -1}, {0, 3, -1, -1}, {1, 0, -1, -1}, {1, 3, -1, -1}, {2, 1, -1, -1}, {0, 1, 2, 3},
    {2, 0, -1, -1},   {2, 3, -1, -1}, {3, 2, -1, -1}, {0, 2, -1, -1}, {1, 2, 3, 0},   {1, 2, -1, -1},
    {3, 1, -1, -1},   {0, 1, -1, -1}, {3, 0, -1, -1}, {-1, -1, -1, -1},
};
static const int cell_corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
/* side s's vertex, in lexels from cell (a, b)'s low lexel edge */
static const double side_point[4][2] = {{1.0, 0.5}, {1.5, 1.0}, {1.0, 1.5}, {0.5, 1.0}};

/* Does lexel (a, b) of the search area (the window less its border) block
 * p? *k: its image scale (backproject_light_scale), NaN where its depth is
 * unknown (it may block: its vertices are then unknown). */
static bool contour_inside(const Window *w, int a, int b, double *k)
{
    if (a < 1 || b < 1 || a > w->w - 2 || b > w->h - 2) return false;
    double z = win_z(w, a, b);
    *k = NAN;
    return isnan(z) || backproject_light_scale(w->p_z, z, k); /* +INFINITY (lit): false */
}

/* Toggle in mask the samples whose ray toward +x crosses edge a -> b (the
 * crossing test of poly_contains, one edge at a time): over closed loops
 * the samples left set are those enclosed an odd number of times. */
static void toggle_crossings(const FaceSamples *fs, P2 a, P2 b, uint64_t *mask)
{
    double ylo = a.y < b.y ? a.y : b.y, yhi = a.y < b.y ? b.y : a.y, xhi = a.x < b.x ? b.x : a.x;
    if (!(ylo <= -fs->y0 && yhi >= fs->y0 && xhi >= fs->x0)) return; /* no sample of the light left of it */
    int r0 = grid_cell(ylo, fs->y0, fs->cell_y), r1 = grid_cell(yhi, fs->y0, fs->cell_y);
    int c1 = grid_cell(xhi, fs->x0, fs->cell_x);
    for (int row = r0; row <= r1; row++)
        for (int k = fs->start[row * BP_GRID]; k < fs->start[row * BP_GRID + c1 + 1]; k++) {
            int s = fs->index[k];
            double x = fs->x[s], y = fs->y[s];
            if ((a.y > y) != (b.y > y) && x < a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y)) /* a.y != b.y here */
                mask[s >> 6] ^= 1ull << (s & 63);
        }
}

/* Signed area of triangle (light centre, a, b) cut by the light, as a share
 * of the light: in the light's own coordinates (M^-1, softmap.h) K is the
 * unit disk or [-1, 1]^2, and M scales every area by |det M| (a negative
 * det flips the orientation; an edge-on light, M^-1 = 0, covers nothing). */
static double radial_share(const SoftLight *L, P2 a, P2 b)
{
    P2 ua = {L->Minv[0][0] * a.x + L->Minv[0][1] * a.y, L->Minv[1][0] * a.x + L->Minv[1][1] * a.y};
    P2 ub = {L->Minv[0][0] * b.x + L->Minv[0][1] * b.y, L->Minv[1][0] * b.x + L->Minv[1][1] * b.y};
    double det = L->M[0][0] * L->M[1][1] - L->M[0][1] * L->M[1][0];
    double share = L->square ? tri_square_area(ua, ub) / 4.0 : tri_disk_area(ua, ub, 1.0) / M_PI;
    return det < 0.0 ? -share : share;
}

/* The image on the light's plane (world units, face axes) of side s's
 * vertex in cell (a, b), whose corners' flags and scales are in[], k[]. */
static P2 contour_vertex(const Window *w, int a, int b, const bool *in, const double *k, int s)
{
    int c = in[s] ? s : (s + 1) % 4; /* the side's blocking corner */
    double x = win_x(w, a + side_point[s][0]), y = win_y(w, b + side_point[s][1]);
    return (P2){k[c] * (x - w->u), k[c] * (y - w->v)};
}

/* The window's contour loops: accumulate=area their exact covered share of
 * the light, added to o's; bitmask the light samples they enclose (the
 * crossing parity of this layer's loops alone), united with o's. */
static void contour_occlusion(const BpState *st, const SoftLight *L, const FaceSamples *fs, const Window *w,
                              Occlusion *o)
{
    uint64_t mask[BP_WORDS] = {0};
    double share = 0.0;
    for (int b = 0; b < w->h - 1; b++)
        for (int a = 0; a < w->w - 1; a++) {
            bool in[4];
            double k[4];
            int code = 0;
            for (int c = 0; c < 4; c++) {
                in[c] = contour_inside(w, a + cell_corner[c][0], b + cell_corner[c][1], &k[c]);
                code |= in[c] << c;
            }
            for (int e = 0; e < 4 && contour_table[code][e] >= 0; e += 2) {
                P2 p = contour_vertex(w, a, b, in, k, contour_table[code][e]);
                P2 q = contour_vertex(w, a, b, in, k, contour_table[code][e + 1]);
                if (isnan(p.x) || isnan(p.y) || isnan(q.x) || isnan(q.y)) {
                    o->unknown = true;
                    continue;
                }
                work_micropatches(1); /* one contour edge backprojected */
                if (st->accumulate == ACC_AREA)
                    share += radial_share(L, p, q);
                else
                    toggle_crossings(fs, p, q, mask);
            }
        }
    o->share += share;
    for (int k = 0; k < BP_WORDS; k++) o->mask[k] |= mask[k];
}

/* Add the window's occluders to o: polygons' samples united (bitmask) or
 * counted (area); an occluder that may exist but reads a NaN depth marks o
 * unknown (issue 13 §1). */
static void window_occlusion(const BpState *st, const SoftFace *f, const FaceSamples *fs, const Window *w,
                             Occlusion *o)
{
    if (st->occluder == OCC_CONTOUR) {
        contour_occlusion(st, &f->light, fs, w, o);
        return;
    }
    bool patch = st->occluder == OCC_MICROPATCH;
    for (int b = patch ? 1 : 0; b < w->h - 1; b++)
        for (int a = patch ? 1 : 0; a < w->w - 1; a++) {
            Poly p = {.n = 0};
            bool ok = patch ? win_z(w, a, b) != INFINITY && micropatch(st, w, a, b, &p) : microquad(st, w, a, b, &p);
            if (!ok) continue;
            if (poly_unknown(&p, patch)) {
                o->unknown = true;
                continue;
            }
            o->count += cover(fs, &p, patch, st->accumulate == ACC_AREA ? NULL : o->mask); /* area: counted */
        }
}

/* V of o per channel into v: bitmask the samples left unset (their colours
 * on a textured light), area 1 - the summed shares (contour's exact); NaN
 * when an occluder that may exist is unknown, unless the known ones already
 * cover every sample (occluders only add). */
static void occlusion_visibility(const BpState *st, const FaceSamples *fs, const Occlusion *o, double *v)
{
    if (st->accumulate == ACC_BITMASK) mask_visibility(st, fs, o->mask, o->unknown, v);
    else area_visibility(st, st->occluder == OCC_CONTOUR ? o->share : (double)o->count / st->samples, o->unknown, v);
}

/* V over the search window at one budget level, occluders taken from every
 * layer (course §5.2.3.3's depth-peeled layers): each layer's own lexels
 * make its polygons (quads, gap filling and contours join neighbours of one
 * layer), and a layer's lexel occludes where it passes the shadow test, i.e.
 * lies nearer the light than the receiver; empty lexels (+INFINITY: a
 * texel with fewer surfaces) never do. */
static void level_visibility(const BpState *st, const SmapReceiver *r, int wi, int wj, int level, Window *w,
                             double *v)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    Occlusion o = {.unknown = false};
    for (int k = 0; k < st->layers; k++) {
        load_window(st, &st->layer[k], r, wi, wj, level, w);
        window_occlusion(st, f, &st->face[r->mc.face], w, &o);
    }
    occlusion_visibility(st, &st->face[r->mc.face], &o, v);
}

static void fill(float *out, int channels, float v)
{
    for (int c = 0; c < channels; c++) out[c] = v;
}

/* Visibility of one receiver into out[0..channels); *cls its path (aux
 * `class`), *level the budget level read. The search area and both early outs read layer 0 only, and
 * stay exact with layers: per texel layer 0 is the nearest surface, so its
 * z_min over an area is every layer's (no blocker of any layer lies nearer
 * the light than z_b; lit where none can block); the umbra early out needs
 * a height field in front of p over the whole area, and layer 0's, if it
 * passes, is one (deeper layers only add occluders; their z_max would be
 * wrong to use, an empty texel or a surface behind p failing an area that
 * layer 0 already closes). */
static void visibility(const BpState *st, const SmapReceiver *r, Window *w, int *cls, int *level, float *out)
{
    double z_b, t;
    bool may_block = backproject_search_in(&st->sm, ms_bounds, st, r, &z_b);
    int wi, wj;
    backproject_search_halfwidth(&st->sm, r, z_b, &wi, &wj);
    *level = 0;
    *cls = CLASS_LIT;
    if (!may_block && st->early_out != EARLY_NONE) { fill(out, st->channels, 1.0f); return; } /* z_p <= z_min: lit */
    *cls = CLASS_UMBRA;
    if (st->early_out == EARLY_BOTH && area_occludes(st, r, wi, wj)) { fill(out, st->channels, 0.0f); return; }
    *cls = CLASS_BACKPROJECTED;
    *level = budget_level(st, wi, wj, &t);
    double v[3], next[3];
    level_visibility(st, r, wi, wj, *level, w, v);
    if (st->blend && t > 0.0) { /* course §5.2.3.5: blending two levels hides the switch */
        level_visibility(st, r, wi, wj, *level + 1, w, next);
        for (int c = 0; c < st->channels; c++) v[c] = (1.0 - t) * v[c] + t * next[c];
    }
    for (int c = 0; c < st->channels; c++) out[c] = (float)v[c];
}

static void bp_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const BpState *st = state;
    int channels = st->classify ? 2 : 1; /* ms_aux or bp_aux */
    Window *w = malloc(sizeof *w);
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float *v = out + (size_t)(s - begin) * (size_t)ctx->channels;
        int level = 0, cls = CLASS_LIT;
        if (w && smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            visibility(st, &r, w, &cls, &level, v);
        else fill(v, ctx->channels, w ? 1.0f : NAN); /* outside the map: lit (a lit early out); no memory: no value */
        if (!ctx->aux) continue;
        if (st->classify) ctx->aux[(size_t)s * channels] = (float)cls;
        ctx->aux[(size_t)s * channels + channels - 1] = (float)level;
    }
    free(w);
}

/* Gap filling joins neighbouring micropatches only. */
static const ParamCondition bp_conditions[] = {
    {"gaps", "occluder=micropatch"},
    {NULL, NULL},
};

/* What the four techniques share. */
#define BP_TECHNIQUE                                                                                                \
    .conditions = bp_conditions, .family = "soft", .rgb = true,                                                      \
    .lights = LIGHTS_AREA,                                                                                            \
    .main_param = "budget", /* course Fig. 5.11: accuracy against the texel budget */                                \
        .evaluate = bp_evaluate, .release = free

const Technique tech_backprojection = {
    BP_TECHNIQUE,
    .name = "backprojection",
    .source = "course §5.2.3.1-3 (Guennebaud et al. 2006; Bavoil & Silva 2006), occlusion bitmasks §5.2.3.2 "
              "(Schwarz & Stamminger 2007)",
    .summary = "occluder samples of the map's search area (refined through z_min) as micropatches, microquads or "
               "microtris, projected back from the receiver onto the light: a bitmask over 4 tiles^2 light "
               "samples (union) or summed areas",
    .params = bp_params,
    .num_params = (int)(sizeof bp_params / sizeof bp_params[0]),
    .resources = bp_resources,
    .aux = bp_aux,
    .prepare = bp_prepare,
};

const Technique tech_hsm = {
    BP_TECHNIQUE,
    .name = "hsm",
    .source = "course §5.2.3.4-5 (hierarchical shadow map, Guennebaud et al. 2006; texel budget Fig. 5.11)",
    .summary = "backprojection whose search area is bounded by the min-max mip pyramid's 2 x 2 nodes: lit and "
               "umbra early outs, then the budget's pyramid level backprojected (aux class and level)",
    .params = ms_params,
    .num_params = (int)(sizeof ms_params / sizeof ms_params[0]),
    .resources = bp_resources,
    .aux = ms_aux,
    .prepare = hsm_prepare,
};

const Technique tech_mssm = {
    BP_TECHNIQUE,
    .name = "mssm",
    .source = "course §5.2.3.4-5 (multi-scale shadow map, Schwarz & Stamminger 2008; texel budget Fig. 5.11)",
    .summary = "backprojection on min-max windows of 2^i texels at every texel and level (full resolution, maps "
               "up to 1024^2): exact bounds for the lit and umbra early outs, budget lexels centred on the "
               "receiver (aux class and level)",
    .params = ms_params,
    .num_params = (int)(sizeof ms_params / sizeof ms_params[0]),
    .resources = ms_resources,
    .aux = ms_aux,
    .prepare = mssm_prepare,
};

const Technique tech_ysm = {
    BP_TECHNIQUE,
    .name = "ysm",
    .source = "course §5.2.3.4-5 (YSM: HSM levels, then an MSSM; texel budget Fig. 5.11)",
    .summary = "backprojection on the min-max pyramid's first n levels and an MSSM built on level n - 1: the "
               "early outs of mssm at a quarter^(n-1) of its memory (aux class and level)",
    .params = ysm_params,
    .num_params = (int)(sizeof ysm_params / sizeof ysm_params[0]),
    .resources = ms_resources,
    .aux = ms_aux,
    .prepare = ysm_prepare,
};
