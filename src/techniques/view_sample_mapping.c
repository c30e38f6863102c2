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
 * which errs on the samples between an edge and its quantised line.
 * Two sample sets (sample_set, the reference's --sample-set):
 * per_view_sample (the default): each view sample draws its own stream
 * (sampling_stream(seed, s)), so with masks=hough the angle axis (the bins'
 * normals) is a set-up table keyed by hough_bins (point_table) and each
 * entry's mask is evaluated when fetched, not stored: a stored table would
 * be one per view sample. shared: one stream for the frame, so on a rect,
 * disk or textured light every view sample sees the same points of the
 * light, and masks=hough reads the papers' one stored table (HoughTable, a
 * set-up resource keyed by the light's shape, the sample set and the bins):
 * each edge's plane through the view sample cuts the light's plane in a
 * line, whose entry's mask is looked up; the AND of the polygon's masks is
 * ORed into the bitmask, no sample tested on its own.
 * `near_edge` (aux) counts the light samples within EXACT_AMBIGUOUS_TAN of a
 * projected (exact) edge, where the ray test and the exact mask may disagree
 * (with the stored table no sample is tested, so there it counts only the
 * off-axis samples).
 *
 * Influence region: the view samples are taken in tiles of TILE; a chunk of
 * triangles maps onto the samples of the tile whose cone toward the light
 * its bounding sphere reaches, and each of its triangles onto those of them
 * the triangle's plane does not separate from the light (the exact region
 * is inside; it is not bounded in screen space). Triangles crossing the
 * plane through the sample perpendicular to the light's axis are clipped to
 * its front first (exact_clip): the part behind cannot hide a light sample.
 * Casters are assumed between receivers and light (a triangle beyond a light
 * sample is counted as hiding it). Coloured (textured rect) lights weigh each
 * sample by its colour, the reference's own ratio (light_bitmask_visibility). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
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
#define HOUGH_MAX_BYTES (1ull << 30) /* a stored table (sample_set=shared) larger is refused */

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
     "masks=hough's table resolution: bins of the line angle over [-pi, pi) and of its offset over the "
     "samples' radius about the light's centre (the course's 64 to 1024); finer bins err on fewer samples. "
     "per_view_sample: masks evaluated when fetched, up to 2^20 (8 bytes per angle bin); shared: the stored "
     "table, bins (N (N + 1) / 8 + 4 N + 8) bytes, refused over 1 GiB",
     NULL},
};

static const ParamCondition vsm_conditions[] = {
    {"hough_bins", "masks=hough"},
    {NULL, NULL},
};

static const char *const vsm_resources[] = {"embree_bvh", "silhouette", "point_table", "vsm_hough_table", NULL};
static const char *const vsm_aux[] = {"near_edge", NULL};

/* One view sample of a tile: its light samples and masks. */
typedef struct Mapped {
    int s;           /* view sample */
    bool reached;    /* some caster reaches the light's cone from it */
    int open;        /* kept light samples no triangle hides yet: 0 ends the mapping onto it (umbra) */
    const PointTable *hough_normals; /* masks=hough, per_view_sample: the bins' unit normals; else NULL */
    double hough_range; /* masks=hough, per_view_sample: the offset axis spans [-range, range] (normalised frame) */
    const struct HoughTable *table; /* masks=hough, shared: the stored table; else NULL */
    LightPoints lp;
    uint64_t blocked[WORDS], near[WORDS], kept[WORDS];
    /* The kept samples binned in a GRID x GRID grid over their bounds lo..hi
     * (normalised light frame), so a triangle tests only the samples of the
     * cells its projected bounds overlap: cell c holds cell_sample[cell_first[c]
     * .. cell_first[c + 1]). */
    double scale_x, scale_y; /* cells per normalised-frame unit (0 when the bounds are flat) */
    int cell_first[GRID * GRID + 1];
    int cell_sample[EXACT_MAX_SAMPLES];
} Mapped;

typedef struct VsmState {
    const PointTable *hough_normals; /* masks=hough, per_view_sample: the angle axis, keyed by the bins; else NULL */
    const struct HoughTable *table;  /* masks=hough, shared: the stored table; else NULL */
    float *vis;  /* per view sample, ctx->channels each */
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

/* The table entry of the line n . x = r (n a unit normal, r finite or
 * +-inf): the nearest angle bin k and offset bin j, clamped to the ends. */
static void hough_quantise(double nx, double ny, double r, int bins, double range, int *k, int *j)
{
    double step_theta = 2.0 * M_PI / bins, t = (r + range) / (2.0 * range / (bins - 1));
    *k = (int)(lround((atan2(ny, nx) + M_PI) / step_theta) % bins);
    *j = t <= 0.0 ? 0 : t >= bins - 1 ? bins - 1 : (int)lround(t);
}

/* Offset bin j's r. */
static double hough_offset(int j, int bins, double range) { return -range + j * (2.0 * range / (bins - 1)); }

static HoughLine hough_line(P2 a, P2 b, const PointTable *normals, double range)
{
    int bins = normals->n, k, j;
    double dx = b.x - a.x, dy = b.y - a.y, len = hypot(dx, dy), r = (-dy * a.x + dx * a.y) / len;
    if (!(len > 0.0) || !isfinite(r)) return (HoughLine){1.0, 0.0, INFINITY};
    hough_quantise(-dy / len, dx / len, r, bins, range, &k, &j);
    return (HoughLine){normals->pts[k][0], normals->pts[k][1], hough_offset(j, bins, range)};
}

/* sample_set=shared, masks=hough: the one stored left-sample table of the
 * frame (Eisemann & Décoret 2007 §4; Sintorn et al. 2008 §4; course
 * §5.3.3.2), over the light's own plane: the N shared samples' points a_i
 * in its axes (light_plane_point, world units), angle bins theta_k (the
 * per-view-sample table's normals n_k, hough_fill_normals) x offset bins r_j
 * over [-range, range] (range just above the largest |a_i|), entry (k, j)
 * the N-bit mask of the samples with n_k . a_i > r_j. Along a row the mask
 * only loses samples as r grows, one at a time in the order of n_k . a_i, so
 * a row holds N + 1 distinct masks (mask m: the m samples farthest along
 * n_k) and N steps (leave[m - 1]: the first offset bin the m-th farthest
 * sample is out at): entry (k, j) is mask m of row k for the largest m with
 * leave[m - 1] > j (a binary search). Losslessly the dense bins x bins x
 * N-bit table in bins (N (N + 1) / 8 + 4 N) bytes, so 2^16 bins per axis fit
 * where the dense table would take 2^29 N bytes. */
typedef struct HoughTable {
    int bins, n, words; /* bins per axis; light samples; 64-bit words per mask */
    double range;       /* light-plane units */
    P2 lo, hi;          /* the samples' bounds (light plane) */
    float (*normal)[2]; /* per angle bin: its unit normal */
    uint32_t *leave;    /* bins x n, row (angle) major, non-increasing along a row */
    uint64_t *mask;     /* bins x (n + 1) x words */
} HoughTable;

typedef struct TableArgs {
    const Light *light;
    SamplingPattern pattern;
    uint32_t seed;
    int n, bins;
} TableArgs;

static size_t table_bytes_for(int bins, int n)
{
    int words = (n + 63) / 64;
    return (size_t)bins * (size_t)n * sizeof(uint32_t) + (size_t)bins * (size_t)(n + 1) * (size_t)words * 8 +
           (size_t)bins * sizeof(float[2]);
}
static size_t table_bytes(const void *r)
{
    const HoughTable *t = r;
    return table_bytes_for(t->bins, t->n);
}
static void table_destroy(void *r)
{
    HoughTable *t = r;
    free(t->normal);
    free(t->leave);
    free(t->mask);
    free(t);
}
static const ResourceKind kind_hough_table = {"vsm_hough_table", table_bytes, table_destroy, RES_SETUP};

typedef struct Projection {
    double p;
    int i;
} Projection;

static int by_projection_descending(const void *a, const void *b)
{
    double x = ((const Projection *)a)->p, y = ((const Projection *)b)->p;
    return x < y ? 1 : x > y ? -1 : ((const Projection *)a)->i - ((const Projection *)b)->i;
}

/* Row k: the masks of the samples farthest along n_k, and each offset's rank. */
static void fill_row(HoughTable *t, int k, double (*a)[2], Projection *order)
{
    for (int i = 0; i < t->n; i++)
        order[i] = (Projection){t->normal[k][0] * a[i][0] + t->normal[k][1] * a[i][1], i};
    qsort(order, (size_t)t->n, sizeof *order, by_projection_descending);
    uint64_t *m = t->mask + (size_t)k * (size_t)(t->n + 1) * (size_t)t->words;
    memset(m, 0, sizeof *m * (size_t)t->words);
    for (int r = 1; r <= t->n; r++) {
        memcpy(m + (size_t)r * t->words, m + (size_t)(r - 1) * t->words, sizeof *m * (size_t)t->words);
        m[(size_t)r * t->words + order[r - 1].i / 64] |= 1ull << (order[r - 1].i % 64);
    }
    for (int r = 0; r < t->n; r++) { /* the first bin j with !(p > r_j): from the nearest, then exactly */
        double p = order[r].p, c = ceil((p + t->range) / (2.0 * t->range / (t->bins - 1)));
        int j = c <= 0.0 ? 0 : c >= t->bins ? t->bins : (int)c;
        while (j > 0 && !(p > hough_offset(j - 1, t->bins, t->range))) j--;
        while (j < t->bins && p > hough_offset(j, t->bins, t->range)) j++;
        t->leave[(size_t)k * t->n + r] = (uint32_t)j;
    }
}

/* Entry (k, j): mask m of row k, m the samples with n_k . a_i > r_j. */
static const uint64_t *table_entry(const HoughTable *t, int k, int j)
{
    const uint32_t *leave = t->leave + (size_t)k * t->n;
    int lo = 0, hi = t->n;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (leave[mid - 1] > (uint32_t)j) lo = mid;
        else hi = mid - 1;
    }
    return t->mask + ((size_t)k * (size_t)(t->n + 1) + (size_t)lo) * t->words;
}

static void *build_table(const void *args, Error *err)
{
    const TableArgs *ta = args;
    HoughTable *t = calloc(1, sizeof *t);
    double (*a)[2] = malloc(sizeof *a * (size_t)ta->n);
    Projection *order = malloc(sizeof *order * (size_t)ta->n);
    if (t) {
        *t = (HoughTable){.bins = ta->bins, .n = ta->n, .words = (ta->n + 63) / 64};
        t->normal = malloc(sizeof *t->normal * (size_t)t->bins);
        t->leave = malloc(sizeof *t->leave * (size_t)t->bins * (size_t)t->n);
        t->mask = malloc(sizeof *t->mask * (size_t)t->bins * (size_t)(t->n + 1) * (size_t)t->words);
    }
    if (!t || !a || !order || !t->normal || !t->leave || !t->mask) {
        if (t) table_destroy(t);
        free(a);
        free(order);
        error_set(err, "out of memory for view_sample_mapping's %d x %d Hough table (%zu bytes)", ta->bins, ta->bins,
                  table_bytes_for(ta->bins, ta->n));
        return NULL;
    }
    uint32_t stream = sampling_set_stream(ta->seed, true, 0);
    t->range = 0.0;
    t->lo = (P2){INFINITY, INFINITY};
    t->hi = (P2){-INFINITY, -INFINITY};
    for (int i = 0; i < t->n; i++) {
        float u, v;
        sample_2d(ta->pattern, stream, i, t->n, &u, &v);
        light_plane_point(ta->light, u, v, a[i]);
        t->range = fmax(t->range, hypot(a[i][0], a[i][1]) * (1.0 + 1e-9));
        t->lo = (P2){fmin(t->lo.x, a[i][0]), fmin(t->lo.y, a[i][1])};
        t->hi = (P2){fmax(t->hi.x, a[i][0]), fmax(t->hi.y, a[i][1])};
    }
    t->range = fmax(t->range, 1e-30); /* a light of one point: bins still have a width */
    hough_fill_normals(t->normal, t->bins);
    for (int k = 0; k < t->bins; k++) fill_row(t, k, a, order);
    free(a);
    free(order);
    return t;
}

/* The stored table for the context's light, samples and bins. */
static const HoughTable *acquire_table(const TechContext *ctx, Error *err)
{
    const Light *l = ctx->light;
    vec3 centre, e1, e2;
    if (!light_plane_axes(l, &centre, &e1, &e2)) {
        error_set(err, "sample_set=shared with masks=hough needs a rect, disk or textured_rect "
                       "light (light %d is not planar: a sphere light's samples are directions in the cone from "
                       "each view sample, not points one table can hold); use sample_set=per_view_sample or "
                       "masks=exact", ctx->light_index + 1);
        return NULL;
    }
    TableArgs ta = {l, (SamplingPattern)ctx->params[EXACT_P_PATTERN], (uint32_t)ctx->params[EXACT_P_SEED],
                    (int)ctx->params[EXACT_P_SAMPLES], (int)ctx->params[VSM_P_HOUGH_BINS]};
    size_t bytes = table_bytes_for(ta.bins, ta.n);
    if (bytes > HOUGH_MAX_BYTES) {
        error_set(err, "hough_bins=%d with samples=%d needs a %zu-byte table, over the bound of "
                       "%llu (sample_set=shared); lower hough_bins or samples", ta.bins, ta.n, bytes,
                  (unsigned long long)HOUGH_MAX_BYTES);
        return NULL;
    }
    Hasher h; /* the table depends on the light's shape in its own plane, not its pose */
    hash_init(&h);
    hash_u64(&h, (uint64_t)l->kind);
    hash_f32(&h, l->kind == LIGHT_DISK ? l->radius : l->width);
    hash_f32(&h, l->kind == LIGHT_DISK ? 0.0f : l->height);
    hash_u64(&h, (uint64_t)ta.pattern);
    hash_u64(&h, ta.seed);
    hash_u64(&h, (uint64_t)ta.n);
    hash_u64(&h, (uint64_t)ta.bins);
    char desc[160];
    snprintf(desc, sizeof desc, "%d x %d bins, %d %s samples (seed %u) of light %d's shape", ta.bins, ta.bins, ta.n,
             sampling_pattern_name(ta.pattern), ta.seed, ctx->light_index + 1);
    return rm_acquire(ctx->rm, &kind_hough_table, hash_final(&h), desc, build_table, &ta, err);
}

/* The light-plane line of the polygon edge a -> b (normalised frame) seen
 * from org: the plane through org and the edge, normal m = D_a x D_b with
 * D = u x + v y + c, holds the directions d with orient(a, b, x(d)) = 0
 * (d.c > 0: det[D_a, D_b, d] = d.c orient(a, b, x(d)) in the right-handed
 * frame), so the light point C + s e1 + t e2 is on the edge's inner side
 * iff m' . (C - org) + s m' . e1 + t m' . e2 > 0, m' = orientation m: the
 * line n . (s, t) > r. A plane parallel to the light's has its line at
 * infinity: every point inside (r = -inf) or none (+inf). */
static void light_plane_line(const Frame *f, P2 a, P2 b, double orientation, const dvec3 axes[3], double *nx,
                             double *ny, double *r)
{
    dvec3 da = d3_add(d3_add(d3_scale(f->u, a.x), d3_scale(f->v, a.y)), f->c);
    dvec3 db = d3_add(d3_add(d3_scale(f->u, b.x), d3_scale(f->v, b.y)), f->c);
    dvec3 m = d3_scale(d3_cross(da, db), orientation);
    double mx = d3_dot(m, axes[1]), my = d3_dot(m, axes[2]), len = hypot(mx, my);
    double h = d3_dot(m, d3_sub(axes[0], f->org));
    *nx = 1.0;
    *ny = 0.0;
    if (len > 0.0 && isfinite(h / len)) {
        *nx = mx / len;
        *ny = my / len;
        *r = -h / len;
    } else *r = h > 0.0 ? -INFINITY : INFINITY; /* also a zero edge (h = 0): no inner side */
}

/* sample_set=shared, masks=hough: the kept samples the polygon hides by the
 * stored table (one lookup per edge, the AND of their masks), ORed into the
 * view sample's bitmask. */
static void hide_by_table(Mapped *m, const P2 *q, int np, double orientation, const dvec3 axes[3])
{
    const HoughTable *t = m->table;
    uint64_t in[WORDS];
    for (int w = 0; w < t->words; w++) in[w] = m->kept[w] & ~m->blocked[w];
    for (int e = 0; e < np; e++) {
        double nx, ny, r;
        int k, j;
        light_plane_line(&m->lp.f, q[e], q[(e + 1) % np], orientation, axes, &nx, &ny, &r);
        hough_quantise(nx, ny, r, t->bins, t->range, &k, &j);
        const uint64_t *mask = table_entry(t, k, j);
        for (int w = 0; w < t->words; w++) in[w] &= mask[w];
    }
    for (int w = 0; w < t->words; w++) {
        m->blocked[w] |= in[w];
        m->open -= __builtin_popcountll(in[w]);
    }
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
        double dx = q[(e + 1) % np].x - q[e].x, dy = q[(e + 1) % np].y - q[e].y;
        double len = sqrt(dx * dx + dy * dy); /* |q| < 1e100 (callers): no overflow, and cheaper than hypot */
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
        *lo = (P2){c.x < lo->x ? c.x : lo->x, c.y < lo->y ? c.y : lo->y}; /* c is finite (cosine > 1e-12) */
        *hi = (P2){c.x > hi->x ? c.x : hi->x, c.y > hi->y ? c.y : hi->y};
    }
}

/* sample_set=shared, masks=hough: can the stored table's lookups hide no
 * sample? The polygon (normalised frame) projected from org onto the light's
 * plane, where every corner's direction D meets it in front (D . n_l of the
 * sign of (C - org) . n_l), and widened by hough_bounds there (the same
 * lines, quantised in the same bins, |a_i| < range), misses the samples'
 * bounds: then no sample is inside every quantised line. A corner that
 * meets the plane behind org, never, or past 1e100: no cull. */
static bool table_misses(const Mapped *m, const P2 *q, int np, const dvec3 axes[3])
{
    const HoughTable *t = m->table;
    const Frame *f = &m->lp.f;
    dvec3 normal = d3_cross(axes[1], axes[2]), to_c = d3_sub(axes[0], f->org);
    double height = d3_dot(to_c, normal), area = 0.0;
    P2 pq[4], lo, hi;
    for (int k = 0; k < np; k++) {
        dvec3 d = d3_add(d3_add(d3_scale(f->u, q[k].x), d3_scale(f->v, q[k].y)), f->c);
        double dn = d3_dot(d, normal), lambda = height / dn;
        if (!(lambda > 0.0) || !isfinite(lambda)) return false;
        dvec3 hit = d3_sub(d3_scale(d, lambda), to_c); /* relative to the light's centre */
        pq[k] = (P2){d3_dot(hit, axes[1]), d3_dot(hit, axes[2])};
        if (!(fabs(pq[k].x) < 1e100 && fabs(pq[k].y) < 1e100)) return false;
    }
    for (int k = 1; k + 1 < np; k++) area += exact_orient(pq[0], pq[k], pq[k + 1]);
    if (area == 0.0) return false;
    hough_bounds(pq, np, area > 0.0 ? 1.0 : -1.0, t->bins, t->range, &lo, &hi);
    return hi.x < t->lo.x || lo.x > t->hi.x || hi.y < t->lo.y || lo.y > t->hi.y;
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

/* Triangle t backprojected from view sample m into its light frame; axes:
 * the light's centre and plane axes (the stored table's; light_plane_axes). */
static void map_triangle(Mapped *m, const vec3 *tri, bool front_only, const dvec3 axes[3])
{
    work_influence(1); /* one pair of the triangle's influence region, on either mask path */
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
    if (!m->hough_normals && !m->table && misses_samples(&m->lp, lo, hi)) return;
    for (int k = 1; k + 1 < np; k++) area += exact_orient(q[0], q[k], q[k + 1]);
    if (area == 0.0) return;
    double orientation = area > 0.0 ? 1.0 : -1.0;
    if (m->table) { /* the papers' lookups, once the quantised polygon may hold a sample */
        if (!table_misses(m, q, np, axes)) hide_by_table(m, q, np, orientation, axes);
        return;
    }
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

/* Kept light samples whose bit in mask is set. */
static int count_kept(const uint64_t *mask, const LightPoints *lp)
{
    int c = 0;
    for (int i = 0; i < lp->n; i++) c += lp->above[i] && ((mask[i / 64] >> (i % 64)) & 1) != 0;
    return c;
}

/* The view sample's visibility per channel from its bitmask: the kept
 * unblocked samples' colours over all kept samples' (light_bitmask_visibility). */
static void bitmask_visibility(const Mapped *m, int channels, float *out)
{
    vec3 colour[EXACT_MAX_SAMPLES];
    for (int i = 0; i < m->lp.n; i++) colour[i] = m->lp.ls[i].vis_weight;
    light_bitmask_visibility(colour, m->kept, m->blocked, m->lp.n, channels, out);
}

static void store_all(float *out, int channels, float v)
{
    for (int c = 0; c < channels; c++) out[c] = v;
}

/* Maps every caster chunk onto the tile's `count` view samples. */
static void map_tile(const ExactCasters *cs, const TechContext *ctx, Mapped *tile, int count, VsmState *st)
{
    dvec3 axes[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    vec3 centre, e1, e2;
    if (light_plane_axes(ctx->light, &centre, &e1, &e2)) {
        axes[0] = d3_from(centre);
        axes[1] = d3_from(e1);
        axes[2] = d3_from(e2);
    }
    for (int k = 0; k < count; k++) {
        Mapped *m = &tile[k];
        memset(m->blocked, 0, sizeof m->blocked);
        memset(m->near, 0, sizeof m->near);
        memset(m->kept, 0, sizeof m->kept);
        m->reached = exact_begin(cs, ctx, m->s, &m->lp);
        if (m->reached) {
            exact_draw(&m->lp, ctx, m->s);
            bin_samples(m);
            for (int i = 0; i < m->lp.n; i++) m->kept[i / 64] |= (uint64_t)m->lp.above[i] << (i % 64);
        }
        m->open = m->reached ? m->lp.kept : 0;
        m->hough_normals = st->hough_normals;
        m->table = st->table;
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
                    if (exact_triangle_reaches(cs, t, &m->lp)) map_triangle(m, &cs->tri[3 * t], front_only[k], axes);
            }
    }
    for (int k = 0; k < count; k++) {
        Mapped *m = &tile[k];
        const LightPoints *lp = &m->lp;
        float *vis = st->vis + (size_t)m->s * (size_t)ctx->channels;
        st->near[m->s] = 0.0f;
        if (!m->reached) store_all(vis, ctx->channels, 1.0f);
        else if (lp->kept == 0) store_all(vis, ctx->channels, exact_sliver_visibility(cs, ctx, m->s, lp));
        else {
            bitmask_visibility(m, ctx->channels, vis);
            st->near[m->s] = (float)(count_kept(m->near, lp) + lp->off_axis);
        }
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
    const HoughTable *table = NULL;
    bool hough = ctx->params[VSM_P_MASKS] == VSM_MASKS_HOUGH;
    if (hough && ctx->params[EXACT_P_SAMPLE_SET] == EXACT_SET_SHARED) {
        SamplingPattern pattern = (SamplingPattern)ctx->params[EXACT_P_PATTERN];
        if (!sampling_check_count(pattern, (int)ctx->params[EXACT_P_SAMPLES], err) || !(table = acquire_table(ctx, err)))
            return false;
    } else if (hough && !(normals = res_point_table(ctx->rm, "view_sample_mapping hough normals", hough_fill_normals,
                                                    (int)ctx->params[VSM_P_HOUGH_BINS], err)))
        return false;
    ExactCasters cs;
    if (!exact_casters_init(ctx, false, &cs, err)) return false;
    VsmState *st = calloc(1, sizeof *st);
    if (st) {
        st->hough_normals = normals;
        st->table = table;
    }
    bool ok = st && (st->vis = malloc(sizeof *st->vis * (size_t)ctx->vs->count * (size_t)ctx->channels)) &&
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
        memcpy(out + (size_t)(s - begin) * (size_t)ctx->channels, st->vis + (size_t)s * (size_t)ctx->channels,
               sizeof *out * (size_t)ctx->channels);
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
    .rgb = true,
    .lights = LIGHTS_AREA,
    .main_param = "samples",
    .prepare = vsm_prepare,
    .evaluate = vsm_evaluate,
    .release = vsm_release,
    .aux = vsm_aux,
};
