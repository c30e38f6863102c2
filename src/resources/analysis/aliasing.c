/* aliasing.c -- the sampling-error instrument (aliasing.h; course §3.1). */
#include "resources/analysis/aliasing.h"
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

const char *aliasing_storage_name(const AliasingSummary *s)
{
    return s->perspective_only ? "storage_factor" : "total_aliasing_storage";
}

void aliasing_summary_init(AliasingSummary *s, int num_faces, double depth_lo, double depth_hi, bool perspective_only)
{
    memset(s, 0, sizeof *s);
    s->num_faces = num_faces;
    s->perspective_only = perspective_only;
    s->depth_lo = fmax(depth_lo, 1e-300);
    s->depth_hi = fmax(depth_hi, s->depth_lo * (1.0 + 1e-12));
}

/* Depth-profile bin of view depth z (log bins over the summary's range). */
static int depth_bin(const AliasingSummary *s, double z)
{
    double t = log(z / s->depth_lo) / log(s->depth_hi / s->depth_lo);
    int k = (int)floor(t * ALIASING_DEPTH_BINS);
    return k < 0 ? 0 : k >= ALIASING_DEPTH_BINS ? ALIASING_DEPTH_BINS - 1 : k;
}

/* The maxima alone (overall, per depth bin, per face) of a finite point. */
static void raise_maxima(AliasingSummary *s, const AliasingPoint *pt)
{
    s->m_max = fmax(s->m_max, fmax(pt->m_s, pt->m_t));
    s->m_s_max = fmax(s->m_s_max, pt->m_s);
    s->m_t_max = fmax(s->m_t_max, pt->m_t);
    int k = depth_bin(s, pt->depth);
    s->depth_m_s_max[k] = fmax(s->depth_m_s_max[k], pt->m_s);
    s->depth_m_t_max[k] = fmax(s->depth_m_t_max[k], pt->m_t);
    if (pt->face >= 0 && pt->face < LIGHTVIEW_MAX_FACES) {
        s->face_m_s_max[pt->face] = fmax(s->face_m_s_max[pt->face], pt->m_s);
        s->face_m_t_max[pt->face] = fmax(s->face_m_t_max[pt->face], pt->m_t);
    }
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
    raise_maxima(s, pt);
    s->m_mean += m;
    s->m_s_mean += pt->m_s;
    s->m_t_mean += pt->m_t;
    int b = (int)floor((log10(fmax(m, 1e-300)) + 2.0) * ALIASING_HIST_BINS / 4.0);
    s->hist[b < 0 ? 0 : b >= ALIASING_HIST_BINS ? ALIASING_HIST_BINS - 1 : b]++;
    int k = depth_bin(s, pt->depth);
    s->depth_count[k]++;
    s->depth_m_s[k] += pt->m_s;
    s->depth_m_t[k] += pt->m_t;
    s->depth_persp_s[k] += pt->m_s / fmax(pt->proj, 1e-12);
    s->depth_persp_t[k] += pt->m_t / fmax(pt->proj, 1e-12);
    if (pt->face >= 0 && pt->face < LIGHTVIEW_MAX_FACES) s->face_count[pt->face]++;
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
    aliasing_summary_init(&a->sum, args->map->num_faces, cam->near_dist, cam->far_dist, false);
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

/* Lloyd et al. 2006 (§3) take the maximum error over the frustum; for
 * each map it lies on the boundary of the part of B the map serves (the
 * near plane, B's faces and edges, a cascade's split plane, a frustum
 * face's partition plane). The measure probes B's boundary exactly (image
 * edges, each ray's entry and exit), finds every map change a ray crosses
 * by bisection, and climbs from each map's highest probe to boundaries no
 * ray crosses (planes through the eye). A probe is an image position
 * (sx, sy) in [-1, 1]^2 and tau in [0, 1]: the log-spaced place along that
 * ray's span [d0, d1] inside B, view depth d0 (d1 / d0)^tau. */
#define TRANSITION_STEPS 40 /* bisections of a map change along a ray: tau to 2^-40 */
#define CLIMB_HALVINGS 24   /* a climb's step shrinks from one node spacing to 2^-24 of it */
#define CLIMB_MOVES 64      /* and moves at most this many times (it starts within a spacing of its peak) */

typedef struct FrustumPeak {
    double at[3];  /* sx, sy, tau */
    double value;  /* m_s or m_t there; 0: none yet */
} FrustumPeak;

typedef struct FrustumProbe {
    const LightView *lv;
    const Scene *scene;
    const Light *light;
    AliasingView av;
    AliasingSummary *out;
    FrustumPeak peak[LIGHTVIEW_MAX_FACES][2]; /* per map, the largest m_s [0] and m_t [1] probed */
} FrustumProbe;

/* Node i of n over [lo, hi], both ends included (n = 1: the middle). */
static double node(int i, int n, double lo, double hi) { return n > 1 ? lo + (hi - lo) * i / (n - 1) : 0.5 * (lo + hi); }

/* The view depths [*d0, *d1] where the ray through image position (sx, sy)
 * is inside both the frustum's depth range and the scene's bounds (slab
 * clipping, Kay & Kajiya 1986); false where it misses the box. */
static bool ray_span(const ViewFrustum *f, const Scene *sc, double sx, double sy, double *d0, double *d1)
{
    dvec3 dir = d3_sub(frustum_point(f, sx, sy, 1.0), f->eye); /* world units per unit view depth */
    const double o[3] = {f->eye.x, f->eye.y, f->eye.z}, v[3] = {dir.x, dir.y, dir.z};
    const double lo[3] = {sc->bounds_min.x, sc->bounds_min.y, sc->bounds_min.z};
    const double hi[3] = {sc->bounds_max.x, sc->bounds_max.y, sc->bounds_max.z};
    double a = f->near, b = f->far;
    for (int k = 0; k < 3; k++) {
        if (v[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k]) return false;
            continue;
        }
        double t0 = (lo[k] - o[k]) / v[k], t1 = (hi[k] - o[k]) / v[k];
        if (t0 > t1) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
        if (t0 > a) a = t0;
        if (t1 < b) b = t1;
    }
    *d0 = a;
    *d1 = b;
    return a <= b;
}

/* The instrument at a probe; its map's index, or -1 where not measured. */
static int probe_at(const FrustumProbe *p, const double at[3], AliasingPoint *pt)
{
    double d0, d1;
    if (!ray_span(&p->av.frustum, p->scene, at[0], at[1], &d0, &d1)) return -1;
    dvec3 x = frustum_point(&p->av.frustum, at[0], at[1], d0 * pow(d1 / d0, at[2]));
    return half_vector_at(p->lv, &p->av, p->light, x, pt) && pt->m_s < ALIASING_M_CAP && pt->m_t < ALIASING_M_CAP
               ? pt->face
               : -1;
}

/* Keep a probe's point in the summary and as its map's peak when higher. */
static void keep(FrustumProbe *p, const AliasingPoint *pt, const double at[3])
{
    aliasing_summary_add(p->out, pt);
    const double m[2] = {pt->m_s, pt->m_t};
    for (int a = 0; a < 2; a++) {
        FrustumPeak *k = &p->peak[pt->face][a];
        if (m[a] > k->value) *k = (FrustumPeak){{at[0], at[1], at[2]}, m[a]};
    }
}

/* A map change (or the map's edge) between tau lo and hi on a ray: bisect
 * it and keep the last point on lo's side and the first on hi's (the
 * nodes themselves are kept already). */
static void add_transition(FrustumProbe *p, double sx, double sy, double lo, double hi, int face_lo)
{
    AliasingPoint at_lo, at_hi;
    double where_lo[3] = {sx, sy, lo}, where_hi[3] = {sx, sy, hi};
    bool got_lo = false, got_hi = false;
    for (int i = 0; i < TRANSITION_STEPS; i++) {
        double mid[3] = {sx, sy, 0.5 * (where_lo[2] + where_hi[2])};
        AliasingPoint pt;
        int face = probe_at(p, mid, &pt);
        bool low_side = face == face_lo;
        memcpy(low_side ? where_lo : where_hi, mid, sizeof mid);
        *(low_side ? &at_lo : &at_hi) = pt;
        *(low_side ? &got_lo : &got_hi) = face >= 0;
    }
    if (got_lo) keep(p, &at_lo, where_lo);
    if (got_hi) keep(p, &at_hi, where_hi);
}

/* nz nodes along the ray through (sx, sy), both ends of its span included,
 * and every map change between them. */
static void add_ray(FrustumProbe *p, double sx, double sy, int nz)
{
    int prev_face = -1;
    for (int k = 0; k < nz; k++) {
        double at[3] = {sx, sy, node(k, nz, 0.0, 1.0)};
        AliasingPoint pt;
        int face = probe_at(p, at, &pt);
        if (k > 0 && face != prev_face) add_transition(p, sx, sy, node(k - 1, nz, 0.0, 1.0), at[2], prev_face);
        if (face >= 0) keep(p, &pt, at);
        prev_face = face;
    }
}

/* From a map's highest probe of m_s (axis 0) or m_t (1), a compass search
 * (Hooke & Jeeves 1961) over (sx, sy, tau) within the domain and that
 * map's region: it moves to the best higher neighbour at step h and halves
 * h when none is higher. Only the maxima take its points (the means and
 * counts stay the grid's). */
static void climb(FrustumProbe *p, int face, int axis, const double h0[3])
{
    FrustumPeak best = p->peak[face][axis];
    if (!(best.value > 0.0)) return;
    static const double lo[3] = {-1.0, -1.0, 0.0}, hi[3] = {1.0, 1.0, 1.0};
    double h[3] = {h0[0], h0[1], h0[2]};
    int moves = 0;
    for (int halvings = 0; halvings < CLIMB_HALVINGS && moves < CLIMB_MOVES;) {
        FrustumPeak next = best;
        AliasingPoint next_pt;
        for (int c = 0; c < 6; c++) {
            double at[3] = {best.at[0], best.at[1], best.at[2]};
            at[c / 2] = fmin(fmax(at[c / 2] + (c % 2 ? h[c / 2] : -h[c / 2]), lo[c / 2]), hi[c / 2]);
            AliasingPoint pt;
            double m = probe_at(p, at, &pt) == face ? (axis ? pt.m_t : pt.m_s) : 0.0;
            if (m > next.value) {
                next = (FrustumPeak){{at[0], at[1], at[2]}, m};
                next_pt = pt;
            }
        }
        if (next.value > best.value) {
            best = next;
            raise_maxima(p->out, &next_pt);
            moves++;
        } else {
            for (int k = 0; k < 3; k++) h[k] *= 0.5;
            halvings++;
        }
    }
}

void aliasing_frustum(const LightView *lv, const Scene *scene, const Light *light, int nx, int ny, int nz,
                      AliasingSummary *out)
{
    FrustumProbe p = {.lv = lv, .scene = scene, .light = light, .av = aliasing_view(&scene->camera), .out = out};
    aliasing_summary_init(out, lv->num_faces, p.av.frustum.near, p.av.frustum.far, true);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) add_ray(&p, node(i, nx, -1.0, 1.0), node(j, ny, -1.0, 1.0), nz);
    const double h0[3] = {nx > 1 ? 2.0 / (nx - 1) : 1.0, ny > 1 ? 2.0 / (ny - 1) : 1.0, nz > 1 ? 1.0 / (nz - 1) : 0.5};
    for (int f = 0; f < lv->num_faces && f < LIGHTVIEW_MAX_FACES; f++)
        for (int axis = 0; axis < 2; axis++) climb(&p, f, axis, h0);
    aliasing_summary_finish(out, lv->res, scene->camera.width, scene->camera.height);
}
