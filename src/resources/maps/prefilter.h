/* prefilter.h -- what filtered shadow maps (course ch.4) build from a depth
 * map, each a keyed resource derived from the ShadowMap's key: moment maps
 * (per-texel warps of the depth: powers, layers, exponentials, Fourier
 * bases, or a log-exponential channel for ESM), their prefiltered forms (a
 * separable K x K box blur, or a summed-area table that serves every K), and
 * a min-max mip pyramid or one N-buffer level of the depth (ESM's
 * classifiers, §4.2.4). So a sweep over K builds one moment map and one SAT;
 * a box blur is keyed by K.
 *
 * Depth is normalised per face, u = (z - near) / (far - near) in [0, 1]
 * (linear maps; ndc maps store u = z_ndc), the course's convention for
 * ch.4 (CSM depths in [0, 1], ESM's c = 80); empty texels (+INFINITY) are
 * the far plane, u = 1, before any moment is formed.
 *
 * Precision (f64 or f32) is the element type of the moment map and of the
 * prefiltered map, and the arithmetic of a SAT's running sums: an f32 SAT
 * rounds every partial sum to float, as a GPU would (catalogue, Prefilter
 * structures: "never use an fp32 SAT"). Box blurs sum in double and store
 * the result in the element type. SAT channels have their face mean
 * subtracted (catalogue [OWN]); log channels (ESM) are summed as
 * e^(x - x_max) with x_max the face's largest value, so nothing overflows. */
#ifndef SL_PREFILTER_H
#define SL_PREFILTER_H
#include "resources/maps/shadowmap.h"

#define PREFILTER_MAX_K 63         /* the widest window, texels (pcf's K) */
#define PREFILTER_PAD (PREFILTER_MAX_K / 2 + 3) /* texels of edge replication around each face */
#define PREFILTER_MAX_CHANNELS 64  /* CSM with 32 terms */
#define PREFILTER_MAX_BYTES ((size_t)2 << 30)

typedef enum MomentWarp {
    WARP_POWERS,   /* u, u^2, ... u^order (VSM: 2); with `signed_depth` powers of z = 2u - 1 (MSM: 4) */
    WARP_LAYERS,   /* LVSM (§4.2.2): per layer i of `order` uniform layers, phi_i(u) and phi_i(u)^2 */
    WARP_EXP,      /* EVSM: e^(c+ (u - 1)), e^(2 c+ (u - 1)) [, -e^(-c- u), e^(-2 c- u)] (order 2 or 4) */
    WARP_FOURIER,  /* CSM (§4.2.3, Eq. 4.6): sin(c_k u), cos(c_k u), c_k = pi (2k - 1), k = 1..order */
    WARP_LOG_EXP,  /* ESM (§4.2.4): the log of exp(c u), i.e. c u: a log channel, filtered as log-sum-exp */
    WARP_FOURIER_DEPTH, /* CSSM (course §5.2.2.3): at v = u / 2, sin(c_k v), cos(c_k v) (2 order), then u,
                           u sin(c_k v), u cos(c_k v) (2 order + 1): 4 order + 1 channels; the half depth keeps
                           |v_z - v_d| <= 1/2, inside the series' period of 2 */
} MomentWarp;

typedef struct MomentSpec {
    MomentWarp warp;
    int order;            /* see MomentWarp */
    double c_pos, c_neg;  /* exponents (EVSM c+ and c-; ESM's c is c_pos) */
    bool signed_depth;    /* WARP_POWERS: powers of 2u - 1 */
    bool slope_moment;    /* WARP_POWERS, order 2: M2 += (dx^2 + dy^2) / 4 (Lauritzen 2007, §4.2.1 box) */
    bool f64;             /* element type: double, else float */
} MomentSpec;

/* Element storage: exactly one of d, f is non-NULL. */
typedef struct PfStore { double *d; float *f; } PfStore;

static inline double pf_get(const PfStore *s, size_t i) { return s->d ? s->d[i] : (double)s->f[i]; }

typedef struct MomentMap {
    uint64_t key;
    const ShadowMap *map;
    MomentSpec spec;
    int res, num_faces, channels;
    bool log;             /* channels hold logarithms (WARP_LOG_EXP) */
    PfStore data;         /* [(face * res + j) * res + i] * channels + c */
} MomentMap;

int moment_channels(const MomentSpec *spec);
/* CSM's basis at depth u: out[2k] = sin(c_k u), out[2k + 1] = cos(c_k u),
 * c_k = pi (2k + 1) for k = 0..terms-1 (course Eq. 4.6, k counted from 1 there). */
void fourier_basis(double u, int terms, double *out);
/* Normalised depth u in [0, 1] of a stored depth on a face (+INFINITY: 1). */
double prefilter_depth_unit(const ShadowMap *m, int face, double z_stored);
const MomentMap *res_moment_map(ResourceManager *rm, const ShadowMap *map, const MomentSpec *spec, Error *err);

typedef enum PrefilterKind { PREFILTER_BOX, PREFILTER_SAT } PrefilterKind;
#define PREFILTER_NAMES "box", "sat"

/* A prefiltered moment map in a padded layout: face texel (i, j) is at
 * (i + pad, j + pad) of a stride x stride grid, the border replicating the
 * edge texels as pcf's clamped lookups do. BOX: texel c holds the average
 * over the K texels starting at c - K/2 (per axis); SAT: (stride + 1)^2
 * running sums, entry (I, J) the sum over padded texels [0, I) x [0, J). */
typedef struct Prefiltered {
    uint64_t key;
    const MomentMap *moments;
    PrefilterKind kind;
    int K;                /* BOX only; 0 for SAT */
    int res, pad, stride, num_faces, channels;
    bool log, f64;
    double *offset;       /* [face * channels + c]: the mean subtracted (SAT) or x_max (log SAT); else 0 */
    double sat_rel_error; /* log SAT: a window sum below this times its largest corner is rounding noise */
    PfStore data;
} Prefiltered;

const Prefiltered *res_prefiltered(ResourceManager *rm, const MomentMap *moments, PrefilterKind kind, int K,
                                   Error *err);

/* The texels a lookup at map coordinates (s, t) averages, matching pcf's
 * kernels of the same K: nearest, the K x K box starting at (i0, j0) =
 * floor((s, t) - K/2 + 1/2); bilinear, hardware 2x2 taps over K x K, i.e.
 * boxes starting at i0 and i0 + 1 (and j0, j0 + 1) weighted (1 - ax, ax). */
typedef struct PfFootprint {
    int K, i0, j0;
    double ax, ay;        /* 0 for nearest */
    bool bilinear;
} PfFootprint;

PfFootprint pf_footprint(double s, double t, int K, bool bilinear);
/* Weight of texel i0 + k (k = 0..K, the last only when bilinear) along one axis. */
static inline double pf_weight(const PfFootprint *fp, int k, double a)
{
    if (!fp->bilinear) return k < fp->K ? 1.0 : 0.0;
    return k == 0 ? 1.0 - a : k == fp->K ? a : 1.0;
}

/* The footprint's weighted average of every channel into out[channels]
 * (log channels: the log of the average of their exponentials). false when
 * a log SAT's window sum is below its rounding error (ESM falls back to
 * PCF there); the values are then still finite. */
bool pf_fetch(const Prefiltered *pf, int face, const PfFootprint *fp, double *out);

/* The box average of every channel over the continuous window
 * [s - hx, s + hx] x [t - hy, t + hy] of a face (map texel units: texel i
 * covers [i, i + 1]), from a SAT of linear channels: the SAT is the integral
 * of the piecewise-constant texels at integer corners, and that integral is
 * bilinear inside each texel, so the SAT interpolated bilinearly at the four
 * fractional corners is the exact sum with fractional edge weights (pcss's
 * exhaustive box, course §5.2.2.2: "any rectangle in four texture fetches").
 * The first `channels` channels; half-widths in (0, PREFILTER_MAX_HALF]
 * texels; false (out untouched) for a box blur, a log channel, a channel
 * count outside [1, pf->channels] or a half-width outside that range. */
#define PREFILTER_MAX_HALF (PREFILTER_MAX_K / 2.0)
bool pf_fetch_box(const Prefiltered *pf, int face, double s, double t, double hx, double hy, int channels,
                  double *out);

/* Min and max of the stored depth over mip levels (+INFINITY kept): the
 * window max for ESM's conservative classifier, the min for a lit early-out. */
typedef struct MinMaxPyramid {
    uint64_t key;
    int res, num_faces, levels;
    int size[32];         /* texels per side at each level */
    size_t offset[32];    /* start of each level (per face: faces * size^2 pairs) */
    float *minmax;        /* pairs (min, max) */
} MinMaxPyramid;

const MinMaxPyramid *res_minmax_pyramid(ResourceManager *rm, const ShadowMap *map, Error *err);
/* Conservative bounds of the stored depth over texels [i0, i1] x [j0, j1]
 * (clamped to the face: the same texels as an edge-clamped window). */
void minmax_query(const MinMaxPyramid *p, int face, int i0, int j0, int i1, int j1, float *zmin, float *zmax);
/* The level minmax_query reads for texels [i0, i1] x [j0, j1] (clamped to
 * the face): the finest whose nodes cover them with at most 2 x 2 (HSM's
 * query, course §5.2.3.4). */
int minmax_query_level(const MinMaxPyramid *p, int i0, int j0, int i1, int j1);
/* The minimum of node (*i, *j) of `level` (clamped to the level's grid: an
 * edge-clamped read), and in *i, *j the level-0 texel that holds it, found by
 * descending through the children (for a test at that texel's own reference:
 * seed 000's closest caster of a coarse lexel). */
float minmax_node_min(const MinMaxPyramid *p, int face, int level, int *i, int *j);

/* One level of an N-buffer (Decoret 2005; course ch.4 box "Fast-box Filter
 * Approximations"): the min and max of the stored depth over the 2^level x
 * 2^level texels starting at each texel (edge-clamped), at full resolution.
 * A window's bounds are then exact from a few overlapping blocks, where the
 * mip pyramid's aligned nodes cover up to four times the window. */
typedef struct MinMaxBuffer {
    uint64_t key;
    int res, num_faces, level;
    float *minmax;        /* pairs (min, max), [(face * res + j) * res + i] */
} MinMaxBuffer;

/* The level a K-wide window reads: blocks no wider than half the window. */
int minmax_buffer_level(int K);
const MinMaxBuffer *res_minmax_buffer(ResourceManager *rm, const ShadowMap *map, int level, Error *err);
/* Exact bounds over texels [i0, i1] x [j0, j1], clamped to the face
 * (conservative only for windows narrower than a block). */
void minmax_buffer_query(const MinMaxBuffer *b, int face, int i0, int j0, int i1, int j1, float *zmin, float *zmax);

/* Every N-buffer level of one min-max pyramid level `base` (the MSSM of
 * course §5.2.3.4, Schwarz & Stamminger 2008: "level i holds min/max over a
 * 2^i x 2^i window ... at full resolution"; YSM's "MSSM from HSM level
 * n - 1" for base = n - 1): level k holds, at each node (x, y) of the base
 * level, the min and max over nodes [x, x + 2^k) x [y, y + 2^k), indices
 * clamped to the face (Decoret 2005's doubling, as res_minmax_buffer),
 * k = 0 .. levels - 1 with 2^(levels - 1) >= the base level's size. A
 * window at any position then has exact bounds from 4 entries, and a coarse
 * lexel needs no alignment to the quadtree. Memory: levels x faces x size^2
 * pairs of floats, 88 MiB per face at 1024^2; refused above
 * MINMAX_LEVELS_MAX_RES nodes a side (the course: MSSM is "too expensive
 * for ... greater than 1024^2"). */
#define MINMAX_LEVELS_MAX_RES 1024
typedef struct MinMaxLevels {
    uint64_t key;
    int base, res, num_faces, levels; /* res: nodes per side of the base level */
    float *minmax;        /* pairs (min, max), [((k * faces + face) * res + y) * res + x] */
} MinMaxLevels;

const MinMaxLevels *res_minmax_levels(ResourceManager *rm, const MinMaxPyramid *p, int base, Error *err);
/* Exact bounds over base-level nodes [x0, x1] x [y0, y1], clamped to the
 * face: the four overlapping windows of level floor(log2 width). */
void minmax_levels_query(const MinMaxLevels *m, int face, int x0, int y0, int x1, int y1, float *zmin, float *zmax);
/* The minimum of level k's window at node (*x, *y) (clamped to the face),
 * and in *x, *y the base-level node that holds it, found by descending
 * through the four half-size windows each level was doubled from (the
 * first in scan order on ties). */
float minmax_levels_min(const MinMaxLevels *m, int face, int k, int *x, int *y);

#endif
