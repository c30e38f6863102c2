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
 *     and projected back from p onto the light's plane
 *     (backproject_light_scale, L = k (x - u));
 *  3. accumulated over the light's N samples (4 tiles^2 on the RGSS
 *     tiling, backproject_light_sample): bitmask = the union of the
 *     samples each polygon covers, V = 1 - popcount / N (§5.2.3.2, fusion
 *     exact up to the sample count); area = each polygon's covered share
 *     summed, V = 1 - min(1, sum) (§5.2.3.1's summed areas, measured by the
 *     same samples: over-occludes where polygons overlap).
 * Only casters seen from the light's centre exist (one layer; course
 * Fig. 1.8). The light is the scene's (sphere: its central cross-section). */
#include <stdlib.h>
#include "core/nanmath.h"
#include "techniques/backproject.h"

enum { OCC_MICROPATCH, OCC_MICROQUAD, OCC_MICROTRI };
static const char *const occluder_names[] = {"micropatch", "microquad", "microtri", NULL};
enum { GAPS_NONE, GAPS_GUENNEBAUD, GAPS_DIAGONAL };
static const char *const gaps_names[] = {"none", "guennebaud", "diagonal", NULL};
enum { ACC_BITMASK, ACC_AREA };
static const char *const accumulate_names[] = {"bitmask", "area", NULL};

enum { P_OCCLUDER = SMAP_NUM_PARAMS, P_GAPS, P_ACCUMULATE, P_TILES, P_BUDGET };

#define BP_MAX_BUDGET 256
#define BP_WORDS (BACKPROJECT_MAX_SAMPLES / 64)

/* Plain perspective faces only (softmap.h): no warps or frustum-face splits. */
static const ParamDesc bp_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    {"occluder", PARAM_ENUM, OCC_MICROQUAD, 0, 2, "",
     "occluder representation (course §5.2.3.3): micropatch (each lexel's square at its depth: over-occludes, "
     "keeps one-texel twigs), microquad (quads of 2 x 2 lexel centres, all four in front: no gaps, misses "
     "one-texel twigs; the course's recommendation with bitmasks) or microtri (also triangles of three of four)",
     occluder_names},
    {"gaps", PARAM_ENUM, GAPS_DIAGONAL, 0, 2, "",
     "occluder=micropatch: gap filling (course §5.2.3.3): none (neighbouring patches at different depths leave "
     "slits that leak light), guennebaud (each patch extended to its left and bottom neighbours', Guennebaud "
     "2006) or diagonal (also its bottom-left corner to the diagonal neighbour's, Bavoil 2008)",
     gaps_names},
    {"accumulate", PARAM_ENUM, ACC_BITMASK, 0, 1, "",
     "bitmask (Schwarz & Stamminger 2007: one bit per light sample, the union of the occluders' masks, V = 1 - "
     "popcount / N) or area (course §5.2.3.1: each occluder's share of the light summed, over-occluding where "
     "occluders overlap; shares measured with the same samples)",
     accumulate_names},
    {"tiles", PARAM_INT, 8, 1, 16, "tiles",
     "light samples: a tiles x tiles tiling of the 2 x 2 rotated grid (RGSS), N = 4 tiles^2 (8: the course's "
     "256; 16: 1024)",
     NULL},
    {"budget", PARAM_INT, 32, 2, BP_MAX_BUDGET, "lexels",
     "texel budget T (course §5.2.3.5, Fig. 5.11): the search area is read at the finest min-pyramid level "
     "whose window is at most T lexels a side (cost O(T^2) per receiver; aux `level`)",
     NULL},
};

static const char *const bp_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};
static const char *const bp_aux[] = {"level", NULL};

/* The light's samples on one face's light plane (world units, face axes),
 * bucketed on a G x G grid over the light's bounding box, so a polygon
 * tests only the samples under its bounding box. */
#define BP_GRID 16
typedef struct FaceSamples {
    float x[BACKPROJECT_MAX_SAMPLES], y[BACKPROJECT_MAX_SAMPLES];
    short start[BP_GRID * BP_GRID + 1];
    short index[BACKPROJECT_MAX_SAMPLES];
    double x0, y0, cell_x, cell_y; /* the grid's corner and cell size */
} FaceSamples;

typedef struct BpState {
    SoftMap sm;
    SmapBias bias;
    int occluder, gaps, accumulate, budget, samples;
    FaceSamples face[LIGHTVIEW_MAX_FACES];
} BpState;

static int grid_cell(double v, double v0, double cell)
{
    double c = floor((v - v0) / cell);
    return c >= 0.0 ? (int)fmin(c, BP_GRID - 1) : 0; /* NaN compares false: 0 */
}

static void face_samples(const SoftLight *L, int tiles, int n, FaceSamples *fs)
{
    int count[BP_GRID * BP_GRID] = {0}, cell[BACKPROJECT_MAX_SAMPLES];
    fs->x0 = -L->half_x;
    fs->y0 = -L->half_y;
    fs->cell_x = fmax(2.0 * L->half_x / BP_GRID, 1e-300); /* an edge-on light: every sample in cell 0 */
    fs->cell_y = fmax(2.0 * L->half_y / BP_GRID, 1e-300);
    for (int k = 0; k < n; k++) {
        double a, b;
        backproject_light_sample(tiles, k, L->square, &a, &b);
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
}

static bool bp_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    BpState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&st->sm, ctx->rm, map, ctx->light, "backprojection", err)) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->occluder = (int)p[P_OCCLUDER];
    st->gaps = (int)p[P_GAPS];
    st->accumulate = (int)p[P_ACCUMULATE];
    st->budget = (int)p[P_BUDGET];
    int tiles = (int)p[P_TILES];
    st->samples = 4 * tiles * tiles;
    for (int k = 0; k < map->num_faces; k++) face_samples(&st->sm.face[k].light, tiles, st->samples, &st->face[k]);
    *state = st;
    return true;
}

/* The occluder samples of one receiver: the search window at one pyramid
 * level, with a border of one lexel (gap filling and quads read their
 * neighbours), each lexel's caster depth (world units), +INFINITY where
 * its closest texel does not lie in front of p, NaN where the test reads a
 * NaN (an unknown caster, issue 13 §1). */
typedef struct Window {
    int level, i0, j0, w, h; /* first lexel (border included) and size */
    double dx, dy;           /* lexel size, tangent units */
    double l, b;             /* tangent of lexel edge 0 */
    double u, v, p_z;        /* the receiver's tangents and depth */
    double z[BP_MAX_BUDGET + 3][BP_MAX_BUDGET + 3];
} Window;

static double win_z(const Window *w, int a, int b) { return w->z[b][a]; }

/* The finest level whose window of 2 wi + 1 texels fits the budget. */
static int budget_level(const BpState *st, int wi, int wj)
{
    int level = 0, span = 2 * (wi > wj ? wi : wj) + 1;
    while (level + 1 < st->sm.pyramid->levels && (span >> level) + 1 > st->budget) level++;
    return level;
}

static void load_window(const BpState *st, const SmapReceiver *r, int wi, int wj, Window *w)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    int level = budget_level(st, wi, wj), scale = 1 << level;
    int i, j;
    smap_texel(r, &i, &j);
    int i0 = (int)floor((double)(i - wi) / scale), i1 = (int)floor((double)(i + wi) / scale);
    int j0 = (int)floor((double)(j - wj) / scale), j1 = (int)floor((double)(j + wj) / scale);
    w->level = level;
    w->i0 = i0 - 1;
    w->j0 = j0 - 1;
    w->w = i1 - i0 + 3;
    w->h = j1 - j0 + 3;
    w->dx = f->dx * scale;
    w->dy = f->dy * scale;
    w->l = f->l;
    w->b = f->b;
    w->u = f->l + r->mc.s * f->dx;
    w->v = f->b + r->mc.t * f->dy;
    w->p_z = r->mc.depth_linear;
    for (int b = 0; b < w->h; b++)
        for (int a = 0; a < w->w; a++) {
            int ti = w->i0 + a, tj = w->j0 + b; /* off the face: edge-clamped, as every window of the map */
            float stored = minmax_node_min(st->sm.pyramid, r->mc.face, level, &ti, &tj); /* keeps NaN */
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
 * axis-aligned box, corners (x[0], y[0]) and (x[1], y[1])); returns how
 * many it covers. */
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
    if (!(xlo <= -fs->x0 && xhi >= fs->x0 && ylo <= -fs->y0 && yhi >= fs->y0)) return 0; /* off the light, or NaN */
    int c0 = grid_cell(xlo, fs->x0, fs->cell_x), c1 = grid_cell(xhi, fs->x0, fs->cell_x);
    int r0 = grid_cell(ylo, fs->y0, fs->cell_y), r1 = grid_cell(yhi, fs->y0, fs->cell_y);
    int marked = 0;
    for (int row = r0; row <= r1; row++)
        for (int k = fs->start[row * BP_GRID + c0]; k < fs->start[row * BP_GRID + c1 + 1]; k++) {
            int s = fs->index[k];
            double x = fs->x[s], y = fs->y[s];
            bool in = rect ? x >= xlo && x < xhi && y >= ylo && y < yhi : poly_contains(p, x, y);
            if (!in) continue;
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

/* 1 - occluded share of the light's samples over the window; NaN when an
 * occluder that may exist reads a NaN depth (issue 13 §1), unless the known
 * ones already cover every sample (occluders only add: V = 0 either way). */
static double window_visibility(const BpState *st, const FaceSamples *fs, const Window *w)
{
    uint64_t mask[BP_WORDS] = {0};
    long sum = 0;
    bool patch = st->occluder == OCC_MICROPATCH, unknown = false;
    for (int b = patch ? 1 : 0; b < w->h - 1; b++)
        for (int a = patch ? 1 : 0; a < w->w - 1; a++) {
            Poly p = {.n = 0};
            bool ok = patch ? win_z(w, a, b) != INFINITY && micropatch(st, w, a, b, &p) : microquad(st, w, a, b, &p);
            if (!ok) continue;
            if (poly_unknown(&p, patch)) {
                unknown = true;
                continue;
            }
            sum += cover(fs, &p, patch, st->accumulate == ACC_AREA ? NULL : mask); /* area: counted, not united */
        }
    if (st->accumulate == ACC_AREA) return sum >= st->samples ? 0.0 : unknown ? NAN : 1.0 - (double)sum / st->samples;
    int marked = 0;
    for (int k = 0; k < BP_WORDS; k++) marked += __builtin_popcountll(mask[k]);
    return marked == st->samples ? 0.0 : unknown ? NAN : 1.0 - (double)marked / st->samples;
}

static float visibility(const BpState *st, const SmapReceiver *r, Window *w, int *level)
{
    double z_b;
    *level = 0;
    if (!backproject_search(&st->sm, r, &z_b)) return 1.0f; /* z_p <= z_min over the search area: lit */
    int wi, wj;
    backproject_search_halfwidth(&st->sm, r, z_b, &wi, &wj);
    load_window(st, r, wi, wj, w);
    *level = w->level;
    return (float)window_visibility(st, &st->face[r->mc.face], w);
}

static void bp_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const BpState *st = state;
    Window *w = malloc(sizeof *w);
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        int level = 0;
        if (w && smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r, w, &level);
        else if (!w)
            v = NAN; /* out of memory: no value, never a made-up one */
        tech_store(ctx, out, begin, s, v);
        if (ctx->aux) ctx->aux[s] = (float)level;
    }
    free(w);
}

/* Gap filling joins neighbouring micropatches only. */
static const ParamCondition bp_conditions[] = {
    {"gaps", "occluder=micropatch"},
    {NULL, NULL},
};

const Technique tech_backprojection = {
    .conditions = bp_conditions,
    .name = "backprojection",
    .family = "soft",
    .source = "course §5.2.3.1-3 (Guennebaud et al. 2006; Bavoil & Silva 2006), occlusion bitmasks §5.2.3.2 "
              "(Schwarz & Stamminger 2007)",
    .summary = "occluder samples of the map's search area (refined through z_min) as micropatches, microquads or "
               "microtris, projected back from the receiver onto the light: a bitmask over 4 tiles^2 light "
               "samples (union) or summed areas",
    .params = bp_params,
    .num_params = (int)(sizeof bp_params / sizeof bp_params[0]),
    .resources = bp_resources,
    .aux = bp_aux,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "budget", /* course Fig. 5.11: accuracy against the texel budget */
    .prepare = bp_prepare,
    .evaluate = bp_evaluate,
    .release = free,
};
