/* reference.c -- Embree ground truth (see reference.h). Light samples come
 * from core/sampling (one stream per view sample) mapped onto the light by
 * scene/light; occlusion rays are traced sixteen at a time with
 * rtcOccluded16 across all cores. Origins are lifted off the surface by
 * rt_ray_offset along the geometric normal. */
#include "rt/reference.h"
#include <math.h>
#include <string.h>
#include "core/progress.h"

#define PACKET 16
#define INV_PI 0.31830988618379067f

static const char *const measure_names[] = {"visibility", "irradiance"};

const char *measure_name(Measure m) { return measure_names[m]; }

bool measure_parse(const char *name, Measure *m, Error *err)
{
    for (int i = 0; i < 2; i++) {
        if (strcmp(name, measure_names[i]) == 0) {
            *m = (Measure)i;
            return true;
        }
    }
    return error_set(err, "--measure '%s' is not one of: visibility, irradiance", name);
}

bool reference_params_check(const ReferenceParams *p, Error *err)
{
    if (p->samples < 1 || p->samples > REFERENCE_MAX_SAMPLES)
        return error_set(err, "--samples %d outside [1, %d]", p->samples, REFERENCE_MAX_SAMPLES);
    return sampling_check_count(p->pattern, p->samples, err);
}

int reference_channels(const Scene *scene, int light_index, Measure m)
{
    return (m == MEASURE_IRRADIANCE || scene->lights[light_index].kind == LIGHT_TEXTURED_RECT) ? 3 : 1;
}

const char *ref_error_estimator_name(RefErrorEstimator e)
{
    static const char *const names[REF_ERROR_ESTIMATOR_COUNT] = {"exact", "independent", "rqmc"};
    return names[e];
}

/* Running sums of one view sample's estimator, per batch (core/sampling's
 * independent randomisations) and colour channel: weights W and weighted
 * values X. Visibility: w the light sample's colour weight, x 1 (lit) or 0;
 * irradiance: w 1, x the sample's contribution. */
typedef struct Accum {
    double w[SAMPLING_MAX_BATCHES][3], x[SAMPLING_MAX_BATCHES][3];
    double w2[3]; /* squared weights: the binomial's n_eff */
    double x2[3]; /* squared values: independent samples' variance (irradiance, w = 1) */
    int n;
} Accum;

/* valid: the lanes traced. below: lanes whose light sample was drawn but not
 * traced, on or below the receiver's geometric tangent plane. */
typedef struct Batch {
    LightSample ls[PACKET];
    _Alignas(64) struct RTCRay16 ray;
    _Alignas(64) int valid[PACKET];
    bool below[PACKET];
    int below_horizon; /* how many lanes are below */
} Batch;

/* Embree reads every lane: keep untraced ones finite and empty. */
static void empty_lane(Batch *b, int k)
{
    b->valid[k] = 0;
    b->below[k] = false;
    b->ray.org_x[k] = b->ray.org_y[k] = b->ray.org_z[k] = 0.0f;
    b->ray.dir_x[k] = b->ray.dir_y[k] = 0.0f; b->ray.dir_z[k] = 1.0f;
    b->ray.tnear[k] = b->ray.tfar[k] = b->ray.time[k] = 0.0f;
}

/* Lane k traces the open segment from org toward the light sample s
 * (course Eq. 1.1), stored in the batch for the accumulation. */
static void aim_lane(Batch *b, int k, vec3 org, const LightSample *s)
{
    b->ls[k] = *s;
    b->valid[k] = -1;
    b->below[k] = false;
    b->ray.org_x[k] = org.x; b->ray.org_y[k] = org.y; b->ray.org_z[k] = org.z;
    b->ray.dir_x[k] = s->dir_world.x; b->ray.dir_y[k] = s->dir_world.y; b->ray.dir_z[k] = s->dir_world.z;
    b->ray.tnear[k] = 0.0f;
    b->ray.tfar[k] = isinf(s->dist) ? INFINITY : s->dist * (1.0f - 1e-5f);
    b->ray.time[k] = 0.0f;
    b->ray.mask[k] = 0xFFFFFFFFu;
    b->ray.id[k] = (unsigned)k;
    b->ray.flags[k] = 0;
}

/* The horizon is shading, not shadow (course §1: Eq. 1.1 integrates over
 * H+(p) only): a light sample on or below the geometric tangent plane of p
 * (n_geom) is neither traced nor counted in the visibility, which is thus the
 * ratio over the samples above the plane, the visible fraction of the part
 * of the light above it. Light samples are equally weighted points of an R2,
 * stratified or independent pattern over the light, so dropping some keeps
 * that ratio consistent (unbiased given the count kept; the batches' ratio
 * estimator takes their unequal counts, see batch_spread); irradiance counts
 * them as zero terms of its mean (accumulate_irradiance). So the receiver's
 * caster flag no longer decides its own horizon: the rays traced leave
 * above the plane, where a convex mesh cannot block them, and a receiver
 * that casts still shadows itself elsewhere (a bunny's ear on its back). */
static void fill_batch(Batch *b, const Light *l, vec3 org, vec3 p, vec3 n_geom, uint32_t stream, int first,
                       int count, const ReferenceParams *prm)
{
    b->below_horizon = 0;
    for (int k = 0; k < PACKET; k++) {
        int i = first + k;
        if (i >= count) { empty_lane(b, k); continue; }
        float u, v;
        sample_2d(prm->pattern, stream, i, count, &u, &v);
        LightSample s = light_sample(l, p, u, v);
        if (v3_dot(n_geom, s.dir_world) <= 0.0f) {
            empty_lane(b, k);
            b->below[k] = true;
            b->below_horizon++;
        } else aim_lane(b, k, org, &s);
    }
}

/* A part of the light above the horizon too thin for any of the pattern's
 * samples (visibility's ratio would be 0/0): the visible fraction of a part
 * shrinking to a point tends to that point's visibility, so one ray toward
 * the light's highest point, reported with the error of one draw
 * (one_draw_error). */
static void fill_highest(Batch *b, const Light *l, vec3 org, vec3 p, vec3 n_geom)
{
    LightSample s = light_sample_highest(l, p, n_geom);
    b->below_horizon = 0;
    aim_lane(b, 0, org, &s);
    for (int k = 1; k < PACKET; k++) empty_lane(b, k);
}

static void add_sample(Accum *a, int batch, const float *w, const double *x, int nc)
{
    for (int c = 0; c < nc; c++) {
        a->w[batch][c] += w[c];
        a->x[batch][c] += w[c] * x[c];
        a->w2[c] += (double)w[c] * w[c];
        a->x2[c] += x[c] * x[c];
    }
    a->n++;
}

/* Batch of the sample after one of batch `batch`: core/sampling deals samples
 * i into batches i % m, so consecutive lanes take consecutive batches. */
static int next_batch(int batch, int m) { return batch + 1 == m ? 0 : batch + 1; }

/* Visibility of the `nc` channels the reference stores; the packet's lane 0
 * is in batch `batch` of m. */
static void accumulate_visibility(Accum *a, const Batch *b, int batch, int m, int nc)
{
    for (int k = 0; k < PACKET; k++, batch = next_batch(batch, m)) {
        if (!b->valid[k]) continue;
        const LightSample *s = &b->ls[k];
        double vis = b->ray.tfar[k] == -INFINITY ? 0.0 : 1.0; /* Embree marks occluded rays with tfar = -inf */
        const float w[3] = {s->vis_weight.x, s->vis_weight.y, s->vis_weight.z};
        const double x[3] = {vis, vis, vis};
        add_sample(a, batch, w, x, nc);
    }
}

/* Lambertian direct illumination, course Eq. 1.3: E cos / pi per sample. */
static void accumulate_irradiance(Accum *a, const Batch *b, int batch, int m, vec3 n_shading, vec3 albedo)
{
    static const float unit[3] = {1.0f, 1.0f, 1.0f};
    static const double zero[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < PACKET; k++, batch = next_batch(batch, m)) {
        if (b->below[k]) add_sample(a, batch, unit, zero, 3); /* light below the horizon: a zero term (fill_batch) */
        if (!b->valid[k]) continue;
        const LightSample *s = &b->ls[k];
        float vis = b->ray.tfar[k] == -INFINITY ? 0.0f : 1.0f;
        float cos_p = fmaxf(0.0f, v3_dot(n_shading, s->dir_world));
        const float e[3] = {s->irradiance.x * albedo.x, s->irradiance.y * albedo.y, s->irradiance.z * albedo.z};
        double x[3];
        for (int c = 0; c < 3; c++) x[c] = e[c] * cos_p * vis * INV_PI;
        add_sample(a, batch, unit, x, 3);
    }
}

/* Standard error of the ratio estimate mean = X / W from m independent
 * batches, the linearised variance of a ratio estimator over independent
 * clusters (Cochran, Sampling Techniques, ch. 6): se^2 = m / (m - 1)
 * sum_b (X_b - W_b mean)^2 / W^2; with equal weights the batch means'
 * standard deviation over sqrt(m), randomised QMC's error estimate (L'Ecuyer
 * & Lemieux 2002). It is 0 where every batch agrees: no smoothing floor.
 * W > 0, m > 1. */
static double batch_spread(const Accum *a, int c, int m, double mean, double w)
{
    double sq = 0;
    for (int b = 0; b < m; b++) {
        double d = a->x[b][c] - a->w[b][c] * mean;
        sq += d * d;
    }
    return sqrt(sq * m / (m - 1)) / w;
}

static double channel_sum(const double (*v)[3], int m, int c)
{
    double s = 0;
    for (int b = 0; b < m; b++) s += v[b][c];
    return s;
}

/* Independent samples' visibility error: the Laplace-smoothed binomial, p~ =
 * (k+1)/(n+2) in weighted form, so an all-lit or all-blocked sample still
 * reports the uncertainty of n draws; n_eff = (sum w)^2 / sum w^2. */
static double binomial_error(const Accum *a, int c, double w, double wx)
{
    double mean_w = w / a->n;
    double p_s = (wx + mean_w) / (w + 2.0 * mean_w);
    double n_eff = w * w / a->w2[c];
    return sqrt(p_s * (1.0 - p_s) / n_eff);
}

/* Independent samples' irradiance error: sample variance over n (w = 1). */
static double sample_variance_error(const Accum *a, int c, double mean)
{
    if (a->n < 2) return 0.0;
    double var = fmax(0.0, (a->x2[c] / a->n - mean * mean) * a->n / (a->n - 1));
    return sqrt(var / a->n);
}

/* The error of the one ray toward the light's highest point (fill_highest):
 * the Laplace-smoothed binomial of one draw, p~ = (k + 1) / 3 for k in {0, 1},
 * sqrt(p~ (1 - p~)) = sqrt(2) / 3 whatever the ray found. */
static double one_draw_error(void) { return sqrt(2.0) / 3.0; }

/* Value and standard error per channel, by the reference's estimator (m batches). */
static void finish(const Accum *a, const Reference *ref, int nc, float *value, float *se)
{
    int m = ref->batches;
    bool irradiance = ref->params.measure == MEASURE_IRRADIANCE;
    for (int c = 0; c < nc; c++) {
        double w = channel_sum(a->w, m, c), wx = channel_sum(a->x, m, c);
        if (w <= 0.0) { value[c] = 1.0f; se[c] = 0.0f; continue; } /* a black light texel set: nothing to block */
        double mean = wx / w;
        value[c] = (float)mean;
        if (ref->estimator == REF_ERROR_EXACT) se[c] = 0.0f;
        else if (ref->estimator == REF_ERROR_RQMC) se[c] = (float)batch_spread(a, c, m, mean, w);
        else se[c] = (float)(irradiance ? sample_variance_error(a, c, mean) : binomial_error(a, c, w, wx));
    }
}

typedef struct RefJob {
    RTCScene rtc;
    const Scene *scene;
    const Light *light;
    const ViewSamples *vs;
    const ReferenceParams *p;
    int count; /* samples per view sample actually traced */
    float extent;
    Reference *out;
} RefJob;

/* Estimates sample s; returns the rays traced (fill_batch drops some). */
static int trace_sample(const RefJob *j, int s, struct RTCIntersectContext *ctx, Batch *b)
{
    vec3 p = j->vs->p_world[s], ng = j->vs->n_geom_world[s];
    vec3 org = v3_madd(p, ng, rt_ray_offset(j->extent, p));
    uint32_t stream = sampling_set_stream(j->p->seed, j->p->shared_set, (uint32_t)s);
    int nc = j->out->value.channels, m = j->out->batches;
    Accum a = {0};
    int rays = 0;
    for (int first = 0; first < j->count; first += PACKET) {
        fill_batch(b, j->light, org, p, ng, stream, first, j->count, j->p);
        rays += (j->count - first < PACKET ? j->count - first : PACKET) - b->below_horizon;
        rt_occluded16(b->valid, j->rtc, ctx, &b->ray);
        int batch = sampling_batch_of(j->p->pattern, first, j->count);
        if (j->p->measure == MEASURE_IRRADIANCE)
            accumulate_irradiance(&a, b, batch, m, j->vs->n_shading_world[s],
                                  j->scene->objects[j->vs->object[s]].albedo);
        else accumulate_visibility(&a, b, batch, m, nc);
    }
    float *v = j->out->value.data + (size_t)s * nc, *se = j->out->std_error.data + (size_t)s * nc;
    bool sliver = rays == 0 && j->p->measure == MEASURE_VISIBILITY;
    if (sliver) {
        fill_highest(b, j->light, org, p, ng);
        rt_occluded16(b->valid, j->rtc, ctx, &b->ray);
        accumulate_visibility(&a, b, 0, m, nc);
        rays = 1;
    }
    finish(&a, j->out, nc, v, se);
    for (int c = 0; sliver && c < nc; c++) se[c] = (float)one_draw_error();
    return rays;
}

/* Value of samples that are not traced: unlit (0) unless on a non-receiver,
 * which receives no shadow (visibility 1). */
static void fill_untraced(const RefJob *j, int s, uint8_t cls)
{
    int nc = j->out->value.channels;
    float v = (cls == SAMPLE_NOT_RECEIVER && j->p->measure == MEASURE_VISIBILITY) ? 1.0f : 0.0f;
    for (int c = 0; c < nc; c++) {
        j->out->value.data[(size_t)s * nc + c] = v;
        j->out->std_error.data[(size_t)s * nc + c] = 0.0f;
    }
}

static bool traced(const RefJob *j, uint8_t cls)
{
    if (j->p->measure == MEASURE_IRRADIANCE) return cls == SAMPLE_LIT_CANDIDATE || cls == SAMPLE_NOT_RECEIVER;
    return cls == SAMPLE_LIT_CANDIDATE;
}

bool reference_compute(const RtScene *casters, const Scene *scene, int light_index, const ViewSamples *vs,
                       const uint8_t *cls, const ReferenceParams *p, Reference *out, Error *err)
{
    memset(out, 0, sizeof *out);
    if (!reference_params_check(p, err)) return false;
    int nc = reference_channels(scene, light_index, p->measure);
    if (!image_init(&out->value, vs->width, vs->height, nc, err) ||
        !image_init(&out->std_error, vs->width, vs->height, nc, err)) {
        reference_free(out);
        return false;
    }
    out->params = *p;
    const Light *l = &scene->lights[light_index];
    out->rays_per_sample = light_is_delta(l) ? 1 : p->samples;
    out->batches = sampling_batches(p->pattern, out->rays_per_sample);
    out->estimator = light_is_delta(l) ? REF_ERROR_EXACT : out->batches > 1 ? REF_ERROR_RQMC : REF_ERROR_INDEPENDENT;
    RefJob j = {rt_scene_handle(casters), scene, l, vs, p, out->rays_per_sample, scene_extent(scene), out};
    Progress prog;
    progress_begin(&prog, "reference", vs->height);
    long long rays = 0;
#pragma omp parallel reduction(+ : rays)
    {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        Batch b;
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < vs->height; y++) {
            for (int s = y * vs->width; s < (y + 1) * vs->width; s++) {
                if (!traced(&j, cls[s])) { fill_untraced(&j, s, cls[s]); continue; }
                rays += trace_sample(&j, s, &ctx, &b);
            }
            progress_add(&prog, 1);
        }
    }
    progress_end(&prog);
    out->rays = rays;
    return true;
}

void reference_free(Reference *ref)
{
    image_free(&ref->value);
    image_free(&ref->std_error);
}
