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

/* Running sums of one view sample's estimator, per colour channel. */
typedef struct Accum {
    double w[3], wv[3], w2[3]; /* visibility: weights, weighted hits, squared weights */
    double c[3], c2[3];        /* irradiance: contributions and their squares */
    int n;
} Accum;

/* valid: the lanes traced. below_horizon: light samples drawn but not
 * traced, on or below the receiver's geometric tangent plane. */
typedef struct Batch {
    LightSample ls[PACKET];
    _Alignas(64) struct RTCRay16 ray;
    _Alignas(64) int valid[PACKET];
    int below_horizon;
} Batch;

/* Embree reads every lane: keep untraced ones finite and empty. */
static void empty_lane(Batch *b, int k)
{
    b->valid[k] = 0;
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
 * that ratio consistent (unbiased given the count kept); irradiance counts
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
            b->below_horizon++;
        } else aim_lane(b, k, org, &s);
    }
}

/* A part of the light above the horizon too thin for any of the pattern's
 * samples (visibility's ratio would be 0/0): the visible fraction of a part
 * shrinking to a point tends to that point's visibility, so one ray toward
 * the light's highest point, reported with the error of one draw. */
static void fill_highest(Batch *b, const Light *l, vec3 org, vec3 p, vec3 n_geom)
{
    LightSample s = light_sample_highest(l, p, n_geom);
    b->below_horizon = 0;
    aim_lane(b, 0, org, &s);
    for (int k = 1; k < PACKET; k++) empty_lane(b, k);
}

/* Visibility sums of the `nc` channels the reference stores. */
static void accumulate_visibility(Accum *a, const Batch *b, int nc)
{
    for (int k = 0; k < PACKET; k++) {
        if (!b->valid[k]) continue;
        const LightSample *s = &b->ls[k];
        float vis = b->ray.tfar[k] == -INFINITY ? 0.0f : 1.0f; /* Embree marks occluded rays with tfar = -inf */
        const float w[3] = {s->vis_weight.x, s->vis_weight.y, s->vis_weight.z};
        for (int c = 0; c < nc; c++) {
            a->w[c] += w[c];
            a->wv[c] += w[c] * vis;
            a->w2[c] += (double)w[c] * w[c];
        }
        a->n++;
    }
}

/* Lambertian direct illumination, course Eq. 1.3: E cos / pi per sample. */
static void accumulate_irradiance(Accum *a, const Batch *b, vec3 n_shading, vec3 albedo)
{
    for (int k = 0; k < PACKET; k++) {
        if (!b->valid[k]) continue;
        const LightSample *s = &b->ls[k];
        float vis = b->ray.tfar[k] == -INFINITY ? 0.0f : 1.0f;
        float cos_p = fmaxf(0.0f, v3_dot(n_shading, s->dir_world));
        const float e[3] = {s->irradiance.x * albedo.x, s->irradiance.y * albedo.y, s->irradiance.z * albedo.z};
        for (int c = 0; c < 3; c++) {
            double contrib = e[c] * cos_p * vis * INV_PI;
            a->c[c] += contrib;
            a->c2[c] += contrib * contrib;
        }
        a->n++;
    }
    a->n += b->below_horizon; /* light below the horizon: zero terms (fill_batch) */
}

/* Visibility with a Laplace-smoothed binomial standard error, p~ = (k+1)/(n+2)
 * in weighted form, so an all-lit or all-blocked sample still reports the
 * uncertainty of n draws; n_eff = (sum w)^2 / sum w^2 for weighted samples. */
static void finish_visibility(const Accum *a, float *value, float *se, int nc)
{
    for (int c = 0; c < nc; c++) {
        if (a->w[c] <= 0.0) { value[c] = 1.0f; se[c] = 0.0f; continue; } /* a black light texel set: nothing to block */
        double mean_w = a->w[c] / a->n;
        double p = a->wv[c] / a->w[c];
        double p_s = (a->wv[c] + mean_w) / (a->w[c] + 2.0 * mean_w);
        double n_eff = a->w[c] * a->w[c] / a->w2[c];
        value[c] = (float)p;
        se[c] = (float)sqrt(p_s * (1.0 - p_s) / n_eff);
    }
}

static void finish_irradiance(const Accum *a, float *value, float *se)
{
    for (int c = 0; c < 3; c++) {
        double mean = a->c[c] / a->n;
        double var = a->n > 1 ? fmax(0.0, (a->c2[c] / a->n - mean * mean) * a->n / (a->n - 1)) : 0.0;
        value[c] = (float)mean;
        se[c] = (float)sqrt(var / a->n);
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
    uint32_t stream = sampling_stream(j->p->seed, (uint32_t)s);
    int nc = j->out->value.channels;
    Accum a = {0};
    int rays = 0;
    for (int first = 0; first < j->count; first += PACKET) {
        fill_batch(b, j->light, org, p, ng, stream, first, j->count, j->p);
        rays += (j->count - first < PACKET ? j->count - first : PACKET) - b->below_horizon;
        rtcOccluded16(b->valid, j->rtc, ctx, &b->ray);
        if (j->p->measure == MEASURE_IRRADIANCE)
            accumulate_irradiance(&a, b, j->vs->n_shading_world[s], j->scene->objects[j->vs->object[s]].albedo);
        else accumulate_visibility(&a, b, nc);
    }
    if (rays == 0 && j->p->measure == MEASURE_VISIBILITY) {
        fill_highest(b, j->light, org, p, ng);
        rtcOccluded16(b->valid, j->rtc, ctx, &b->ray);
        accumulate_visibility(&a, b, nc);
        rays = 1;
    }
    float *v = j->out->value.data + (size_t)s * nc, *se = j->out->std_error.data + (size_t)s * nc;
    if (j->p->measure == MEASURE_IRRADIANCE) finish_irradiance(&a, v, se);
    else finish_visibility(&a, v, se, nc);
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
    RefJob j = {rt_scene_handle(casters), scene, l, vs, p, light_is_delta(l) ? 1 : p->samples,
                scene_extent(scene), out};
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
