/* metrics.c -- error statistics per region (see metrics.h). Sums are in
 * double; one pass over the samples. */
#include "metrics/metrics.h"
#include <math.h>
#include <string.h>

const char *region_name(Region r)
{
    static const char *const names[] = {"all", "penumbra", "umbra", "lit", "terminator"};
    return names[r];
}

typedef struct Sums { long n, nonfinite; double abs, sq, max_abs, signed_sum, leak, dark, noise_sq, noise; long miscl; } Sums;

/* One finite error e against a reference with standard error sd. */
static void add(Sums *s, double e, double sd)
{
    double a = fabs(e);
    s->n++;
    s->abs += a;
    s->sq += e * e;
    s->max_abs = fmax(s->max_abs, a);
    s->signed_sum += e;
    s->leak += fmax(e, 0.0);
    s->dark += fmax(-e, 0.0);
    s->miscl += a > 0.5;
    s->noise_sq += sd * sd;
    s->noise += sd;
}

static ErrorStats finish(const Sums *s, int channels)
{
    ErrorStats st = {.count = s->n / channels, .nonfinite = s->nonfinite};
    long n = s->n; /* sample-channel pairs */
    if (n == 0) { /* absent, not perfect */
        st.mae = st.rmse = st.max_abs = st.mean_signed = st.leak_mean = st.dark_mean = st.misclassified = NAN;
        st.noise_rms = st.noise_mean = st.rmse_debiased = NAN;
        return st;
    }
    st.mae = s->abs / (double)n;
    st.rmse = sqrt(s->sq / (double)n);
    st.max_abs = s->max_abs;
    st.mean_signed = s->signed_sum / (double)n;
    st.leak_mean = s->leak / (double)n;
    st.dark_mean = s->dark / (double)n;
    st.misclassified = (double)s->miscl / (double)n;
    st.noise_rms = sqrt(s->noise_sq / (double)n);
    st.noise_mean = s->noise / (double)n;
    st.rmse_debiased = sqrt(fmax(0.0, st.rmse * st.rmse - st.noise_rms * st.noise_rms));
    st.resolved = st.rmse > 2.0 * st.noise_rms;
    return st;
}

/* The region of a lit candidate: terminator where the horizon crosses the
 * light (flag set), else by the reference's value. */
static Region region_of(const float *ref, int nc, bool terminator)
{
    if (terminator) return REGION_TERMINATOR;
    double v = 0;
    for (int c = 0; c < nc; c++) v += ref[c];
    v /= nc;
    return v <= 0.01 ? REGION_UMBRA : v >= 0.99 ? REGION_LIT : REGION_PENUMBRA;
}

bool metrics_regions(const Reference *ref, const uint8_t *cls, const uint8_t *terminator, Image *out, Error *err)
{
    const Image *rv = &ref->value;
    if (!image_init(out, rv->width, rv->height, 1, err)) return false;
    for (int s = 0; s < rv->width * rv->height; s++)
        out->data[s] = cls[s] != SAMPLE_LIT_CANDIDATE
                           ? (float)REGION_ALL
                           : (float)region_of(rv->data + (size_t)s * rv->channels, rv->channels, terminator && terminator[s]);
    return true;
}

bool metrics_compute(const Image *est, const Reference *ref, const uint8_t *cls, const uint8_t *terminator,
                     Metrics *m, Image *signed_error, Error *err)
{
    const Image *rv = &ref->value;
    if (est->width != rv->width || est->height != rv->height || est->channels != rv->channels)
        return error_set(err, "estimate %dx%dx%d and reference %dx%dx%d differ in shape", est->width, est->height,
                         est->channels, rv->width, rv->height, rv->channels);
    memset(m, 0, sizeof *m);
    Sums sums[REGION_COUNT] = {{0}};
    int nc = rv->channels;
    long count = (long)rv->width * rv->height;
    for (long s = 0; s < count; s++) {
        m->class_count[cls[s]]++;
        float *se = signed_error ? signed_error->data + s * nc : NULL;
        if (cls[s] != SAMPLE_LIT_CANDIDATE) {
            for (int c = 0; se && c < nc; c++) se[c] = 0.0f;
            continue;
        }
        const float *r = rv->data + s * nc, *e = est->data + s * nc, *sd = ref->std_error.data + s * nc;
        Region reg = region_of(r, nc, terminator && terminator[s]);
        for (int c = 0; c < nc; c++) {
            double err_c = (double)e[c] - (double)r[c]; /* NaN or Inf for a non-finite estimate */
            if (se) se[c] = (float)err_c;
            if (!isfinite(e[c])) { /* counted apart, never a value */
                sums[REGION_ALL].nonfinite++;
                sums[reg].nonfinite++;
                continue;
            }
            add(&sums[REGION_ALL], err_c, sd[c]);
            add(&sums[reg], err_c, sd[c]);
            m->out_of_range += e[c] < 0.0f || e[c] > 1.0f;
            m->false_shadow += r[c] > 0.5f && e[c] < 0.5f;
            m->false_lit += r[c] < 0.5f && e[c] > 0.5f;
        }
    }
    for (int g = 0; g < REGION_COUNT; g++) m->region[g] = finish(&sums[g], nc);
    m->nonfinite = m->region[REGION_ALL].nonfinite;
    return true;
}
