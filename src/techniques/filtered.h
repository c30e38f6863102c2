/* filtered.h -- what the prefiltered shadow-map techniques of course ch.4
 * (vsm, lvsm, evsm, msm in vsm.c; esm.c; csm.c) share: the filter's
 * parameters, declared once and expanded after SMAP_MAP_PARAMS and
 * SMAP_DEPTH_BIAS_PARAMS (no receiver plane: see below); the chain of keyed resources depth map -> moment map ->
 * box blur or SAT (resources/maps/prefilter.h); and the lookup of a view sample:
 * its normalised reference depth and the window's filtered moments.
 *
 * The reference depth is the lead's biased smap_receiver depth at the
 * sample; per-texel receiver-plane depths exist only where a technique tests
 * texels one by one, so only esm (its PCF fallback) declares receiver_plane,
 * among its own parameters. */
#ifndef SL_FILTERED_H
#define SL_FILTERED_H
#include "resources/maps/prefilter.h"
#include "techniques/smap.h"

extern const char *const filter_prefilter_names[];
extern const char *const filter_lookup_names[];
extern const char *const filter_precision_names[];
extern const char *const filter_resources[];

enum { FILTER_LOOKUP_NEAREST, FILTER_LOOKUP_BILINEAR };

#define FILTER_PARAMS(prefilter_default)                                                                          \
    {"K", PARAM_INT, 5, 1, PREFILTER_MAX_K, "texels",                                                               \
     "filter width: the window covers K x K texels, the same texels as pcf's box (lookup=nearest) or pcf's "       \
     "bilinear kernel (lookup=bilinear) of the same K",                                                            \
     NULL},                                                                                                        \
    {"prefilter", PARAM_ENUM, prefilter_default, 0, 1, "",                                                          \
     "box: a separable K x K blur, one per K; sat: one summed-area table for every K (course ch.4 box "            \
     "'Fast-box Filter Approximations': four lookups per window)",                                                 \
     filter_prefilter_names},                                                                                      \
    {"lookup", PARAM_ENUM, FILTER_LOOKUP_BILINEAR, 0, 1, "",                                                        \
     "nearest: the K x K window at the sample's texel; bilinear: hardware-style 2x2 taps of the prefiltered "      \
     "map, (K+1)^2 texels with a tent rim",                                                                        \
     filter_lookup_names},                                                                                         \
    {"precision", PARAM_ENUM, 0, 0, 1, "",                                                                          \
     "moments and prefiltered sums in f64, or in f32 (a SAT's partial sums rounded to float, as on a GPU; "        \
     "catalogue: an fp32 SAT destroys moment differences)",                                                        \
     filter_precision_names}

enum { FILTER_P_K = SMAP_NUM_DEPTH_BIAS_PARAMS, FILTER_P_PREFILTER, FILTER_P_LOOKUP, FILTER_P_PRECISION, FILTER_NUM_PARAMS };

/* A technique's parameter table fits the registry's limit (the shared map
 * parameters grow as the lead adds remedies). */
#define FILTER_CHECK_TABLE(table) \
    _Static_assert(sizeof table / sizeof table[0] <= TECH_MAX_PARAMS, #table ": more than TECH_MAX_PARAMS")

typedef struct FilteredMaps {
    const ShadowMap *map;
    const Prefiltered *pf;
    SmapBias bias;
    int K;
    bool bilinear;
} FilteredMaps;

/* Acquire the depth map, the moment map of `spec` (its precision taken
 * from the parameters) and its prefiltered form; fm->bias without the
 * receiver plane (smap_depth_bias). */
bool filtered_acquire(const TechContext *ctx, MomentSpec spec, FilteredMaps *fm, Error *err);

/* A view sample seen through the filtered map. */
typedef struct FilteredSample {
    SmapReceiver r;
    PfFootprint fp;
    double u;                        /* normalised reference depth, [0, 1] */
    bool reliable;                   /* false: a log SAT's window is below its rounding error */
    double m[PREFILTER_MAX_CHANNELS];/* the footprint's filtered channels */
} FilteredSample;

/* false when the sample falls outside the map (the techniques call it lit). */
bool filtered_lookup(const FilteredMaps *fm, const TechContext *ctx, int s, FilteredSample *fs);

/* course Eq. 4.2, the one-sided Chebyshev (Cantelli) bound on the lit
 * fraction from a window's mean and second moment at reference d:
 * p = var / (var + (d - mean)^2) for d > mean, else 1, with the variance
 * (the text's "sigma", erratum 1) clamped below by min_variance; NaN when
 * a moment or d is NaN (a NaN depth in the window). */
double chebyshev_upper(double mean, double m2, double d, double min_variance);
/* EVSM's two bounds (course §4.2.4): Chebyshev on the positive warp
 * e^(c+ (u - 1)) from moments m[0], m[1], and on the negative warp
 * -e^(-c- u) from m[2], m[3], at the receiver's normalised depth u, each
 * with the variance clamp scaled by the warp's slope there (w' = c w). */
double evsm_positive_bound(const double *m, double u, double c_pos, double min_variance);
double evsm_negative_bound(const double *m, double u, double c_neg, double min_variance);
/* course §4.2.2: light-bleeding reduction, p < amount -> 0 and [amount, 1]
 * smoothstep-remapped onto [0, 1]; amount 0 leaves p unchanged. */
double bleed_reduce(double p, double amount);

/* ---- Hamburger four-moment reconstruction (msm, moment_soft) ----
 * Peters & Klein 2015, Algorithm 2 (Hamburger 4MSM), with the authors'
 * erratum. b: a window's moments of the signed depth z = 2u - 1; zf: the
 * receiver's z; alpha: the moment bias b' = (1 - alpha) b + alpha (0, 0.63,
 * 0, 0.63). Solving B c = (1, zf, zf^2) for the Hankel matrix B of b' gives
 * the roots z2 <= z3 of c1 + c2 x + c3 x^2; the three-point distribution on
 * {zf, z2, z3} with moments b' is the one that bounds the shadow below. */

/* The lit fraction 1 - G, G the weight of that distribution in front of zf
 * (the sharpest lower bound on the shadow); NaN for a NaN moment or zf. */
double msm_lit(const double *b, double zf, double alpha);
/* The blocker search of Peters et al. 2016 (I3D, §5, moment soft shadow
 * mapping; the authors' shader, Compute4MomentAverageBlockerDepth): the
 * same distribution's weight in front of zf, *blocked = G = sum of w_i over
 * the roots z_i < zf, and the mean depth of that weight, *z_mean =
 * sum w_i z_i / G (signed depth). false when the quadratic is degenerate
 * (no finite weights: the caller falls back on two moments, as msm_lit
 * does); a NaN moment or zf gives NaN results (true). *z_mean is NaN for
 * G = 0. */
bool msm_blockers(const double *b, double zf, double alpha, double *blocked, double *z_mean);

#endif
