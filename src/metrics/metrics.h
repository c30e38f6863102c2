/* metrics.h -- error of a visibility image against the reference, over view
 * samples that face the light (class SAMPLE_LIT_CANDIDATE; background,
 * back-facing, outside-the-light and non-receiver samples are counted apart,
 * never as shadow errors). Error e = estimate - reference: e > 0 is light
 * leaking, e < 0 over-darkening. Regions follow the reference: umbra V <= 0.01,
 * penumbra 0.01 < V < 0.99, lit V >= 0.99, except that a sample whose tangent
 * plane cuts the light (its horizon crosses the light: a lit candidate whose
 * reference is the visibility of the light's part above the plane, see
 * scene/light.h) is scored in `terminator` instead, whatever its value; `all`
 * holds every lit candidate, terminator ones included. RGB images are scored
 * per channel, averaged (the max over channels for max_abs). Non-finite
 * estimates are counted apart (nonfinite) and left out of every sum; a region
 * with no finite estimate is absent: count 0 and NaN statistics (null in
 * records). */
#ifndef SL_METRICS_H
#define SL_METRICS_H
#include "rt/reference.h"

typedef enum Region { REGION_ALL, REGION_PENUMBRA, REGION_UMBRA, REGION_LIT, REGION_TERMINATOR, REGION_COUNT } Region;
const char *region_name(Region r);

typedef struct ErrorStats {
    long count;            /* samples in the region with finite estimates */
    long nonfinite;        /* sample-channels in the region with NaN or Inf estimates, left out */
    double mae, rmse, max_abs, mean_signed;
    double leak_mean;      /* mean of max(e, 0): light leaking */
    double dark_mean;      /* mean of max(-e, 0): over-darkening; leak + dark = mae */
    double misclassified;  /* fraction with |e| > 0.5 (hard misclassification) */
    double noise_rms;      /* sqrt(mean of the reference's squared standard errors) over the same samples */
    double noise_mean;     /* mean of the reference's standard errors (the MAE's noise: sqrt(2/pi) times it) */
    double rmse_debiased;  /* sqrt(max(0, rmse^2 - noise_rms^2)): RMSE net of reference noise */
    bool resolved;         /* rmse > 2 noise_rms: the error is above the reference's noise */
} ErrorStats;

typedef struct Metrics {
    long class_count[SAMPLE_CLASS_COUNT];
    ErrorStats region[REGION_COUNT];
    long false_shadow;     /* reference lit (> 0.5), estimate shadowed (< 0.5): acne */
    long false_lit;        /* reference shadowed (< 0.5), estimate lit (> 0.5): leaks, peter panning */
    long nonfinite;        /* NaN or Inf estimates (sample-channels), left out of every statistic */
    long out_of_range;     /* estimates outside [0, 1] */
} Metrics;

/* `terminator` (standard.h's res_terminator; NULL: no terminator region)
 * flags the samples scored in REGION_TERMINATOR. `signed_error` (optional)
 * receives e per sample and channel; 0 outside the evaluated class. est and
 * ref->value must have the same shape. */
bool metrics_compute(const Image *est, const Reference *ref, const uint8_t *cls, const uint8_t *terminator,
                     Metrics *m, Image *signed_error, Error *err);

/* The region each sample is scored in, as a Region value per sample (one
 * channel, ref's size; REGION_ALL, 0, for a sample outside the evaluated
 * class): what a report's pixel inspector shows under the cursor. */
bool metrics_regions(const Reference *ref, const uint8_t *cls, const uint8_t *terminator, Image *out, Error *err);

#endif
