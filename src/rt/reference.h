/* reference.h -- the ground truth: for every view sample, the visible
 * fraction of the light (course Eq. 1.4; seed 000's s = |D_c ∩ D| / |D| for
 * sphere lights), RGB-weighted by the emission image for textured lights, or
 * with MEASURE_IRRADIANCE the Lambertian direct illumination of course
 * Eq. 1.3, L_o = rho/pi * integral L_e G V dA. Each sample carries its
 * standard error so no technique's error is read below the reference's noise. */
#ifndef SL_REFERENCE_H
#define SL_REFERENCE_H
#include "core/sampling.h"
#include "rt/view.h"

typedef enum Measure { MEASURE_VISIBILITY, MEASURE_IRRADIANCE } Measure;
const char *measure_name(Measure m);
bool measure_parse(const char *name, Measure *m, Error *err);

typedef struct ReferenceParams {
    Measure measure;
    int samples;             /* light samples per view sample (delta lights trace one) */
    SamplingPattern pattern;
    uint32_t seed;
    /* false (the default): every view sample draws its own stream,
     * sampling_stream(seed, s); true (--sample-set shared): all draw the one
     * stream sampling_set_stream(seed, true, s), so on rect, disk and
     * textured lights every view sample traces toward the same light points
     * (a sphere light's are directions from each, cone sampling). The
     * standard error stays honest per view sample: the shared stream is
     * still cut into the same M independent randomisations (core/sampling.h),
     * each batch a shared set too, so a sample's batch means are independent
     * and their spread over sqrt(M) estimates its error as before; what
     * changes is that neighbouring samples' errors are correlated (the same
     * points: structured banding, not independent noise), so an image's mean
     * error does not average down over its samples. */
    bool shared_set;
} ReferenceParams;

#define REFERENCE_MAX_SAMPLES 1048576

/* How std_error is estimated. */
typedef enum RefErrorEstimator {
    REF_ERROR_EXACT,       /* a delta light: its one ray is the answer, error 0 */
    REF_ERROR_INDEPENDENT, /* one batch of independent samples: Laplace-smoothed binomial (visibility) or the
                            * sample variance (irradiance), over n */
    REF_ERROR_RQMC,        /* randomised QMC: the spread of `batches` independent randomisations (see
                            * core/sampling.h) over sqrt(batches); 0 where all batches agree */
} RefErrorEstimator;
#define REF_ERROR_ESTIMATOR_COUNT 3
const char *ref_error_estimator_name(RefErrorEstimator e);

typedef struct Reference {
    Image value;     /* visibility in [0,1] (1 or 3 channels) or outgoing radiance (3) */
    Image std_error; /* standard error of value, same shape */
    ReferenceParams params;
    long long rays;  /* occlusion rays traced */
    int rays_per_sample;         /* params.samples, or 1 for a delta light */
    RefErrorEstimator estimator; /* how std_error was estimated */
    int batches;                 /* independent randomisations (RQMC), else 1 */
} Reference;

bool reference_params_check(const ReferenceParams *p, Error *err);
/* Channels of the reference for this light and measure: 3 for textured
 * lights and for irradiance, else 1. */
int reference_channels(const Scene *scene, int light_index, Measure m);
bool reference_compute(const RtScene *casters, const Scene *scene, int light_index, const ViewSamples *vs,
                       const uint8_t *cls, const ReferenceParams *p, Reference *out, Error *err);
void reference_free(Reference *ref);

#endif
