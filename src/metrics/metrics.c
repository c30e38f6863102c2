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

typedef struct Sums { long n; double abs, sq, max_abs, signed_sum, leak, dark; long miscl; } Sums;

static void add(Sums *s, double e)
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
}

static ErrorStats finish(const Sums *s, int channels)
{
    ErrorStats st = {0};
    long n = s->n; /* sample-channel pairs */
    st.count = n / channels;
    if (n == 0) return st;
    st.mae = s->abs / (double)n;
    st.rmse = sqrt(s->sq / (double)n);
    st.max_abs = s->max_abs;
    st.mean_signed = s->signed_sum / (double)n;
    st.leak_mean = s->leak / (double)n;
    st.dark_mean = s->dark / (double)n;
    st.misclassified = (double)s->miscl / (double)n;
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

/* The error of one estimate value: non-finite counts as the worst case. */
static double sample_error(float est, float ref, Metrics *m)
{
    if (!isfinite(est)) {
        m->nonfinite++;
        return 1.0;
    }
    if (est < 0.0f || est > 1.0f) m->out_of_range++;
    return (double)est - (double)ref;
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
    double noise_sq = 0;
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
            double err_c = sample_error(e[c], r[c], m);
            add(&sums[REGION_ALL], err_c);
            add(&sums[reg], err_c);
            noise_sq += (double)sd[c] * sd[c];
            m->false_shadow += r[c] > 0.5f && !(e[c] >= 0.5f);
            m->false_lit += r[c] < 0.5f && e[c] > 0.5f;
            if (se) se[c] = (float)err_c;
        }
    }
    for (int g = 0; g < REGION_COUNT; g++) m->region[g] = finish(&sums[g], nc);
    long n = sums[REGION_ALL].n;
    m->noise_rms = n ? sqrt(noise_sq / (double)n) : 0.0;
    double rmse = m->region[REGION_ALL].rmse;
    m->rmse_debiased = sqrt(fmax(0.0, rmse * rmse - m->noise_rms * m->noise_rms));
    m->resolved = rmse > 2.0 * m->noise_rms;
    return true;
}
