/* view_sample_mapping.c -- `view_sample_mapping`: soft shadows by mapping
 * each caster triangle onto the view samples it can shadow (Eisemann &
 * Décoret 2007, "Visibility sampling on GPU and applications"; Sintorn et
 * al. 2008, "Sample based visibility for soft shadows using alias-free
 * shadow maps"; course §5.3.3). Per triangle: its influence region on the
 * view samples, the triangle backprojected from each of them into the
 * normalised light frame (exact_soft.h), one mask of light samples per edge
 * (those on its inner side), the AND of the edges' masks (the samples the
 * triangle hides), ORed into the view sample's bitmask of N light samples;
 * the visibility is the fraction of kept samples left unset.
 *
 * Light samples are the reference's own (same pattern, seed, count and
 * stream), so the bitmask is the reference's rays' answers, bit for bit, up
 * to float at edges. With masks=exact (the default) the masks are computed
 * exactly per sample (double orientation tests on the projected sample
 * points), with no quantisation error; with masks=hough each edge's mask is
 * that of its line quantised to the nearest bin of a hough_bins x hough_bins
 * table (angle x offset, Eisemann & Décoret's left-sample map; hough_line),
 * which errs on the samples between an edge and its quantised line. The
 * angle axis (the bins' normals) is a set-up table keyed by hough_bins
 * (point_table); the entry's mask is evaluated when fetched, not stored,
 * because the reference draws its own sample set per view sample (stream
 * sampling_stream(seed, s)), so a stored table would be one per view sample
 * (hough_bins^2 x N bits each) where the papers share one across the frame.
 * `near_edge` (aux) counts the light samples within EXACT_AMBIGUOUS_TAN of a
 * projected (exact) edge, where the ray test and the exact mask may disagree.
 *
 * Influence region: the view samples are taken in tiles of TILE; a chunk of
 * triangles maps onto the samples of the tile whose cone toward the light
 * its bounding sphere reaches, and each of its triangles onto those of them
 * the triangle's plane does not separate from the light (the exact region
 * is inside; it is not bounded in screen space). Triangles crossing the
 * plane through the sample perpendicular to the light's axis are clipped to
 * its front first (exact_clip): the part behind cannot hide a light sample.
 * Casters are assumed between receivers and light (a triangle beyond a light
 * sample is counted as hiding it). Textured lights' sample colours are not
 * handled: sphere, rect and disk lights. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "resources/standard.h"
#include "techniques/exact_soft.h"

#define TILE 16 /* view samples mapped together */
/* Lit candidates x light samples mapped in one prepare, at most 2^33
 * (sphere-on-plane at 640x480, 256 samples: 10 us per view sample on one
 * core; 4096^2 at 256 samples is accepted, at 1024 refused). */
#define MAX_SAMPLE_TESTS 8589934592.0
#define WORDS (EXACT_MAX_SAMPLES / 64)
#define GRID 16 /* sample grid cells per side */
/* normalised-frame distance a triangle's bounds are widened by: a sample
 * within EXACT_AMBIGUOUS_TAN of an edge is near it (hide_samples) */
#define NEAR_PAD (2.0 * EXACT_AMBIGUOUS_TAN)
#define HOUGH_FAR 1e300 /* normalised-frame bounds that hold every sample (finite: cell_of's product) */

enum { VSM_P_MASKS = EXACT_NUM_SAMPLE_PARAMS, VSM_P_HOUGH_BINS };
enum { VSM_MASKS_EXACT, VSM_MASKS_HOUGH };
static const char *const vsm_mask_names[] = {"exact", "hough", NULL};

static const ParamDesc vsm_params[] = {
    EXACT_SAMPLE_PARAMS(32, 256,
                        "N: bits of each view sample's light-sample mask (the course's 32 to 1024); the "
                        "reference's --samples gives the same points"),
    {"masks", PARAM_ENUM, VSM_MASKS_EXACT, 0, 1, "",
     "each edge's light-sample mask: exact (orientation test per sample, the reference's answers) or hough (the "
     "mask of the edge's line quantised to the nearest bin of an angle x offset table, course §5.3.3.2)",
     vsm_mask_names},
    {"hough_bins", PARAM_INT, 256, 64, 1048576, "bins per axis",
     "masks=hough's table resolution: bins of the line angle over [-pi, pi) and of its offset over the kept "
     "samples' radius about the light frame's centre (the course's 64 to 1024; masks are evaluated when "
     "fetched, not stored, so up to 2^20, 8 bytes per angle bin); finer bins err on fewer samples",
     NULL},
};

static const ParamCondition vsm_conditions[] = {
    {"hough_bins", "masks=hough"},
    {NULL, NULL},
};

static const char *const vsm_resources[] = {"embree_bvh", "silhouette", "point_table", NULL};
static const char *const vsm_aux[] = {"near_edge", NULL};

/* One view sample of a tile: its light samples and masks. */
typedef struct Mapped {
    int s;           /* view sample */
    bool reached;    /* some caster reaches the light's cone from it */
    int open;        /* kept light samples no triangle hides yet: 0 ends the mapping onto it (umbra) */
    const PointTable *hough_normals; /* masks=hough: the bins' unit normals (hough_fill_normals); NULL: exact */
    double hough_range; /* masks=hough: the offset axis spans [-range, range] (normalised frame) */
    LightPoints lp;
    uint64_t blocked[WORDS], near[WORDS];
    /* The kept samples binned in a GRID x GRID grid over their bounds lo..hi
     * (normalised light frame), so a triangle tests only the samples of the
     * cells its projected bounds overlap: cell c holds cell_sample[cell_first[c]
     * .. cell_first[c + 1]). */
    double scale_x, scale_y; /* cells per normalised-frame unit (0 when the bounds are flat) */
    int cell_first[GRID * GRID + 1];
    int cell_sample[EXACT_MAX_SAMPLES];
} Mapped;

typedef struct VsmState {
    const PointTable *hough_normals; /* masks=hough: the angle axis, a set-up table keyed by the bins; NULL: exact */
    float *vis;  /* per view sample */
    float *near; /* per view sample: light samples within EXACT_AMBIGUOUS_TAN of a projected edge */
} VsmState;

static int cell_of(double x, double lo, double scale)
{
    double c = (x - lo) * scale;
    return c < 0.0 ? 0 : c >= GRID - 1 ? GRID - 1 : (int)c;
}

/* Bins the kept samples (a counting sort by cell). */
static void bin_samples(Mapped *m)
{
    const LightPoints *lp = &m->lp;
    double wx = lp->hi.x - lp->lo.x, wy = lp->hi.y - lp->lo.y;
    m->scale_x = wx > 0.0 ? GRID / wx : 0.0;
    m->scale_y = wy > 0.0 ? GRID / wy : 0.0;
    int cell[EXACT_MAX_SAMPLES];
    memset(m->cell_first, 0, sizeof m->cell_first);
    for (int i = 0; i < lp->n; i++) {
        if (!lp->above[i]) continue;
        cell[i] = cell_of(lp->x[i].y, lp->lo.y, m->scale_y) * GRID + cell_of(lp->x[i].x, lp->lo.x, m->scale_x);
        m->cell_first[cell[i] + 1]++;
    }
    for (int c = 0; c < GRID * GRID; c++) m->cell_first[c + 1] += m->cell_first[c];
    int fill[GRID * GRID] = {0};
    for (int i = 0; i < lp->n; i++)
        if (lp->above[i]) m->cell_sample[m->cell_first[cell[i]] + fill[cell[i]]++] = i;
}

/* masks=hough: a line of the normalised light frame as its quantised Hough
 * pair (course §5.3.3.2 step 3; Eisemann & Décoret 2007, "Visibility
 * sampling on GPU and applications"; Sintorn, Eisemann & Assarsson 2008,
 * "Sample based visibility for soft shadows using alias-free shadow maps",
 * CGF 27(4) 1285-1292): the unit normal n = (cos theta, sin theta) on the
 * left of a -> b and the signed offset r = n . a of the line from the frame's
 * centre (the light's centre direction), so the samples on its left are
 * those with n . x > r. theta is rounded to the nearest of `bins` angles
 * -pi + k 2 pi / bins (the table's REPEAT axis), r to the nearest of `bins`
 * offsets -range + k 2 range / (bins - 1) (CLAMP: range exceeds every kept
 * sample's distance from the centre, so the end bins' masks are none and
 * all, as those of the lines past them). A zero-length or non-finite edge
 * has no left side: r = +inf, an empty mask, as the exact test's. */
typedef struct HoughLine {
    double nx, ny, r; /* normalised frame */
} HoughLine;

/* The angle axis of the table: bin k's unit normal (cos, sin) of
 * theta_k = -pi + k 2 pi / n. */
static void hough_fill_normals(float (*pts)[2], int n)
{
    for (int k = 0; k < n; k++) {
        double theta = -M_PI + 2.0 * M_PI * k / n;
        pts[k][0] = (float)cos(theta);
        pts[k][1] = (float)sin(theta);
    }
}

static HoughLine hough_line(P2 a, P2 b, const PointTable *normals, double range)
{
    int bins = normals->n;
    double dx = b.x - a.x, dy = b.y - a.y, len = hypot(dx, dy), r = (-dy * a.x + dx * a.y) / len;
    if (!(len > 0.0) || !isfinite(r)) return (HoughLine){1.0, 0.0, INFINITY};
    double theta = atan2(dx / len, -dy / len), step_theta = 2.0 * M_PI / bins, step_r = 2.0 * range / (bins - 1);
    long kt = lround((theta + M_PI) / step_theta) % bins;
    double t = (r + range) / step_r;
    double kr = t <= 0.0 ? 0.0 : t >= bins - 1 ? bins - 1 : (double)lround(t);
    return (HoughLine){normals->pts[kt][0], normals->pts[kt][1], -range + kr * step_r};
}

/* masks=hough: widens the polygon's bounds lo..hi to those of the polygon
 * with each edge pushed out by delta = (pi / bins + 2^-22) range + range /
 * (bins - 1), the most a quantised line's n . x - r moves from the edge's at
 * a sample (|n_q - n| <= the angle's half bin plus the float normal's
 * rounding, |x| < range; the offset's half bin; a clamped line's mask is the
 * edge's own), so no sample outside them is
 * inside every quantised line. Corner k moves by the miter delta (n1 + n2) /
 * (1 + n1 . n2) of its edges' outward unit normals; where that blows up (a
 * spike) or an edge has no normal, the bounds become the whole plane. */
static void hough_bounds(const P2 *q, int np, double orientation, int bins, double range, P2 *lo, P2 *hi)
{
    double delta = (M_PI / bins + 0x1p-22) * range + range / (bins - 1);
    P2 out[4]; /* per edge: its outward unit normal */
    for (int e = 0; e < np; e++) {
        double dx = q[(e + 1) % np].x - q[e].x, dy = q[(e + 1) % np].y - q[e].y, len = hypot(dx, dy);
        out[e] = (P2){dy / len * orientation, -dx / len * orientation}; /* right of a -> b when it turns left */
    }
    *lo = (P2){INFINITY, INFINITY};
    *hi = (P2){-INFINITY, -INFINITY};
    for (int k = 0; k < np; k++) {
        P2 n1 = out[(k + np - 1) % np], n2 = out[k];
        double cosine = 1.0 + n1.x * n2.x + n1.y * n2.y; /* > 0 unless the edges fold back */
        if (!(cosine > 1e-12)) {
            *lo = (P2){-HOUGH_FAR, -HOUGH_FAR};
            *hi = (P2){HOUGH_FAR, HOUGH_FAR};
            return;
        }
        P2 c = {q[k].x + delta * (n1.x + n2.x) / cosine, q[k].y + delta * (n1.y + n2.y) / cosine};
        *lo = (P2){fmin(lo->x, c.x), fmin(lo->y, c.y)};
        *hi = (P2){fmax(hi->x, c.x), fmax(hi->y, c.y)};
    }
}

/* masks=hough: is x on the left of every quantised line (the AND of the
 * table entries' masks)? */
static bool hough_inside(const HoughLine *hl, int np, P2 x)
{
    bool inside = true;
    for (int e = 0; e < np; e++) inside &= hl[e].nx * x.x + hl[e].ny * x.y > hl[e].r;
    return inside;
}

/* The light samples inside the clipped, projected polygon q[0..np) (bounds
 * lo..hi): those strictly on the inner side of every edge, ORed into the
 * view sample's bitmask; samples on an edge within the tolerance are marked
 * near. Only the samples of the grid cells the bounds (widened by NEAR_PAD;
 * with masks=hough, by hough_bounds) overlap are tested: one outside is
 * outside the polygon and farther than the tolerance from its edges, so the
 * masks are those of testing every sample. */
static void hide_samples(Mapped *m, const P2 *q, int np, double orientation, P2 lo, P2 hi)
{
    const LightPoints *lp = &m->lp;
    double len[4];
    HoughLine hl[4];
    const bool hough = m->hough_normals != NULL; /* a local: the loop's stores to m may alias the field */
    for (int e = 0; e < np; e++) {
        P2 a = q[e], b = q[(e + 1) % np];
        len[e] = hypot(b.x - a.x, b.y - a.y);
        if (hough) /* the inner side on the left: b -> a where the polygon turns clockwise */
            hl[e] = orientation > 0.0 ? hough_line(a, b, m->hough_normals, m->hough_range)
                                      : hough_line(b, a, m->hough_normals, m->hough_range);
    }
    int x0 = cell_of(lo.x - NEAR_PAD, lp->lo.x, m->scale_x), x1 = cell_of(hi.x + NEAR_PAD, lp->lo.x, m->scale_x);
    int y0 = cell_of(lo.y - NEAR_PAD, lp->lo.y, m->scale_y), y1 = cell_of(hi.y + NEAR_PAD, lp->lo.y, m->scale_y);
    for (int cy = y0; cy <= y1; cy++)
        for (int k = m->cell_first[cy * GRID + x0]; k < m->cell_first[cy * GRID + x1 + 1]; k++) {
            int i = m->cell_sample[k];
            uint64_t bit = 1ull << (i % 64);
            if (m->blocked[i / 64] & bit) continue; /* hidden already */
            bool inside = true;
            for (int e = 0; e < np; e++) {
                P2 a = q[e], b = q[(e + 1) % np];
                double o = exact_orient(a, b, lp->x[i]) * orientation; /* > 0: the inner side */
                inside &= o > 0.0;
                if (fabs(o) <= EXACT_AMBIGUOUS_TAN * len[e]) {
                    double t = ((lp->x[i].x - a.x) * (b.x - a.x) + (lp->x[i].y - a.y) * (b.y - a.y)) /
                               (len[e] * len[e]);
                    if (t >= 0.0 && t <= 1.0) m->near[i / 64] |= bit;
                }
            }
            if (hough) inside = hough_inside(hl, np, lp->x[i]);
            if (!inside) continue;
            m->blocked[i / 64] |= bit;
            m->open--;
        }
}

/* Do bounds lo..hi (normalised frame) miss every kept sample? */
static bool misses_samples(const LightPoints *lp, P2 lo, P2 hi)
{
    return hi.x < lp->lo.x || lo.x > lp->hi.x || hi.y < lp->lo.y || lo.y > lp->hi.y;
}

/* Triangle t backprojected from view sample m into its light frame. */
static void map_triangle(Mapped *m, const vec3 *tri, bool front_only)
{
    dvec3 poly[4];
    int facing, np = exact_clip(&m->lp.f, tri, poly, &facing, NULL);
    if (np < 3 || facing == 0) return; /* nothing in front, or edge-on: it hides no sample */
    if (front_only && facing < 0) return; /* a front face of the closed object hides the same samples */
    P2 q[4];
    double area = 0.0;
    P2 lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY};
    for (int k = 0; k < np; k++) {
        q[k] = exact_project(&m->lp.f, poly[k]);
        lo = (P2){fmin(lo.x, q[k].x), fmin(lo.y, q[k].y)};
        hi = (P2){fmax(hi.x, q[k].x), fmax(hi.y, q[k].y)};
    }
    if (!m->hough_normals && misses_samples(&m->lp, lo, hi)) return;
    for (int k = 1; k + 1 < np; k++) area += exact_orient(q[0], q[k], q[k + 1]);
    if (area == 0.0) return;
    double orientation = area > 0.0 ? 1.0 : -1.0;
    if (m->hough_normals) { /* the quantised lines' bounds, known once the orientation is */
        hough_bounds(q, np, orientation, m->hough_normals->n, m->hough_range, &lo, &hi);
        if (misses_samples(&m->lp, lo, hi)) return;
    }
    hide_samples(m, q, np, orientation, lo, hi);
}

/* masks=hough's offset range: the kept samples' largest distance from the
 * frame's centre (normalised frame), at least EXACT_AMBIGUOUS_TAN so the
 * bins have a width. */
static double hough_range(const LightPoints *lp)
{
    double range = EXACT_AMBIGUOUS_TAN;
    for (int i = 0; i < lp->n; i++)
        if (lp->above[i]) range = fmax(range, hypot(lp->x[i].x, lp->x[i].y) * (1.0 + 1e-9));
    return range;
}

/* Kept light samples whose bit in mask is `set`. */
static int count_kept(const uint64_t *mask, bool set, const LightPoints *lp)
{
    int c = 0;
    for (int i = 0; i < lp->n; i++) c += lp->above[i] && (((mask[i / 64] >> (i % 64)) & 1) != 0) == set;
    return c;
}

/* Maps every caster chunk onto the tile's `count` view samples. */
static void map_tile(const ExactCasters *cs, const TechContext *ctx, Mapped *tile, int count, VsmState *st)
{
    for (int k = 0; k < count; k++) {
        Mapped *m = &tile[k];
        memset(m->blocked, 0, sizeof m->blocked);
        memset(m->near, 0, sizeof m->near);
        m->reached = exact_begin(cs, ctx, m->s, &m->lp);
        if (m->reached) {
            exact_draw(&m->lp, ctx, m->s);
            bin_samples(m);
        }
        m->open = m->reached ? m->lp.kept : 0;
        m->hough_normals = st->hough_normals;
        m->hough_range = m->reached ? hough_range(&m->lp) : 0.0;
    }
    bool in[TILE], front_only[TILE];
    for (int o = 0; o < cs->num_objects; o++) {
        for (int k = 0; k < count; k++) {
            in[k] = tile[k].open > 0 && exact_object_reaches(cs, o, &tile[k].lp);
            front_only[k] = in[k] && exact_front_faces_suffice(cs, o, &tile[k].lp);
        }
        for (int c = cs->object_first[o]; c < cs->object_first[o + 1]; c++)
            for (int k = 0; k < count; k++) {
                Mapped *m = &tile[k];
                if (!in[k] || m->open == 0 || !exact_chunk_reaches(cs, c, &m->lp)) continue;
                for (int t = cs->chunk_first[c]; t < cs->chunk_first[c + 1] && m->open > 0; t++)
                    if (exact_triangle_reaches(cs, t, &m->lp)) map_triangle(m, &cs->tri[3 * t], front_only[k]);
            }
    }
    for (int k = 0; k < count; k++) {
        Mapped *m = &tile[k];
        const LightPoints *lp = &m->lp;
        if (!m->reached) { st->vis[m->s] = 1.0f; st->near[m->s] = 0.0f; continue; }
        if (lp->kept == 0) { st->vis[m->s] = exact_sliver_visibility(cs, ctx, m->s, lp); st->near[m->s] = 0.0f; continue; }
        st->vis[m->s] = (float)count_kept(m->blocked, false, lp) / (float)lp->kept;
        st->near[m->s] = (float)(count_kept(m->near, true, lp) + lp->off_axis);
    }
}

static bool map_all(const ExactCasters *cs, const TechContext *ctx, VsmState *st, Error *err)
{
    int n = ctx->vs->count, failed = 0;
#pragma omp parallel reduction(+ : failed)
    {
        Mapped *tile = malloc(sizeof *tile * TILE);
        failed += !tile;
#pragma omp for schedule(dynamic, 1)
        for (int first = 0; first < n; first += TILE) {
            int count = 0;
            for (int s = first; tile && s < first + TILE && s < n; s++)
                if (ctx->cls[s] == SAMPLE_LIT_CANDIDATE) tile[count++].s = s;
            if (tile) map_tile(cs, ctx, tile, count, st);
        }
        free(tile);
    }
    return failed ? error_set(err, "out of memory for view_sample_mapping's tiles") : true;
}

static void vsm_release(void *state)
{
    VsmState *st = state;
    if (!st) return;
    free(st->vis);
    free(st->near);
    free(st);
}

static bool vsm_prepare(const TechContext *ctx, void **state, Error *err)
{
    long lit = 0;
    for (int s = 0; s < ctx->vs->count; s++) lit += ctx->cls[s] == SAMPLE_LIT_CANDIDATE;
    double tests = (double)lit * ctx->params[EXACT_P_SAMPLES];
    if (tests > MAX_SAMPLE_TESTS)
        return error_set(err, "%ld lit view samples x samples=%d light samples = %.3g exceed the "
                              "bound of %.3g mask bits per frame; lower -p samples or the image size",
                         lit, (int)ctx->params[EXACT_P_SAMPLES], tests, MAX_SAMPLE_TESTS);
    const PointTable *normals = NULL;
    if (ctx->params[VSM_P_MASKS] == VSM_MASKS_HOUGH &&
        !(normals = res_point_table(ctx->rm, "view_sample_mapping hough normals", hough_fill_normals,
                                    (int)ctx->params[VSM_P_HOUGH_BINS], err)))
        return false;
    ExactCasters cs;
    if (!exact_casters_init(ctx, false, &cs, err)) return false;
    VsmState *st = calloc(1, sizeof *st);
    if (st) st->hough_normals = normals;
    bool ok = st && (st->vis = malloc(sizeof *st->vis * (size_t)ctx->vs->count)) &&
              (st->near = malloc(sizeof *st->near * (size_t)ctx->vs->count));
    if (!ok) error_set(err, "out of memory for %d view samples' masks", ctx->vs->count);
    ok = ok && map_all(&cs, ctx, st, err);
    exact_casters_free(&cs);
    if (!ok) {
        vsm_release(st);
        return false;
    }
    *state = st;
    return true;
}

static void vsm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const VsmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        tech_store(ctx, out, begin, s, st->vis[s]);
        if (ctx->aux) ctx->aux[s] = st->near[s];
    }
}

const Technique tech_view_sample_mapping = {
    .name = "view_sample_mapping",
    .family = "geometry",
    .source = "course §5.3.3 (Eisemann & Décoret 2007; Sintorn et al. 2008)",
    .summary = "each caster triangle mapped onto the view samples it can shadow, backprojected into their light "
               "frames, its edges' sample masks ANDed and ORed into a per-sample bitmask of the reference's light "
               "samples",
    .params = vsm_params,
    .num_params = (int)(sizeof vsm_params / sizeof vsm_params[0]),
    .conditions = vsm_conditions,
    .resources = vsm_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK),
    .main_param = "samples",
    .prepare = vsm_prepare,
    .evaluate = vsm_evaluate,
    .release = vsm_release,
    .aux = vsm_aux,
};
