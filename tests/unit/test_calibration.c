/* test_calibration.c -- is the reference's standard error what it claims?
 * For each sampling pattern at N = 64 and 256, 16 references with
 * independent seeds on a wide penumbra (a 2 x 2 rect light over a box): over
 * the penumbra samples (mean of the 16 values in (0.02, 0.98)), the reported
 * error, sqrt(mean se^2) over samples and seeds, must lie within 0.75x to
 * 1.33x of the measured spread, sqrt(mean of the 16 values' sample
 * variance). Both sides are unbiased estimates of the same mean variance, so
 * the ratio is 1 for an honest estimator (issue 12 §1). Delta lights report
 * their one exact ray as error 0. 64 x 48 view samples; about 2 s. */
#include <math.h>
#include <stdlib.h>
#include "fixtures.h"
#include "metrics/metrics.h"
#include "test.h"

static const char *const penumbra_scene =
    "return {\n"
    "  camera = { position = {0, 4, 3.5}, target = {0, 0, 0}, fov = 50, width = 64, height = 48 },\n"
    "  lights = { { type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1},\n"
    "               width = 2, height = 2 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {10, 10} },\n"
    "    { name = 'box', shape = 'box', size = {1, 0.2, 1}, translate = {0, 1.6, 0} },\n"
    "  },\n"
    "}\n";

#define SEEDS 16

typedef struct Calibration { double reported, measured; int penumbra; } Calibration;

/* Reported and measured error over the penumbra of SEEDS references
 * (shared: one light-sample set for the frame, --sample-set shared). */
static bool calibrate(Lab *lab, SamplingPattern pattern, int samples, bool shared, Calibration *out)
{
    Error err;
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = vs ? res_classes(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    if (!cls) { printf("    %s\n", err.msg); return false; }
    double *sum = calloc((size_t)vs->count, sizeof *sum), *sq = calloc((size_t)vs->count, sizeof *sq),
           *se2 = calloc((size_t)vs->count, sizeof *se2);
    bool ok = sum && sq && se2;
    for (int k = 0; ok && k < SEEDS; k++) {
        RefInfo info;
        RefRequest rq = {0, {MEASURE_VISIBILITY, samples, pattern, 1000u + (uint32_t)k, shared}, NULL};
        const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
        if (!ref) { printf("    reference: %s\n", err.msg); ok = false; break; }
        for (int s = 0; s < vs->count; s++) {
            double v = ref->value.data[s], e = ref->std_error.data[s];
            sum[s] += v;
            sq[s] += v * v;
            se2[s] += e * e;
        }
    }
    *out = (Calibration){0};
    double reported = 0, measured = 0;
    for (int s = 0; ok && s < vs->count; s++) {
        double mean = sum[s] / SEEDS;
        if (cls[s] != SAMPLE_LIT_CANDIDATE || mean <= 0.02 || mean >= 0.98) continue;
        reported += se2[s] / SEEDS;
        measured += fmax(0.0, sq[s] - SEEDS * mean * mean) / (SEEDS - 1);
        out->penumbra++;
    }
    if (out->penumbra > 0) {
        out->reported = sqrt(reported / out->penumbra);
        out->measured = sqrt(measured / out->penumbra);
    }
    free(sum);
    free(sq);
    free(se2);
    return ok;
}

TEST(test_calibration_std_error_matches_the_spread_of_seeds)
{
    Lab *lab = fixture_lab("penumbra.lua", penumbra_scene);
    CHECK(lab);
    static const SamplingPattern patterns[] = {SAMPLING_RANDOM, SAMPLING_R2, SAMPLING_STRATIFIED, false};
    static const int counts[] = {64, 256};
    int bad = 0;
    for (int p = 0; p < 3; p++)
        for (int n = 0; n < 2; n++) {
            Calibration c;
            CHECK(calibrate(lab, patterns[p], counts[n], false, &c));
            CHECK_MSG(c.penumbra > 300 && c.measured > 0, "only %d penumbra samples", c.penumbra);
            double ratio = c.reported / c.measured;
            bool in = ratio >= 0.75 && ratio <= 1.33;
            printf("    %-10s N = %3d: reported %.5f, measured %.5f over %d penumbra samples: ratio %.2f%s\n",
                   sampling_pattern_name(patterns[p]), counts[n], c.reported, c.measured, c.penumbra, ratio,
                   in ? "" : "  OUTSIDE [0.75, 1.33]");
            bad += !in;
        }
    CHECK_MSG(bad == 0, "%d of 6 pattern and count pairs report an error outside 0.75x to 1.33x of the spread", bad);
    lab_close(lab);
}

/* One light-sample set shared by every view sample (reference.h): each
 * sample's RQMC batches are still independent randomisations, so its error
 * stays what it claims (the same 0.75x to 1.33x of the seeds' spread); only
 * neighbouring samples' errors are correlated. r2 and stratified at N = 64;
 * about 0.5 s. */
TEST(test_calibration_shared_sample_set_std_error_matches_the_spread_of_seeds)
{
    Lab *lab = fixture_lab("penumbra.lua", penumbra_scene);
    CHECK(lab);
    static const SamplingPattern patterns[] = {SAMPLING_R2, SAMPLING_STRATIFIED};
    for (int p = 0; p < 2; p++) {
        Calibration c;
        CHECK(calibrate(lab, patterns[p], 64, true, &c));
        double ratio = c.measured > 0 ? c.reported / c.measured : NAN;
        printf("    shared %-10s N = 64: reported %.5f, measured %.5f over %d penumbra samples: ratio %.2f\n",
               sampling_pattern_name(patterns[p]), c.reported, c.measured, c.penumbra, ratio);
        CHECK(c.penumbra > 300 && ratio >= 0.75 && ratio <= 1.33);
    }
    lab_close(lab);
}

/* A delta light's one ray is exact: standard error 0, said as such. */
TEST(test_calibration_delta_light_reports_one_exact_ray)
{
    Lab *lab = fixture_lab("point.lua", "return {\n"
                                        "  camera = { position = {0, 3, 4}, target = {0, 0, 0}, width = 40, height = 30 },\n"
                                        "  lights = { { type = 'point', position = {1, 4, 0} } },\n"
                                        "  objects = { { shape = 'plane', size = {8, 8} },\n"
                                        "    { shape = 'box', size = {1, 1, 1}, translate = {0, 0.5, 0} } } }\n");
    CHECK(lab);
    Error err;
    RefInfo info;
    RefRequest rq = {0, {MEASURE_VISIBILITY, 256, SAMPLING_R2, 1, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
    CHECK_MSG(ref, "%s", err.msg);
    double worst = 0;
    for (size_t i = 0; i < image_count(&ref->std_error); i++) worst = fmax(worst, ref->std_error.data[i]);
    printf("    point light, 256 samples asked: %d ray per sample, estimator %s, max std error %g\n",
           ref->rays_per_sample, ref_error_estimator_name(ref->estimator), worst);
    CHECK(ref->rays_per_sample == 1 && ref->estimator == REF_ERROR_EXACT);
    CHECK_MSG(worst == 0, "a delta light's reference reports std error %g", worst);
    lab_close(lab);
}

/* Metrics on a hand-made 4-sample reference (values 1, 1, 0.5, 0.5, std
 * errors 0, 0, 0.1, 0.1): NaN and Inf estimates are counted apart, per
 * region, and left out of every sum; the empty umbra is absent (NaN, count
 * 0), not perfect; the noise is each region's own. */
TEST(test_calibration_metrics_regions_noise_and_nonfinite)
{
    Error err;
    Reference ref = {0};
    Image est = {0}, sig = {0};
    CHECK(image_init(&ref.value, 4, 1, 1, &err) && image_init(&ref.std_error, 4, 1, 1, &err) &&
          image_init(&est, 4, 1, 1, &err) && image_init(&sig, 4, 1, 1, &err));
    const float value[4] = {1.0f, 1.0f, 0.5f, 0.5f}, se[4] = {0.0f, 0.0f, 0.1f, 0.1f};
    const float e[4] = {1.0f, NAN, 0.6f, INFINITY};
    for (int i = 0; i < 4; i++) {
        ref.value.data[i] = value[i];
        ref.std_error.data[i] = se[i];
        est.data[i] = e[i];
    }
    const uint8_t cls[4] = {SAMPLE_LIT_CANDIDATE, SAMPLE_LIT_CANDIDATE, SAMPLE_LIT_CANDIDATE, SAMPLE_LIT_CANDIDATE};
    Metrics m;
    CHECK(metrics_compute(&est, &ref, cls, NULL, &m, &sig, &err));
    const ErrorStats *all = &m.region[REGION_ALL], *lit = &m.region[REGION_LIT], *pen = &m.region[REGION_PENUMBRA],
                     *umb = &m.region[REGION_UMBRA];
    printf("    nonfinite %ld (all %ld, lit %ld, penumbra %ld); all: count %ld rmse %g noise %g; lit rmse %g; "
           "penumbra rmse %g noise %g; umbra count %ld rmse %g noise %g; false shadow %ld\n",
           m.nonfinite, all->nonfinite, lit->nonfinite, pen->nonfinite, all->count, all->rmse, all->noise_rms,
           lit->rmse, pen->rmse, pen->noise_rms, umb->count, umb->rmse, umb->noise_rms, m.false_shadow);
    CHECK(m.nonfinite == 2 && all->nonfinite == 2 && lit->nonfinite == 1 && pen->nonfinite == 1);
    CHECK(all->count == 2 && lit->count == 1 && pen->count == 1 && m.false_shadow == 0);
    CHECK(lit->rmse == 0 && fabs(pen->rmse - 0.1) < 1e-6 && fabs(all->rmse - sqrt(0.005)) < 1e-6);
    CHECK(lit->noise_rms == 0 && fabs(pen->noise_rms - 0.1) < 1e-6 && fabs(all->noise_rms - sqrt(0.005)) < 1e-6);
    CHECK(!pen->resolved && pen->rmse_debiased < 1e-3);
    CHECK(umb->count == 0 && isnan(umb->rmse) && isnan(umb->mae) && isnan(umb->noise_rms) && !umb->resolved);
    CHECK(isnan(sig.data[1]) && isinf(sig.data[3]) && fabsf(sig.data[2] - 0.1f) < 1e-6f);
    image_free(&est);
    image_free(&sig);
    reference_free(&ref);
}

/* The reference cache keeps how the error was estimated (format version 2). */
TEST(test_calibration_cache_keeps_the_estimator)
{
    char cache[1024];
    snprintf(cache, sizeof cache, "%s/cache", test_tmpdir());
    Reference got[2];
    RefOrigin origin[2];
    for (int k = 0; k < 2; k++) { /* a fresh lab each time, as a new process */
        Error err;
        Lab *lab = fixture_lab("cached.lua", penumbra_scene);
        CHECK(lab);
        RefInfo info;
        RefRequest rq = {0, {MEASURE_VISIBILITY, 64, SAMPLING_STRATIFIED, 3, false}, cache};
        const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
        CHECK_MSG(ref, "%s", err.msg);
        got[k] = (Reference){.rays_per_sample = ref->rays_per_sample, .estimator = ref->estimator,
                             .batches = ref->batches};
        origin[k] = info.origin;
        lab_close(lab);
    }
    printf("    %s then %s: estimator %s, %d batches, %d rays per sample\n", ref_origin_name(origin[0]),
           ref_origin_name(origin[1]), ref_error_estimator_name(got[1].estimator), got[1].batches,
           got[1].rays_per_sample);
    CHECK(origin[0] == REF_COMPUTED && origin[1] == REF_CACHE_HIT);
    CHECK(got[0].estimator == REF_ERROR_RQMC && got[0].batches == 16 && got[0].rays_per_sample == 64);
    CHECK(got[1].estimator == got[0].estimator && got[1].batches == got[0].batches &&
          got[1].rays_per_sample == got[0].rays_per_sample);
}
