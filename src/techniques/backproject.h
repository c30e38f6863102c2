/* backproject.h -- seed 000 §1.1 (Aszódi & Szirmay-Kalos): an elementary
 * caster, the part of a surface one shadow-map lexel sees, projected from
 * the receiver r back onto the shadow-map plane z = n, in the light's frame
 * (softmap.h: origin at the light's centre, z along the map's axis). Its
 * position and size are the paper's
 *     size = (r_z - n) / (r_z - c_z) * c_z / n,
 *     l_r  = (n - c_z) / (r_z - c_z) * r + size * l,
 * where l is the lexel on the plane (Eq. 4: l = c n / c_z). With q = r n / r_z,
 * the receiver's own lexel, the coefficients of r add up so that
 *     l_r - q = size * (l - q)      (the r terms: (n - c_z)/(r_z - c_z) + size n / r_z = n / r_z),
 * the form used here: it never subtracts two numbers that grow as c_z -> r_z.
 * Sizes and offsets are in lexels; the plane's lexel grid is the map's. */
#ifndef SL_BACKPROJECT_H
#define SL_BACKPROJECT_H
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include "techniques/softmap.h"

/* The stiff case r_z - c_z -> 0 (contact, self-shadowing): a caster at the
 * receiver's depth or behind it cannot lie between r and the light (every
 * point of a segment from r to the light's plane z = 0 has depth < r_z), so
 * it is skipped; a caster closer than this fraction of r_z is held there,
 * so size stays finite (at most ~1e9 c_z / n lexels): it then covers the
 * whole neighbourhood, which is the right limit. */
#define BACKPROJECT_MIN_GAP 1e-9

typedef struct Backprojected {
    double size;   /* the caster's side seen from r, in lexels of the plane */
    double di, dj; /* l_r - q in lexels */
} Backprojected;

/* Caster at depth c_z whose lexel lies (di, dj) lexels from q, receiver at
 * depth r_z, plane at n (0 < n < r_z). false: it cannot occlude. */
static inline bool backproject(double r_z, double c_z, double n, double di, double dj, Backprojected *out)
{
    double gap = r_z - c_z;
    if (!(gap > 0.0) || !(c_z > 0.0)) return false;
    gap = fmax(gap, BACKPROJECT_MIN_GAP * r_z);
    out->size = (r_z - n) / gap * c_z / n;
    out->di = out->size * di;
    out->dj = out->size * dj;
    return true;
}

/* Assumption 1 of seed 000 §1.1: the plane n at which the light, seen from a
 * receiver at depth r_z, covers the K x K lexel neighbourhood. From r the
 * light (half-extent a in its plane z = 0) projects onto the plane z = n
 * with half-extent a (r_z - n) / r_z, i.e. a (r_z - n) / (r_z n) in tangent
 * units; setting that to the kernel's half-width h = K dx / 2 gives
 *     n = a r_z / (a + r_z h),
 * which is the paper's "n proportional to R" (n = 2R / (K dx)) when
 * r_z h >> a. The additive factor does not depend on n at all (planes z = 0
 * and z = n are parallel, so the projection from r between them is a
 * similarity that scales l_r - q, size and the light alike); the occlusion
 * bits do: n sets how many lexels the light's footprint D holds, here about
 * pi K^2 / 4. The kernel reaches (to half a lexel) every caster that can
 * occlude r and lies farther from the light than n. */
static inline double backproject_plane(double half_world, double r_z, double half_tangent)
{
    return half_world * r_z / (half_world + r_z * half_tangent);
}

/* The same projection onto the light's own plane z = 0 (course §5.2.3.1,
 * [OWN] backprojection: L_xy = (p_z X_xy - z p_xy) / (p_z - z), p the
 * receiver, X a caster point at depth z). With X = x z and p = u p_z (x, u
 * tangents of the face) it is L = k (x - u), k = z p_z / (p_z - z): the
 * caster's tangent offset from the receiver times k (world units on the
 * light's plane). Singular as z -> p_z: guarded as backproject() is (a
 * caster at or behind the receiver cannot occlude: false; closer than
 * BACKPROJECT_MIN_GAP p_z: held there). */
static inline bool backproject_light_scale(double p_z, double z, double *k)
{
    double gap = p_z - z;
    if (!(gap > 0.0) || !(z > 0.0)) return false;
    gap = fmax(gap, BACKPROJECT_MIN_GAP * p_z); /* gap > 0 here: no NaN reaches fmax */
    *k = z * p_z / gap;
    return true;
}

/* Half-width (tangent units) of the light's footprint, seen from a receiver
 * at depth r_z, on the casters at depth z: half_world (r_z - z) / (r_z z),
 * the similar triangles of backproject_plane with n = z (PCSS's search area,
 * course §5.2.2; [OWN] width of course §5.2.3.4). */
static inline double backproject_footprint(double half_world, double r_z, double z)
{
    return half_world * (r_z - z) / (r_z * z);
}

/* Half-widths (texels, level 0) of the footprint at depth z_b, plus one
 * texel for the receiver's own, at most the map's size (NaN: 0, the own texel). */
static inline void backproject_search_halfwidth(const SoftMap *sm, const SmapReceiver *r, double z_b, int *wi,
                                                int *wj)
{
    const SoftFace *f = &sm->face[r->mc.face];
    double r_z = r->mc.depth_linear;
    double ri = ceil(backproject_footprint(f->light.half_x, r_z, z_b) / f->dx) + 1.0;
    double rj = ceil(backproject_footprint(f->light.half_y, r_z, z_b) / f->dy) + 1.0;
    *wi = ri >= 0.0 ? (int)fmin(ri, sm->map->res) : 0; /* NaN compares false: 0 */
    *wj = rj >= 0.0 ? (int)fmin(rj, sm->map->res) : 0;
}

/* Bounds (stored depth) over texels [i0, i1] x [j0, j1] of a face from some
 * min-max structure: the min-max pyramid's 2 x 2 nodes (HSM), or the
 * multiscale levels of course §5.2.3.4 (MSSM, YSM). */
typedef void (*BackprojectBounds)(const void *structure, int face, int i0, int j0, int i1, int j1, float *zmin,
                                  float *zmax);

static inline void backproject_pyramid_bounds(const void *pyramid, int face, int i0, int j0, int i1, int j1,
                                              float *zmin, float *zmax)
{
    minmax_query(pyramid, face, i0, j0, i1, j1, zmin, zmax);
}

/* The search area (course §5.2.3.4, Fig. 5.9): the light's footprint on the
 * face's near plane, narrowed (three passes) through the plane of the
 * minimum z_min that `bounds` gives over the texels that footprint spans:
 * no blocker of r lies nearer the light than *z_b (world units), so the
 * footprint at *z_b holds every texel that can occlude r. false: nothing in
 * reach can block r (z_p <= z_min: lit); *z_b is then the last plane. */
static inline bool backproject_search_in(const SoftMap *sm, BackprojectBounds bounds, const void *structure,
                                         const SmapReceiver *r, double *z_b)
{
    const SoftFace *f = &sm->face[r->mc.face];
    double r_z = r->mc.depth_linear;
    int i, j;
    smap_texel(r, &i, &j);
    *z_b = f->near_world;
    for (int pass = 0; pass < 3 && *z_b < r_z; pass++) {
        int wi, wj;
        backproject_search_halfwidth(sm, r, *z_b, &wi, &wj);
        float zmin, zmax;
        bounds(structure, r->mc.face, i - wi, j - wj, i + wi, j + wj, &zmin, &zmax);
        double z_min;
        if (!softmap_bounds_may_block(sm, r, zmin, i - wi, j - wj, i + wi, j + wj, &z_min)) return false;
        if (z_min > *z_b) *z_b = z_min; /* NaN: not narrowed, the wider area keeps every blocker (issue 13 §1) */
    }
    return true;
}

/* The search through the map's min-max pyramid (HSM's query). */
static inline bool backproject_search(const SoftMap *sm, const SmapReceiver *r, double *z_b)
{
    return backproject_search_in(sm, backproject_pyramid_bounds, sm->pyramid, r, z_b);
}

/* Occlusion bitmasks' light samples (Schwarz & Stamminger 2007, course
 * §5.2.3.2: "256 regularly jittered sample points corresponding to an 8x8
 * tiling of the 2x2 rotated grid (RGSS) pattern"): sample k of
 * 4 tiles^2 in [-1, 1]^2, tile k / 4 (row-major), RGSS offset k % 4 within
 * it (one sample per row and per column quarter of the tile). Disk-shaped
 * lights (sphere cross-sections, disks) take the square through Shirley &
 * Chiu's concentric map (1997), which keeps areas, so every sample still
 * stands for 1/N of the light. The light point is then x = M xi (softmap.h). */
#define BACKPROJECT_MAX_SAMPLES 1024 /* tiles <= 16 */

static inline void backproject_light_sample(int tiles, int k, bool square, double *x, double *y)
{
    static const double rgss[4][2] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
    int t = k / 4;
    double a = -1.0 + 2.0 * (t % tiles + rgss[k % 4][0]) / tiles;
    double b = -1.0 + 2.0 * (t / tiles + rgss[k % 4][1]) / tiles;
    if (square) {
        *x = a;
        *y = b;
        return;
    }
    double r, phi; /* concentric map: the square's rings onto the disk's */
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = M_PI / 4.0 * (b / a);
    } else {
        r = b;
        phi = M_PI / 2.0 - M_PI / 4.0 * (a / b); /* b != 0: the RGSS offsets never hit the centre */
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* ---- arithmetic-only bitmasks of axis-aligned rectangles ------------------
 * Schwarz & Stamminger 2007 (course §5.2.3.2): "arithmetic-only updates for
 * axis-aligned images". [OWN] CPU form (catalogue §5.2.3.2: "4xu64 per mask,
 * built from row/column ranges"): with the N light samples sorted by x,
 * below_x[k] is the mask of the first k of them, i.e. of every sample whose
 * x lies below sorted x[k]; the samples with x < t are then below_x[lower
 * bound of t], those with x >= t its complement, and a rectangle
 * [xlo, xhi) x [ylo, yhi) (the half-open rule of backprojection.c's cover())
 * is
 *     (below_x(xhi) & ~below_x(xlo)) & (below_y(yhi) & ~below_y(ylo)),
 * four binary searches and 4 x 4 word operations at N = 256 whatever the
 * rectangle's size. Coordinates: the light's plane, face axes (world units). */
#define BACKPROJECT_WORDS (BACKPROJECT_MAX_SAMPLES / 64)

typedef struct BackprojectPrefix {
    int n, words;                             /* samples; words = ceil(n / 64) per mask */
    double x[BACKPROJECT_MAX_SAMPLES];        /* the samples' x, ascending */
    double y[BACKPROJECT_MAX_SAMPLES];        /* their y, ascending */
    uint64_t below_x[(BACKPROJECT_MAX_SAMPLES + 1) * BACKPROJECT_WORDS]; /* row k (words each): the first k by x */
    uint64_t below_y[(BACKPROJECT_MAX_SAMPLES + 1) * BACKPROJECT_WORDS];
} BackprojectPrefix;

typedef struct BackprojectKey { double v; int sample; } BackprojectKey;

static inline int backproject_key_order(const void *a, const void *b)
{
    double u = ((const BackprojectKey *)a)->v, w = ((const BackprojectKey *)b)->v;
    return (u > w) - (u < w);
}

/* One axis: coordinates v[0..n) (finite) sorted into sorted[], prefix masks into below[]. */
static inline void backproject_prefix_axis(const float *v, int n, int words, double *sorted, uint64_t *below)
{
    BackprojectKey key[BACKPROJECT_MAX_SAMPLES];
    for (int k = 0; k < n; k++) key[k] = (BackprojectKey){v[k], k};
    qsort(key, (size_t)n, sizeof key[0], backproject_key_order);
    for (int w = 0; w < words; w++) below[w] = 0;
    for (int k = 0; k < n; k++) {
        sorted[k] = key[k].v;
        uint64_t *row = below + (size_t)(k + 1) * words;
        for (int w = 0; w < words; w++) row[w] = row[w - words];
        row[key[k].sample >> 6] |= 1ull << (key[k].sample & 63);
    }
}

/* The prefix masks of n <= BACKPROJECT_MAX_SAMPLES samples at (x[k], y[k]). */
static inline void backproject_prefix_init(BackprojectPrefix *pm, const float *x, const float *y, int n)
{
    pm->n = n;
    pm->words = (n + 63) / 64;
    backproject_prefix_axis(x, n, pm->words, pm->x, pm->below_x);
    backproject_prefix_axis(y, n, pm->words, pm->y, pm->below_y);
}

/* How many of the ascending v[0..n) lie below t (t not NaN). */
static inline int backproject_count_below(const double *v, int n, double t)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (v[mid] < t) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* OR into mask (NULL: none) the samples in [xlo, xhi) x [ylo, yhi); returns
 * how many there are. A NaN bound or an empty range holds none (as the
 * per-sample comparisons, which NaN fails). */
static inline int backproject_rect_mask(const BackprojectPrefix *pm, double xlo, double xhi, double ylo, double yhi,
                                        uint64_t *mask)
{
    if (!(xlo < xhi && ylo < yhi)) return 0;
    int w = pm->words;
    const uint64_t *x0 = pm->below_x + (size_t)backproject_count_below(pm->x, pm->n, xlo) * w;
    const uint64_t *x1 = pm->below_x + (size_t)backproject_count_below(pm->x, pm->n, xhi) * w;
    const uint64_t *y0 = pm->below_y + (size_t)backproject_count_below(pm->y, pm->n, ylo) * w;
    const uint64_t *y1 = pm->below_y + (size_t)backproject_count_below(pm->y, pm->n, yhi) * w;
    int marked = 0;
    for (int k = 0; k < w; k++) {
        uint64_t in = x1[k] & ~x0[k] & y1[k] & ~y0[k];
        if (mask) mask[k] |= in;
        marked += __builtin_popcountll(in);
    }
    return marked;
}

#endif
