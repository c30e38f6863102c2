/* lightview.c -- projections of shadow-map faces, their fitting to a target
 * point set (course §3.2.1 "fitting": the map covers only what is seen or
 * what exists), and world -> map lookups (see lightview.h). */
#include "resources/lightview.h"
#include <float.h>
#include <stdlib.h>
#include <string.h>

#define MAX_TAN_PERSPECTIVE 3.7320508 /* tan 75 degrees: a 150-degree frustum at most */
#define MARGIN_TEXELS 2.0             /* fitted extents grow by this much on each side */
#define NEAR_MIN_FRACTION 1e-4        /* near >= this fraction of far */

const char *map_projection_name(MapProjection p)
{
    static const char *const names[] = {MAP_PROJ_NAMES};
    return names[p];
}

const char *map_fit_name(MapFit f)
{
    static const char *const names[] = {MAP_FIT_NAMES};
    return names[f];
}

/* ---- the target ----------------------------------------------------------- */

typedef struct Target {
    dvec3 *pts;      /* what the map must cover laterally */
    int n;
    dvec3 bounds[8]; /* the scene's box corners: everything that can cast */
    double extent;   /* scene diagonal */
} Target;

static void box_corners(vec3 lo, vec3 hi, dvec3 *out)
{
    for (int k = 0; k < 8; k++) out[k] = d3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
}

static bool target_init(const Scene *sc, MapFit fit, const ViewSamples *vs, const uint8_t *cls, Target *t, Error *err)
{
    memset(t, 0, sizeof *t);
    box_corners(sc->bounds_min, sc->bounds_max, t->bounds);
    t->extent = scene_extent(sc);
    int n = 0;
    if (fit == MAP_FIT_VIEW && vs && cls)
        for (int s = 0; s < vs->count; s++) n += cls[s] == SAMPLE_LIT_CANDIDATE;
    /* no receiver in view (every pixel background or unlit): the scene's bounds */
    t->pts = malloc(sizeof *t->pts * (size_t)(n > 8 ? n : 8));
    if (!t->pts) return error_set(err, "out of memory fitting the light's frustum");
    if (n == 0) {
        memcpy(t->pts, t->bounds, sizeof t->bounds);
        t->n = 8;
        return true;
    }
    for (int s = 0; s < vs->count; s++)
        if (cls[s] == SAMPLE_LIT_CANDIDATE) t->pts[t->n++] = d3_from(vs->p_world[s]);
    return true;
}

/* ---- faces ------------------------------------------------------------------ */

static dvec3 any_up(dvec3 axis) { return fabs(axis.y) < 0.99 ? d3(0, 1, 0) : d3(0, 0, 1); }

static bool face_finish(MapFace *f, const mat4 *proj, double n, double far, Error *err)
{
    f->raster.clip_from_world = m4_mul(proj, &f->view_from_world);
    for (int k = 0; k < 4; k++) f->raster.depth_row[k] = -f->view_from_world.m[2][k];
    f->raster.depth_near = n;
    f->raster.depth_far = far;
    if (!m4_invert(&f->raster.clip_from_world, &f->world_from_clip))
        return error_set(err, "the light's projection is singular (near %g, far %g)", n, far);
    return true;
}

/* Perspective face from `eye` along `axis`, tangent extents [l, r] x [b, t]. */
static bool face_perspective(MapFace *f, dvec3 eye, dvec3 axis, dvec3 up, const double ext[4], double n, double far,
                             Error *err)
{
    memset(f, 0, sizeof *f);
    f->view_from_world = m4_look(eye, axis, up);
    f->axis_world = axis;
    f->perspective = true;
    f->l = ext[0]; f->r = ext[1]; f->b = ext[2]; f->t = ext[3];
    mat4 proj = m4_frustum(ext[0] * n, ext[1] * n, ext[2] * n, ext[3] * n, n, far);
    return face_finish(f, &proj, n, far, err);
}

static bool face_ortho(MapFace *f, dvec3 eye, dvec3 axis, dvec3 up, const double ext[4], double n, double far,
                       Error *err)
{
    memset(f, 0, sizeof *f);
    f->view_from_world = m4_look(eye, axis, up);
    f->axis_world = axis;
    f->l = ext[0]; f->r = ext[1]; f->b = ext[2]; f->t = ext[3];
    mat4 proj = m4_ortho(ext[0], ext[1], ext[2], ext[3], n, far);
    return face_finish(f, &proj, n, far, err);
}

static void face_paraboloid(MapFace *f, dvec3 eye, dvec3 axis, double n, double far)
{
    memset(f, 0, sizeof *f);
    f->view_from_world = m4_look(eye, axis, any_up(axis));
    f->axis_world = axis;
    f->paraboloid = true;
    f->raster.mapping = RASTER_PARABOLOID;
    f->raster.clip_from_world = f->view_from_world;
    f->raster.depth_near = n;
    f->raster.depth_far = far;
    f->l = f->b = -1.0;
    f->r = f->t = 1.0;
}

/* ---- extents of point sets ---------------------------------------------------- */

/* Grow [lo, hi] by the margin, and to a minimum width. */
static void pad(double *lo, double *hi, int res, double min_width)
{
    double w = fmax(*hi - *lo, min_width), c = 0.5 * (*hi + *lo);
    w *= 1.0 + 2.0 * MARGIN_TEXELS / res;
    *lo = c - 0.5 * w;
    *hi = c + 0.5 * w;
}

/* Tangent extents and depth range of pts in front of a perspective view;
 * returns the widest angle (cosine to the axis) among them. */
static double tangent_extents(const mat4 *view, const dvec3 *pts, int n, double max_tan, double ext[4], double *dmax)
{
    ext[0] = ext[2] = INFINITY;
    ext[1] = ext[3] = -INFINITY;
    *dmax = 0.0;
    double min_cos = 1.0;
    for (int i = 0; i < n; i++) {
        dvec4 v = m4_apply(view, pts[i]);
        double d = -v.z, r = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        if (r > 0.0) min_cos = fmin(min_cos, d / r);
        if (!(d > 0.0)) continue; /* behind the light: outside any perspective map */
        double tx = fmin(fmax(v.x / d, -max_tan), max_tan), ty = fmin(fmax(v.y / d, -max_tan), max_tan);
        ext[0] = fmin(ext[0], tx); ext[1] = fmax(ext[1], tx);
        ext[2] = fmin(ext[2], ty); ext[3] = fmax(ext[3], ty);
        *dmax = fmax(*dmax, d);
    }
    if (!(ext[0] <= ext[1])) { ext[0] = ext[2] = -max_tan; ext[1] = ext[3] = max_tan; }
    return min_cos;
}

/* Near plane: the nearest scene-box corner in front, at least a fraction of far. */
static double near_plane(const mat4 *view, const dvec3 *bounds, double far)
{
    double dmin = INFINITY;
    for (int k = 0; k < 8; k++) dmin = fmin(dmin, -m4_apply(view, bounds[k]).z);
    return fmin(fmax(dmin * 0.99, NEAR_MIN_FRACTION * far), 0.5 * far);
}

static dvec3 centroid(const dvec3 *pts, int n)
{
    dvec3 c = d3(0, 0, 0);
    for (int i = 0; i < n; i++) c = d3_add(c, pts[i]);
    return d3_scale(c, 1.0 / n);
}

/* ---- per projection ------------------------------------------------------------ */

static bool fit_perspective(LightView *lv, const Light *light, MapFit fit, const Target *tg, Error *err)
{
    dvec3 eye = d3_from(light->position), axis;
    double max_tan = MAX_TAN_PERSPECTIVE;
    if (light->kind == LIGHT_SPOT) {
        axis = d3_from(light->direction);
        max_tan = fmin(max_tan, tan(light->cone_half_rad));
    } else if (light->kind == LIGHT_RECT || light->kind == LIGHT_DISK || light->kind == LIGHT_TEXTURED_RECT) {
        axis = d3_from(light->direction);
    } else {
        axis = d3_normalize_or(d3_sub(centroid(tg->pts, tg->n), eye), d3(0, -1, 0));
    }
    mat4 view = m4_look(eye, axis, any_up(axis));
    double ext[4], dmax;
    tangent_extents(&view, tg->pts, tg->n, max_tan, ext, &dmax);
    double dbound;
    double bext[4];
    tangent_extents(&view, tg->bounds, 8, max_tan, bext, &dbound);
    if (fit == MAP_FIT_NONE) {
        double m = light->kind == LIGHT_SPOT ? max_tan : fmax(fmax(-bext[0], bext[1]), fmax(-bext[2], bext[3]));
        ext[0] = ext[2] = -m;
        ext[1] = ext[3] = m;
        dmax = dbound;
    }
    double far = fmax(dmax, 1e-6 * tg->extent) * 1.01;
    pad(&ext[0], &ext[1], lv->res, 1e-6);
    pad(&ext[2], &ext[3], lv->res, 1e-6);
    lv->num_faces = 1;
    return face_perspective(&lv->face[0], eye, axis, any_up(axis), ext, near_plane(&view, tg->bounds, far), far, err);
}

static bool fit_ortho(LightView *lv, const Light *light, MapFit fit, const Target *tg, Error *err)
{
    dvec3 axis = d3_from(light->direction);
    dvec3 centre = d3_scale(d3_add(tg->bounds[0], tg->bounds[7]), 0.5);
    double radius = 0.5 * d3_len(d3_sub(tg->bounds[7], tg->bounds[0]));
    dvec3 eye = d3_madd(centre, axis, -2.0 * fmax(radius, 1e-30)); /* outside the scene, looking in */
    mat4 view = m4_look(eye, axis, any_up(axis));
    double ext[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY}, near = INFINITY, far = 0.0;
    for (int i = 0; i < tg->n; i++) {
        dvec4 v = m4_apply(&view, tg->pts[i]);
        ext[0] = fmin(ext[0], v.x); ext[1] = fmax(ext[1], v.x);
        ext[2] = fmin(ext[2], v.y); ext[3] = fmax(ext[3], v.y);
        far = fmax(far, -v.z);
    }
    for (int k = 0; k < 8; k++) {
        dvec4 v = m4_apply(&view, tg->bounds[k]);
        near = fmin(near, -v.z);
        if (fit == MAP_FIT_NONE) far = fmax(far, -v.z);
    }
    if (fit == MAP_FIT_NONE) { /* the bounding sphere, whatever the light's direction */
        dvec4 c = m4_apply(&view, centre);
        ext[0] = c.x - radius; ext[1] = c.x + radius; ext[2] = c.y - radius; ext[3] = c.y + radius;
    }
    double depth_pad = 1e-3 * fmax(radius, 1e-30);
    pad(&ext[0], &ext[1], lv->res, 1e-6 * tg->extent);
    pad(&ext[2], &ext[3], lv->res, 1e-6 * tg->extent);
    lv->num_faces = 1;
    return face_ortho(&lv->face[0], eye, axis, any_up(axis), ext, fmax(near - depth_pad, 0.0), far + depth_pad, err);
}

/* Range of radial distances from the centre to the scene: near, far. */
static void radial_range(dvec3 c, const Target *tg, double *near, double *far)
{
    dvec3 lo = tg->bounds[0], hi = tg->bounds[7];
    dvec3 q = d3(fmin(fmax(c.x, lo.x), hi.x), fmin(fmax(c.y, lo.y), hi.y), fmin(fmax(c.z, lo.z), hi.z));
    *far = 0.0;
    for (int k = 0; k < 8; k++) *far = fmax(*far, d3_len(d3_sub(tg->bounds[k], c)));
    *far = fmax(*far, 1e-6 * tg->extent) * 1.01;
    *near = fmin(fmax(d3_len(d3_sub(q, c)) * 0.99, NEAR_MIN_FRACTION * *far), 0.5 * *far);
}

static bool fit_cube(LightView *lv, const Light *light, const Target *tg, Error *err)
{
    static const double axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    dvec3 c = d3_from(light->position);
    double near, far;
    radial_range(c, tg, &near, &far);
    /* Faces reach `guard` texels past 45 degrees, so filters near a seam read
     * the right texels from one face (course §2.1.1: cube maps; seams). */
    lv->guard = lv->res < 16 ? 0 : lv->res < 64 ? 1 : lv->res / 32 < 16 ? lv->res / 32 : 16;
    double tg_ext = (double)lv->res / (lv->res - 2 * lv->guard);
    const double ext[4] = {-tg_ext, tg_ext, -tg_ext, tg_ext};
    lv->num_faces = 6;
    for (int k = 0; k < 3; k++) lv->cube_axes[k] = d3(k == 0, k == 1, k == 2);
    for (int f = 0; f < 6; f++) {
        dvec3 axis = d3(axes[f][0], axes[f][1], axes[f][2]);
        if (!face_perspective(&lv->face[f], c, axis, any_up(axis), ext, near, far, err)) return false;
    }
    return true;
}

static bool fit_paraboloid(LightView *lv, const Light *light, const Target *tg)
{
    dvec3 c = d3_from(light->position);
    double near, far;
    radial_range(c, tg, &near, &far);
    lv->num_faces = 2;
    lv->cube_axes[0] = d3(0, -1, 0);
    face_paraboloid(&lv->face[0], c, d3(0, -1, 0), near, far); /* front: the lower hemisphere */
    face_paraboloid(&lv->face[1], c, d3(0, 1, 0), near, far);
    return true;
}

/* What AUTO means for this light and target. */
static MapProjection resolve_auto(const Light *light, const Target *tg)
{
    switch (light->kind) {
    case LIGHT_DIRECTIONAL: return MAP_PROJ_ORTHO;
    case LIGHT_POINT:
    case LIGHT_SPHERE: {
        dvec3 eye = d3_from(light->position);
        dvec3 axis = d3_normalize_or(d3_sub(centroid(tg->pts, tg->n), eye), d3(0, -1, 0));
        mat4 view = m4_look(eye, axis, any_up(axis));
        double ext[4], dmax;
        double min_cos = tangent_extents(&view, tg->bounds, 8, MAX_TAN_PERSPECTIVE, ext, &dmax);
        return min_cos > cos(75.0 * M_PI / 180.0) ? MAP_PROJ_PERSPECTIVE : MAP_PROJ_CUBE;
    }
    default: return MAP_PROJ_PERSPECTIVE;
    }
}

bool lightview_fit(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                   const ViewSamples *vs, const uint8_t *cls, LightView *lv, Error *err)
{
    memset(lv, 0, sizeof *lv);
    if (res < 1 || res > RASTER_MAX_SIZE) return error_set(err, "map_size %d outside [1, %d]", res, RASTER_MAX_SIZE);
    bool directional = light->kind == LIGHT_DIRECTIONAL;
    if (directional && projection != MAP_PROJ_AUTO && projection != MAP_PROJ_ORTHO)
        return error_set(err, "projection %s needs a light with a position; a directional light takes ortho",
                         map_projection_name(projection));
    if (!directional && projection == MAP_PROJ_ORTHO)
        return error_set(err, "projection ortho is for directional lights; a %s light takes perspective, cube or "
                              "paraboloid", light_kind_name(light->kind));
    Target tg;
    if (!target_init(scene, fit, vs, cls, &tg, err)) return false;
    lv->res = res;
    lv->origin_world = d3_from(light->position);
    lv->projection = projection == MAP_PROJ_AUTO ? resolve_auto(light, &tg) : projection;
    bool ok;
    switch (lv->projection) {
    case MAP_PROJ_ORTHO: ok = fit_ortho(lv, light, fit, &tg, err); break;
    case MAP_PROJ_CUBE: ok = fit_cube(lv, light, &tg, err); break;
    case MAP_PROJ_PARABOLOID: ok = fit_paraboloid(lv, light, &tg); break;
    default: ok = fit_perspective(lv, light, fit, &tg, err); break;
    }
    free(tg.pts);
    return ok;
}

/* ---- lookups --------------------------------------------------------------------- */

static int choose_face(const LightView *lv, dvec3 p)
{
    dvec3 d = d3_sub(p, lv->origin_world);
    if (lv->projection == MAP_PROJ_PARABOLOID) return d3_dot(d, lv->cube_axes[0]) >= 0.0 ? 0 : 1;
    if (lv->projection != MAP_PROJ_CUBE) return 0;
    double ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
    if (ax >= ay && ax >= az) return d.x >= 0.0 ? 0 : 1;
    if (ay >= az) return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

MapCoord lightview_locate_on(const LightView *lv, int face, dvec3 p)
{
    const MapFace *f = &lv->face[face];
    MapCoord mc = {.face = face};
    double xn, yn;
    if (f->paraboloid) {
        dvec4 v = m4_apply(&f->view_from_world, p);
        double r;
        paraboloid_ndc(d3(v.x, v.y, v.z), &xn, &yn, &r);
        mc.depth_linear = r;
        double range = f->raster.depth_far - f->raster.depth_near;
        mc.z_ndc = (r - f->raster.depth_near) / range;
        mc.inside = v.z <= 0.0;
    } else {
        dvec4 c = m4_apply(&f->raster.clip_from_world, p);
        const double *row = f->raster.depth_row;
        mc.depth_linear = row[0] * p.x + row[1] * p.y + row[2] * p.z + row[3];
        if (!(c.w > 0.0)) return mc; /* behind a perspective face's eye */
        xn = c.x / c.w;
        yn = c.y / c.w;
        mc.z_ndc = c.z / c.w;
        mc.inside = true;
    }
    mc.s = (xn + 1.0) * 0.5 * lv->res;
    mc.t = (yn + 1.0) * 0.5 * lv->res;
    mc.inside = mc.inside && mc.s >= 0.0 && mc.s < lv->res && mc.t >= 0.0 && mc.t < lv->res && mc.z_ndc >= 0.0 &&
                mc.z_ndc <= 1.0;
    return mc;
}

MapCoord lightview_locate(const LightView *lv, dvec3 p_world)
{
    return lightview_locate_on(lv, choose_face(lv, p_world), p_world);
}

void lightview_texel_ray(const LightView *lv, int face, double s, double t, dvec3 *org, dvec3 *dir)
{
    const MapFace *f = &lv->face[face];
    double xn = 2.0 * s / lv->res - 1.0, yn = 2.0 * t / lv->res - 1.0;
    if (f->paraboloid) { /* inverse of paraboloid_ndc: the unit direction in view space */
        double k = 1.0 / (1.0 + xn * xn + yn * yn);
        dvec3 dv = d3(2.0 * xn * k, 2.0 * yn * k, -(1.0 - xn * xn - yn * yn) * k);
        const double(*m)[4] = f->view_from_world.m; /* rotation part; its transpose maps back */
        *dir = d3(m[0][0] * dv.x + m[1][0] * dv.y + m[2][0] * dv.z, m[0][1] * dv.x + m[1][1] * dv.y + m[2][1] * dv.z,
                  m[0][2] * dv.x + m[1][2] * dv.y + m[2][2] * dv.z);
        *org = lv->origin_world;
        return;
    }
    dvec4 a = m4_apply4(&f->world_from_clip, (dvec4){xn, yn, 0.0, 1.0});
    dvec4 b = m4_apply4(&f->world_from_clip, (dvec4){xn, yn, 1.0, 1.0});
    *org = d3(a.x / a.w, a.y / a.w, a.z / a.w);
    *dir = d3_normalize_or(d3_sub(d3(b.x / b.w, b.y / b.w, b.z / b.w), *org), f->axis_world);
}

double lightview_texel_world(const LightView *lv, const MapCoord *mc)
{
    const MapFace *f = &lv->face[mc->face];
    double w = fmax(f->r - f->l, f->t - f->b) / lv->res;
    if (f->perspective) return w * mc->depth_linear;
    if (f->paraboloid) { /* u = tan(theta/2): d theta = du (1 + cos theta), 1 + cos = 2 / (1 + rho^2) */
        double xn = 2.0 * mc->s / lv->res - 1.0, yn = 2.0 * mc->t / lv->res - 1.0;
        return mc->depth_linear * w * 2.0 / (1.0 + xn * xn + yn * yn);
    }
    return w;
}

double lightview_ndc_per_world(const LightView *lv, const MapCoord *mc)
{
    const MapFace *f = &lv->face[mc->face];
    double n = f->raster.depth_near, far = f->raster.depth_far;
    if (!f->perspective) return 1.0 / (far - n);
    double d = fmax(mc->depth_linear, n); /* z = f/(f-n) (1 - n/d): dz/dd = f n / ((f-n) d^2) */
    return far * n / ((far - n) * d * d);
}
