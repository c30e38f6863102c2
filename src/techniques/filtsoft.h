/* filtsoft.h -- what the constant-time filtered soft shadows share
 * (pcss_prefiltered, cssm, evssm: course §5.2.2.2-3; dpcf, Filament's
 * distance-based PCF): PCSS's geometry (course §5.2.2, pcss.c) in a map
 * face's tangent frame (softmap.h) and the windows it sets, in texels:
 *   search half-width a (z_p - z_n) / (z_p z_n) / dx (the light-receiver
 *   pyramid on the near plane z_n, then on the window's nearest depth,
 *   course §5.2.3.4's search area through z_min: filtsoft_search),
 *   filter half-width a (z_p - z_avg) / (z_avg z_p) / dx (w_f = w_penumbra
 *   z_n / z_p with w_penumbra = (z_p - z_avg) / z_avg w_light),
 * both clamped to [1/2, max_radius] texels (sub-texel kernels alias; the
 * widest window a SAT's padding serves is PREFILTER_MAX_HALF). Depths z are
 * linear (world units along the face's axis); the prefiltered maps hold the
 * normalised u in [0, 1] of prefilter.h, converted by filtsoft_linear.
 *
 * A SAT answers any window in four fetches per channel (pf_fetch_box), so
 * pcss_prefiltered, cssm and evssm cost the same at every light size. */
#ifndef SL_FILTSOFT_H
#define SL_FILTSOFT_H
#include "techniques/filtered.h"
#include "techniques/softmap.h"

#define FILTSOFT_MIN_HALF 0.5 /* texels */

/* max_radius, the bound on both windows; its range ends where the SAT's padding does. */
#define FILTSOFT_MAX_RADIUS_PARAM(default_texels)                                                                  \
    {"max_radius", PARAM_FLOAT, default_texels, FILTSOFT_MIN_HALF, PREFILTER_MAX_HALF, "texels",                    \
     "bound on the search and filter half-widths: wider windows (a huge light, a receiver near the light or a "   \
     "blocker depth near 0, course §5.2.2.1) are clamped to it; at most the summed-area table's padding",         \
     NULL}

#define FILTSOFT_PRECISION_PARAM                                                                                   \
    {"precision", PARAM_ENUM, 0, 0, 1, "",                                                                          \
     "moments and summed-area tables in f64, or in f32 (partial sums rounded to float, as on a GPU; catalogue: "   \
     "an fp32 SAT destroys moment differences)",                                                                   \
     filter_precision_names}

/* The blocked fraction (`fraction`: its name in the technique's estimate,
 * e.g. "1 - p") below which filtsoft_blocker_mean calls a receiver lit. */
#define FILTSOFT_LIT_THRESHOLD_PARAM(fraction)                                                                      \
    {"lit_threshold", PARAM_FLOAT, 1e-4, 1e-9, 0.5, "fraction",                                                      \
     "the search window's " fraction " below which the receiver is lit: the blocker mean divides by it", NULL}

typedef struct FiltSoft {
    SoftMap sm;
    SmapBias bias;
    double max_radius; /* texels */
} FiltSoft;

/* Acquire the depth map of the parameters (SMAP_MAP_PARAMS first) and set
 * up its faces (perspective only, refused by name otherwise, softmap_init).
 * receiver_plane: the technique declares SMAP_BIAS_PARAMS_PLANE (a tap per
 * texel, dpcf); false for SMAP_DEPTH_BIAS_PARAMS (a prefiltered window is
 * compared with one reference depth: the receiver plane cannot act). */
bool filtsoft_init(FiltSoft *fs, const TechContext *ctx, double max_radius, bool receiver_plane, const char *tech,
                   Error *err);

/* A window about the receiver: half-widths in texels. */
typedef struct FsWindow { double hx, hy; } FsWindow;

/* The blocker search window *w and *z_min, a lower bound of every depth in
 * it (linear): the light-receiver pyramid cut at the near plane, then twice
 * at the nearest depth the min-max pyramid finds in the window so far
 * (course §5.2.3.4, as brabec's outer_limit). Exact: a blocker lies in the
 * window and beyond its nearest depth, so within the pyramid's cut there.
 * The near plane alone, on a map fitted to a large scene, gave the widest
 * window at every contact (the moments then mixed the receiver's own tilted
 * floor, 62 texels of it, into the blocker estimate: umbrae lit). false:
 * nothing in reach can block (lit, without a fetch). A NaN depth in reach
 * gives a NaN window and *z_min. */
bool filtsoft_search(const FiltSoft *fs, const SmapReceiver *r, FsWindow *w, double *z_min);
/* z_avg: the average blocker depth, linear; clamped first to [z_min, z_p],
 * z_min filtsoft_search's: a mean of the blockers cannot lie nearer than
 * the nearest of them. */
FsWindow filtsoft_filter_window(const FiltSoft *fs, const SmapReceiver *r, double z_avg, double z_min);

/* The receiver's normalised reference depth u in [0, 1] (prefilter.h). */
double filtsoft_unit(const FiltSoft *fs, const SmapReceiver *r);
/* Normalised depth u of the receiver's face back to linear depth. */
double filtsoft_linear(const FiltSoft *fs, int face, double u);

/* Acquire the moment map of `spec` and its SAT. */
const Prefiltered *filtsoft_sat(const TechContext *ctx, const FiltSoft *fs, MomentSpec spec, Error *err);

/* Yang et al. 2010 (VSSM, §4, the blocker estimate): in a window of mean
 * mean_all, a fraction lit of texels at (or behind) the receiver's d and the
 * rest, the blockers, at their mean z_occ: mean_all = lit d + (1 - lit) z_occ,
 * so z_occ = (mean_all - lit d) / (1 - lit). false when 1 - lit < eps (no
 * blocker left to average, the caller's "lit"); a NaN input gives a NaN
 * z_occ, which the callers carry to a NaN result (counted non-finite). */
bool filtsoft_blocker_mean(double mean_all, double lit, double d, double eps, double *z_occ);

/* CSM's truncated step (course Eq. 4.6, csm.c) at reference d, from a
 * window's filtered basis pairs m[2k] = E w sin(c_k z), m[2k + 1] =
 * E w cos(c_k z) and the mean E w of the weight the constant term 1/2
 * multiplies (w = 1: the lit fraction; w = z: cssm's E z step(z - d)):
 *   E w / 2 + sum_k coef_k (cos(c_k d) m[2k] - sin(c_k d) m[2k + 1]),
 * coef_k = 2 exp(-a (k/M)^2) / c_k (csm's damping). */
#define FILTSOFT_MAX_TERMS ((PREFILTER_MAX_CHANNELS - 1) / 4) /* cssm's 4M + 1 channels */
void filtsoft_fourier_coefficients(int terms, double damping, double *coef);
double filtsoft_fourier_step(const double *coef, int terms, const double *m, double mean_w, double d);

/* The clamp of v to [0, 1], NaN kept (so a broken estimate shows). */
static inline double filtsoft_unit_clamp(double v) { return v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v; }

/* PCSS from one summed-area table of u and u^2 read through Chebyshev's
 * bound, with Yang et al. 2010's kernel subdivision to split_depth levels
 * (vssm.c, where the estimate is written out); pcss_prefiltered is it with
 * split_depth 0, the same function. */
typedef struct ChebSoft {
    FiltSoft fs;
    const Prefiltered *sat;
    double min_variance, lit_eps;
    int split_depth;
} ChebSoft;
/* Acquire the map, pyramid and SAT (f64 when f64) for technique `tech`. */
bool chebsoft_init(ChebSoft *cs, const TechContext *ctx, double max_radius, bool receiver_plane, bool f64,
                   double min_variance, double lit_eps, int split_depth, const char *tech, Error *err);
/* The receiver's visibility, and in *deepest the deepest level split. */
double chebsoft_visibility(const ChebSoft *cs, const SmapReceiver *r, int *deepest);

#endif
