/* aliasing.c -- the sampling-error instrument (aliasing.h; course §3.1). */
#include "resources/aliasing.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "resources/standard.h"

#define STEP_PIXELS 1e-3 /* central differences over a thousandth of a pixel's footprint */

AliasingView aliasing_view(const Camera *cam)
{
    AliasingView av = {view_frustum(cam), 0.0, cam->width, cam->height};
    av.pixel = 2.0 * av.frustum.tan_y / cam->height;
    return av;
}

dvec3 aliasing_to_light(const Light *light, dvec3 p)
{
    if (light->kind == LIGHT_DIRECTIONAL) return d3_scale(d3_normalize_or(d3_from(light->direction), d3(0, -1, 0)), -1);
    return d3_normalize_or(d3_sub(d3_from(light->position), p), d3(0, 1, 0));
}

/* The tangent-plane step of one pixel along image axis e (unit, in the
 * image plane): the ray through p moves by e per unit depth; it meets the
 * plane (p, n) at p + z (e - (n.e) / (n.d) d), d = (p - eye) / z. */
static dvec3 pixel_step(dvec3 d, double z, dvec3 n, dvec3 e, double pixel)
{
    double nd = d3_dot(n, d);
    return d3_scale(d3_sub(e, d3_scale(d, d3_dot(n, e) / nd)), z * pixel);
}

bool aliasing_at(const LightView *lv, const AliasingView *av, dvec3 p, dvec3 n, dvec3 to_light, AliasingPoint *out)
{
    const ViewFrustum *f = &av->frustum;
    dvec3 r = d3_sub(p, f->eye);
    double z = d3_dot(r, f->fwd), dist = d3_len(r);
    if (!(z > 0.0) || !isfinite(z)) return false;
    dvec3 d = d3_scale(r, 1.0 / z);
    if (!(fabs(d3_dot(n, d)) > 1e-9 * d3_len(d))) return false; /* seen edge-on: no footprint */
    MapCoord mc = lightview_locate(lv, p);
    if (!mc.inside) return false;
    /* pixel x runs along `right`, pixel y downward */
    dvec3 step[2] = {pixel_step(d, z, n, f->right, av->pixel), pixel_step(d, z, n, d3_scale(f->up, -1), av->pixel)};
    double J[2][2]; /* J[axis s|t][pixel x|y], texels per pixel */
    for (int k = 0; k < 2; k++) {
        MapCoord a = lightview_locate_on(lv, mc.face, d3_madd(p, step[k], -STEP_PIXELS));
        MapCoord b = lightview_locate_on(lv, mc.face, d3_madd(p, step[k], STEP_PIXELS));
        J[0][k] = (b.s - a.s) / (2.0 * STEP_PIXELS);
        J[1][k] = (b.t - a.t) / (2.0 * STEP_PIXELS);
    }
    double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    if (!isfinite(det) || !isfinite(J[0][0] + J[0][1] + J[1][0] + J[1][1])) return false;
    /* columns of J^-1: pixels per unit s (J11, -J10) / det and per unit t (-J01, J00) / det */
    double as = hypot(J[1][1], J[1][0]), at = hypot(J[0][1], J[0][0]);
    out->m_s = fabs(det) > 0.0 ? fmin(as / fabs(det), ALIASING_M_CAP) : ALIASING_M_CAP;
    out->m_t = fabs(det) > 0.0 ? fmin(at / fabs(det), ALIASING_M_CAP) : ALIASING_M_CAP;
    double cos_a = fabs(d3_dot(n, r)) / dist, cos_b = fabs(d3_dot(n, to_light));
    out->proj = cos_a / fmax(cos_b, 1e-9);
    out->face = mc.face;
    out->depth = z;
    return true;
}

/* The instrument at p for a surface element facing the eye and the light alike. */
static bool half_vector_at(const LightView *lv, const AliasingView *av, const Light *light, dvec3 p, AliasingPoint *out)
{
    dvec3 to_eye = d3_normalize_or(d3_sub(av->frustum.eye, p), d3_scale(av->frustum.fwd, -1));
    dvec3 to_light = aliasing_to_light(light, p);
    dvec3 n = d3_normalize_or(d3_add(to_eye, to_light), to_eye); /* the half vector */
    return aliasing_at(lv, av, p, n, to_light, out);
}

bool aliasing_on_axis(const LightView *lv, const AliasingView *av, const Light *light, double z, AliasingPoint *out)
{
    return half_vector_at(lv, av, light, d3_madd(av->frustum.eye, av->frustum.fwd, z), out);
}

void aliasing_normalised(const AliasingView *av, int res, const AliasingPoint *pt, double *e_x, double *e_y)
{
    *e_y = pt->m_t * res * av->pixel;
    *e_x = pt->m_s * res / av->width;
}

/* ---- summaries ------------------------------------------------------------------- */

double aliasing_hist_edge(int b) { return pow(10.0, -2.0 + 4.0 * b / ALIASING_HIST_BINS); }

void aliasing_summary_init(AliasingSummary *s, int num_faces, double depth_lo, double depth_hi)
{
    memset(s, 0, sizeof *s);
    s->num_faces = num_faces;
    s->depth_lo = fmax(depth_lo, 1e-300);
    s->depth_hi = fmax(depth_hi, s->depth_lo * (1.0 + 1e-12));
}

void aliasing_summary_add(AliasingSummary *s, const AliasingPoint *pt)
{
    double m = fmax(pt->m_s, pt->m_t);
    s->measured++;
    s->undersampled += m > 1.0;
    if (m >= ALIASING_M_CAP) { /* a texel edge-on: projection aliasing without bound */
        s->singular++;
        s->hist[ALIASING_HIST_BINS - 1]++;
        return;
    }
    s->m_max = fmax(s->m_max, m);
    s->m_mean += m;
    s->m_s_max = fmax(s->m_s_max, pt->m_s);
    s->m_t_max = fmax(s->m_t_max, pt->m_t);
    s->m_s_mean += pt->m_s;
    s->m_t_mean += pt->m_t;
    int b = (int)floor((log10(fmax(m, 1e-300)) + 2.0) * ALIASING_HIST_BINS / 4.0);
    s->hist[b < 0 ? 0 : b >= ALIASING_HIST_BINS ? ALIASING_HIST_BINS - 1 : b]++;
    double t = log(pt->depth / s->depth_lo) / log(s->depth_hi / s->depth_lo);
    int k = (int)floor(t * ALIASING_DEPTH_BINS);
    k = k < 0 ? 0 : k >= ALIASING_DEPTH_BINS ? ALIASING_DEPTH_BINS - 1 : k;
    s->depth_count[k]++;
    s->depth_m_s[k] += pt->m_s;
    s->depth_m_t[k] += pt->m_t;
    s->depth_m_s_max[k] = fmax(s->depth_m_s_max[k], pt->m_s);
    s->depth_m_t_max[k] = fmax(s->depth_m_t_max[k], pt->m_t);
    s->depth_persp_s[k] += pt->m_s / fmax(pt->proj, 1e-12);
    s->depth_persp_t[k] += pt->m_t / fmax(pt->proj, 1e-12);
    if (pt->face >= 0 && pt->face < LIGHTVIEW_MAX_FACES) {
        s->face_count[pt->face]++;
        s->face_m_s_max[pt->face] = fmax(s->face_m_s_max[pt->face], pt->m_s);
        s->face_m_t_max[pt->face] = fmax(s->face_m_t_max[pt->face], pt->m_t);
    }
}

void aliasing_summary_finish(AliasingSummary *s, int res, int width, int height)
{
    double n = s->measured > s->singular ? (double)(s->measured - s->singular) : 1.0;
    s->m_mean /= n;
    s->m_s_mean /= n;
    s->m_t_mean /= n;
    for (int k = 0; k < ALIASING_DEPTH_BINS; k++) {
        double c = s->depth_count[k] > 0 ? (double)s->depth_count[k] : 1.0;
        s->depth_m_s[k] /= c;
        s->depth_m_t[k] /= c;
        s->depth_persp_s[k] /= c;
        s->depth_persp_t[k] /= c;
    }
    /* Lloyd et al. 2006 §3: the storage a map needs scales with its
     * resolution squared; res max(m_s) x res max(m_t) texels per map bring
     * its maximum error to 1 on both axes. */
    s->storage = 0.0;
    for (int f = 0; f < s->num_faces && f < LIGHTVIEW_MAX_FACES; f++)
        if (s->face_count[f] > 0)
            s->storage += (double)res * res * s->face_m_s_max[f] * s->face_m_t_max[f] / ((double)width * height);
}

/* ---- the resource -------------------------------------------------------------------- */

static void aliasing_destroy(void *r)
{
    AliasingMap *a = r;
    free(a->m_s);
    free(a->m_t);
    free(a->proj);
    free(a->face);
    free(a);
}

static size_t aliasing_bytes(const void *r)
{
    const AliasingMap *a = r;
    return sizeof *a + (size_t)a->width * a->height * (3 * sizeof(float) + sizeof(int8_t));
}

static const ResourceKind kind_aliasing = {"aliasing", aliasing_bytes, aliasing_destroy, RES_FRAME};

typedef struct AliasingArgs {
    ResourceManager *rm;
    const Scene *scene;
    int light_index;
    const ShadowMap *map;
} AliasingArgs;

static void measure_samples(AliasingMap *a, const AliasingArgs *args, const ViewSamples *vs, const uint8_t *cls)
{
    const Light *light = &args->scene->lights[args->light_index];
    AliasingView av = aliasing_view(&args->scene->camera);
    const LightView *lv = &args->map->view;
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < vs->height; y++)
        for (int x = 0; x < vs->width; x++) {
            int s = y * vs->width + x;
            AliasingPoint pt;
            dvec3 p = d3_from(vs->p_world[s]);
            bool ok = cls[s] == SAMPLE_LIT_CANDIDATE &&
                      aliasing_at(lv, &av, p, d3_from(vs->n_geom_world[s]), aliasing_to_light(light, p), &pt);
            a->m_s[s] = ok ? (float)pt.m_s : NAN;
            a->m_t[s] = ok ? (float)pt.m_t : NAN;
            a->proj[s] = ok ? (float)pt.proj : NAN;
            a->face[s] = ok ? (int8_t)pt.face : -1;
        }
}

static void *build_aliasing(const void *args_, Error *err)
{
    const AliasingArgs *args = args_;
    const ViewSamples *vs = res_view_samples(args->rm, args->scene, err);
    const uint8_t *cls = vs ? res_classes(args->rm, args->scene, args->light_index, err) : NULL;
    if (!cls) return NULL;
    AliasingMap *a = calloc(1, sizeof *a);
    size_t n = (size_t)vs->count;
    if (a) {
        a->width = vs->width;
        a->height = vs->height;
        a->m_s = malloc(n * sizeof *a->m_s);
        a->m_t = malloc(n * sizeof *a->m_t);
        a->proj = malloc(n * sizeof *a->proj);
        a->face = malloc(n * sizeof *a->face);
    }
    if (!a || !a->m_s || !a->m_t || !a->proj || !a->face) {
        if (a) aliasing_destroy(a);
        error_set(err, "out of memory for the aliasing analysis of %dx%d samples", vs->width, vs->height);
        return NULL;
    }
    measure_samples(a, args, vs, cls);
    const Camera *cam = &args->scene->camera;
    aliasing_summary_init(&a->sum, args->map->num_faces, cam->near_dist, cam->far_dist);
    for (size_t s = 0; s < n; s++) {
        if (a->face[s] < 0) continue;
        AliasingPoint pt = {a->m_s[s], a->m_t[s], a->proj[s], a->face[s], vs->depth_view[s]};
        aliasing_summary_add(&a->sum, &pt);
    }
    aliasing_summary_finish(&a->sum, args->map->res, cam->width, cam->height);
    return a;
}

const AliasingMap *res_aliasing(ResourceManager *rm, const Scene *scene, int light_index, const ShadowMap *map,
                                Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, "aliasing");
    hash_u64(&h, map->key);
    hash_u64(&h, scene->hash_geometry); /* the view samples */
    hash_u64(&h, scene->hash_camera);
    hash_u64(&h, scene->hash_lights[light_index]);
    AliasingArgs a = {rm, scene, light_index, map};
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %d^2 %s map x%d", light_index + 1, map->res,
             map_projection_name(map->view.projection), map->num_faces);
    return rm_acquire(rm, &kind_aliasing, hash_final(&h), desc, build_aliasing, &a, err);
}

/* ---- over the frustum ----------------------------------------------------------------- */

static bool inside_box(const Scene *sc, dvec3 p)
{
    return p.x >= sc->bounds_min.x && p.x <= sc->bounds_max.x && p.y >= sc->bounds_min.y &&
           p.y <= sc->bounds_max.y && p.z >= sc->bounds_min.z && p.z <= sc->bounds_max.z;
}

void aliasing_frustum(const LightView *lv, const Scene *scene, const Light *light, int nx, int ny, int nz,
                      AliasingSummary *out)
{
    AliasingView av = aliasing_view(&scene->camera);
    const ViewFrustum *f = &av.frustum;
    aliasing_summary_init(out, lv->num_faces, f->near, f->far);
    for (int k = 0; k < nz; k++) {
        double d = f->near * pow(f->far / f->near, (k + 0.5) / nz);
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                dvec3 p = frustum_point(f, 2.0 * (i + 0.5) / nx - 1.0, 2.0 * (j + 0.5) / ny - 1.0, d);
                AliasingPoint pt;
                if (inside_box(scene, p) && half_vector_at(lv, &av, light, p, &pt)) aliasing_summary_add(out, &pt);
            }
    }
    aliasing_summary_finish(out, lv->res, scene->camera.width, scene->camera.height);
}
