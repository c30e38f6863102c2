/* lightview.c -- projections of shadow-map faces and their fitting to a
 * target point set (course §3.2.1 "fitting": the map covers only what is
 * seen or what exists): the scene's bounds, the visible receivers, or the
 * intersection body B (lightbody.h); the warps of §3.2.2 on top (warp.h);
 * z-partitioning into cascades (§3.2.3.1), one face per slice; texel-snapped
 * stabilisation of uniform maps. Lookups are in lightview_lookup.c. */
#include "resources/views/lightview.h"
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include "resources/views/warp.h"

#define MAX_TAN_PERSPECTIVE 3.7320508 /* tan 75 degrees: a 150-degree frustum at most */
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

LightViewParams lightview_params_default(void)
{
    return (LightViewParams){.warp_n = 1.0, .falloff = WARP_FALLOFF_LLOYD, .tsm_focus = 0.5, .cascades = 1,
                             .split = SPLIT_PRACTICAL, .split_lambda = 0.5, .select = CASCADE_BY_DEPTH};
}

static bool is_warp(MapProjection p) { return p >= MAP_PROJ_PSM && p <= MAP_PROJ_LOGPSM; }
static bool is_body(MapFit f) { return f == MAP_FIT_BODY || f == MAP_FIT_BODY_VISIBLE; }

bool lightview_follows_camera(MapProjection projection, MapFit fit, const LightViewParams *p)
{
    return fit != MAP_FIT_SCENE && fit != MAP_FIT_NONE ? true : is_warp(projection) || (p && p->cascades > 1);
}

/* ---- splits (course §3.2.3.1) ---------------------------------------------- */

static double split_at(SplitScheme s, double lambda, int i, int m, double zn, double zf)
{
    double t = (double)i / m, lg = zn * pow(zf / zn, t), un = zn + (zf - zn) * t;
    if (s == SPLIT_LOG) return lg;          /* Lloyd et al. 2006 */
    if (s == SPLIT_UNIFORM) return un;
    return lambda * lg + (1.0 - lambda) * un; /* Zhang et al. 2006a, the practical split scheme */
}

/* The view depths the splits divide: z_n kept above 1e-9 z_f, since
 * C_i = z_n r^(i/m) divides by z_n. */
static void split_range(double *z_n, double *z_f)
{
    *z_f = fmax(*z_f, *z_n);
    *z_n = fmax(*z_n, 1e-9 * *z_f);
    if (!(*z_f > *z_n)) *z_f = *z_n * (1.0 + 1e-9) + 1e-300;
}

/* With a pseudo-near plane z_p (Lloyd 2007 §5.1.8) the first slice is
 * [z_n, z_p] and the scheme splits [z_p, z_f] into the other m - 1;
 * explicit distances are used as given. */
void lightview_splits(const LightViewParams *lp, int m, double z_n, double z_f, double *split)
{
    split_range(&z_n, &z_f);
    split[0] = z_n;
    split[m] = z_f;
    if (lp->split == SPLIT_EXPLICIT) {
        for (int i = 1; i < m; i++) split[i] = lp->split_at[i - 1];
        return;
    }
    int first = 0;
    double lo = z_n, pseudo_near = lp->pseudo_near;
    if (pseudo_near > z_n && pseudo_near < z_f && m >= 2) {
        split[1] = pseudo_near;
        first = 1;
        lo = pseudo_near;
    }
    for (int i = first + 1; i < m; i++)
        split[i] = split_at(lp->split, lp->split_lambda, i - first, m - first, lo, z_f);
}

bool lightview_check_splits(const LightViewParams *lp, int m, double z_n, double z_f, const char *far_what,
                            Error *err)
{
    const int n = LIGHTVIEW_EXPLICIT_SPLITS;
    if (lp->split != SPLIT_EXPLICIT) return true;
    if (m - 1 > n)
        return error_set(err, "cascades %d with split_scheme explicit: only split_1..split_%d can be given, so "
                              "cascades in [1, %d]", m, n, n + 1);
    for (int k = 0; k < n; k++) {
        bool used = k < m - 1;
        if (used && !(lp->split_at[k] > 0.0))
            return error_set(err, "cascades %d with split_scheme explicit takes split_1..split_%d; split_%d is not "
                                  "given (0)", m, m - 1, k + 1);
        if (!used && lp->split_at[k] != 0.0)
            return error_set(err, "split_%d = %g is given, but cascades %d with split_scheme explicit takes %d split "
                                  "distance(s): set cascades %d, or split_%d = 0", k + 1, lp->split_at[k], m, m - 1,
                             k + 2, k + 1);
    }
    split_range(&z_n, &z_f);
    for (int k = 0; k < m - 1; k++) {
        double c = lp->split_at[k], lo = k > 0 ? lp->split_at[k - 1] : z_n;
        if (!(c > lo && c < z_f))
            return error_set(err, "split_%d = %g outside (%g, %g): explicit split distances are view depths in world "
                                  "units, increasing, inside the view's (z_n, z_f) = (%g, %g) (z_f: %s)",
                             k + 1, c, lo, z_f, z_n, z_f, far_what);
    }
    return true;
}

/* ---- the target ------------------------------------------------------------- */

typedef struct Target {
    dvec3 *pts;      /* what the map must cover laterally */
    int n;
    dvec3 bounds[8]; /* the scene's box corners: everything that can cast */
    double extent;   /* scene diagonal */
    double z_min, z_max; /* view-depth range of the points (warps), within the camera's */
} Target;

static dvec3 bounds_centre(const Target *t) { return d3_scale(d3_add(t->bounds[0], t->bounds[7]), 0.5); }

static void box_corners(vec3 lo, vec3 hi, dvec3 *out)
{
    for (int k = 0; k < 8; k++) out[k] = d3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
}

static void target_depths(Target *t, const ViewFrustum *vf, double d0, double d1)
{
    t->z_min = INFINITY;
    t->z_max = -INFINITY;
    for (int i = 0; i < t->n; i++) {
        double d = view_depth(vf, t->pts[i]);
        t->z_min = fmin(t->z_min, d);
        t->z_max = fmax(t->z_max, d);
    }
    t->z_min = fmin(fmax(t->z_min, d0), d1);
    t->z_max = fmin(fmax(t->z_max, t->z_min), d1);
}

/* The scene's box corners as the points (no receiver in view, an empty body). */
static void target_bounds(Target *t)
{
    memcpy(t->pts, t->bounds, sizeof t->bounds);
    t->n = 8;
}

/* Points of the fit over the view-depth slice [d0, d1] (the whole frustum
 * when not partitioned): B's vertices, or the visible lit candidates. */
static bool target_init(const Scene *sc, const Light *light, MapFit fit, const ViewSamples *vs, const uint8_t *cls,
                        const ViewFrustum *vf, double d0, double d1, Target *t, Error *err)
{
    memset(t, 0, sizeof *t);
    box_corners(sc->bounds_min, sc->bounds_max, t->bounds);
    t->extent = scene_extent(sc);
    int n = 0;
    bool sliced = d0 > vf->near || d1 < vf->far;
    if (fit == MAP_FIT_VIEW && vs && cls)
        for (int s = 0; s < vs->count; s++)
            n += cls[s] == SAMPLE_LIT_CANDIDATE && (!sliced || (vs->depth_view[s] >= d0 && vs->depth_view[s] <= d1));
    size_t cap = (size_t)(n > BODY_MAX_POINTS ? n : BODY_MAX_POINTS);
    t->pts = malloc(sizeof *t->pts * cap);
    if (!t->pts) return error_set(err, "out of memory fitting the light's frustum");
    if (fit == MAP_FIT_VIEW && n > 0) {
        for (int s = 0; s < vs->count; s++)
            if (cls[s] == SAMPLE_LIT_CANDIDATE && (!sliced || (vs->depth_view[s] >= d0 && vs->depth_view[s] <= d1)))
                t->pts[t->n++] = d3_from(vs->p_world[s]);
    } else if (is_body(fit) || (fit == MAP_FIT_VIEW && sliced)) {
        BodyPlane cone[5];
        int nc = light->kind == LIGHT_SPOT ? spot_cone_planes(light, cone) : 0;
        t->n = body_points(vf, d0, d1, sc, cone, nc, t->pts, (int)cap);
    }
    if (t->n == 0) target_bounds(t);
    target_depths(t, vf, d0, d1);
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
    f->base_clip = f->raster.clip_from_world;
    f->base_inv = f->world_from_clip;
    f->base_half = 0.5 * fmax(f->r - f->l, f->t - f->b);
    f->warp_n = INFINITY;
    return true;
}

/* Perspective face from `eye` along `axis`, tangent extents [l, r] x [b, t]. */
static bool face_perspective(MapFace *f, dvec3 eye, dvec3 axis, dvec3 up, const double ext[4], double n, double far,
                             Error *err)
{
    memset(f, 0, sizeof *f);
    f->view_from_world = m4_look(eye, axis, up);
    f->axis_world = axis;
    f->perspective = f->base_perspective = true;
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

/* How a single face is oriented and shaped beyond its target. */
typedef struct FaceOpts {
    bool aligned;   /* the light view's y axis follows `up` (the view direction), not a world axis */
    dvec3 up;
    bool square;    /* equal extents (a warp's base: its plane stays isotropic) */
    bool stabilize; /* world-fixed orientation, texel-snapped on a ladder of sizes (unwarped faces) */
} FaceOpts;

static dvec3 face_up(const FaceOpts *o, dvec3 axis) { return o->aligned ? o->up : any_up(axis); }

/* ---- extents of point sets ---------------------------------------------------- */

/* Grow [lo, hi] by the margin, and to a minimum width. */
static void pad(double *lo, double *hi, int res, double min_width)
{
    double w = fmax(*hi - *lo, min_width), c = 0.5 * (*hi + *lo);
    w *= 1.0 + 2.0 * LIGHTVIEW_MARGIN_TEXELS / res;
    *lo = c - 0.5 * w;
    *hi = c + 0.5 * w;
}

static void make_square(double ext[4])
{
    double h = 0.5 * fmax(ext[1] - ext[0], ext[3] - ext[2]);
    double cx = 0.5 * (ext[0] + ext[1]), cy = 0.5 * (ext[2] + ext[3]);
    ext[0] = cx - h; ext[1] = cx + h; ext[2] = cy - h; ext[3] = cy + h;
}

/* Course §3.2.1: a constant orientation (the light view's axes are world-
 * fixed, face_up) and texel-sized steps: the width is rounded up to a
 * ladder 2^(k/4) of `unit` and the window's corner snapped to whole texels,
 * so the texel grid stays put in world space while the body moves (it only
 * jumps when the body outgrows a rung). Ortho windows are in world units
 * (unit: the scene's extent); perspective ones in tangents at unit depth
 * (unit 1), where a fixed window is a fixed bundle of rays from the light. */
static void stabilize_extents(double ext[4], int res, double unit)
{
    double need = fmax(ext[1] - ext[0], ext[3] - ext[2]);
    double k = ceil(4.0 * log2(fmax(need, 1e-300) / unit)), size = unit * exp2(k / 4.0);
    while (size < need + 2.0 * (LIGHTVIEW_MARGIN_TEXELS + 1.0) * size / res) size *= exp2(0.25);
    double texel = size / res;
    for (int a = 0; a < 2; a++) {
        double c = 0.5 * (ext[2 * a] + ext[2 * a + 1]);
        ext[2 * a] = floor((c - 0.5 * size) / texel) * texel;
        ext[2 * a + 1] = ext[2 * a] + size;
    }
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

static bool fit_perspective(MapFace *f, int res, const Light *light, MapFit fit, const Target *tg, const FaceOpts *o,
                            Error *err)
{
    dvec3 eye = d3_from(light->position), axis;
    double max_tan = MAX_TAN_PERSPECTIVE;
    if (light->kind == LIGHT_SPOT) {
        axis = d3_from(light->direction);
        max_tan = fmin(max_tan, tan(light->cone_half_rad));
    } else if (light->kind == LIGHT_RECT || light->kind == LIGHT_DISK || light->kind == LIGHT_TEXTURED_RECT) {
        axis = d3_from(light->direction);
    } else { /* point, sphere: toward the target, or the scene's centre when the orientation must stay fixed */
        dvec3 aim = o->stabilize ? bounds_centre(tg) : centroid(tg->pts, tg->n);
        axis = d3_normalize_or(d3_sub(aim, eye), d3(0, -1, 0));
    }
    dvec3 up = face_up(o, axis);
    mat4 view = m4_look(eye, axis, up);
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
    if (o->stabilize) {
        stabilize_extents(ext, res, 1.0);
    } else {
        pad(&ext[0], &ext[1], res, 1e-6);
        pad(&ext[2], &ext[3], res, 1e-6);
    }
    if (o->square) make_square(ext);
    return face_perspective(f, eye, axis, up, ext, near_plane(&view, tg->bounds, far), far, err);
}

static bool fit_ortho(MapFace *f, int res, const Light *light, MapFit fit, const Target *tg, const FaceOpts *o,
                      Error *err)
{
    dvec3 axis = d3_from(light->direction);
    dvec3 centre = bounds_centre(tg);
    double radius = 0.5 * d3_len(d3_sub(tg->bounds[7], tg->bounds[0]));
    dvec3 eye = d3_madd(centre, axis, -2.0 * fmax(radius, 1e-30)); /* outside the scene, looking in */
    dvec3 up = face_up(o, axis);
    mat4 view = m4_look(eye, axis, up);
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
    if (o->stabilize) {
        stabilize_extents(ext, res, tg->extent);
    } else {
        pad(&ext[0], &ext[1], res, 1e-6 * tg->extent);
        pad(&ext[2], &ext[3], res, 1e-6 * tg->extent);
    }
    if (o->square) make_square(ext);
    return face_ortho(f, eye, axis, up, ext, fmax(near - depth_pad, 0.0), far + depth_pad, err);
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

/* ---- one face: base projection, then the warp ------------------------------------ */

typedef struct FitJob {
    const Scene *scene;
    const Light *light;
    MapProjection projection; /* asked for (AUTO resolved per target) */
    MapFit fit;
    const LightViewParams *params;
    const ViewFrustum *view;
} FitJob;

/* Face `index` with the job's projection (or `proj`, when not AUTO), its
 * warp along the view axis (or along axis[0] -> axis[1] when given). */
static bool fit_face_along(LightView *lv, int index, const FitJob *j, const Target *tg, MapProjection proj,
                           const dvec3 *axis, Error *err)
{
    bool directional = j->light->kind == LIGHT_DIRECTIONAL;
    MapProjection projection = proj != MAP_PROJ_AUTO ? proj : j->projection;
    bool warp = is_warp(projection);
    /* stabilisation holds the unwarped faces still (ortho and perspective); a warp follows the view */
    bool stable = j->params->stabilize && !warp;
    FaceOpts o = {.aligned = !stable && (warp || is_body(j->fit) || j->params->cascades > 1),
                  .up = j->view->fwd, .square = warp, .stabilize = stable};
    MapFace *f = &lv->face[index];
    bool parted = j->params->cascades > 1 || j->params->split == SPLIT_FACES;
    MapFit fit = parted && j->fit != MAP_FIT_VIEW ? MAP_FIT_BODY : j->fit; /* a slice or face covers its target */
    bool ok = directional ? fit_ortho(f, lv->res, j->light, fit, tg, &o, err)
                          : fit_perspective(f, lv->res, j->light, fit, tg, &o, err);
    if (!ok || !warp) return ok;
    WarpSetup w = {.kind = projection, .params = j->params, .view = j->view, .directional = directional,
                   .light_axis = directional ? d3_normalize_or(d3_from(j->light->direction), d3(0, -1, 0))
                                             : f->axis_world,
                   .light_pos = d3_from(j->light->position), .pts = tg->pts, .n = tg->n,
                   .z_min = tg->z_min, .z_max = tg->z_max, .has_axis = axis != NULL};
    if (axis) {
        w.axis_from = axis[0];
        w.axis_to = axis[1];
    }
    return warp_face(f, lv->res, &w, err);
}

static bool fit_face(LightView *lv, int index, const FitJob *j, const Target *tg, Error *err)
{
    return fit_face_along(lv, index, j, tg, MAP_PROJ_AUTO, NULL, err);
}

/* ---- frustum-face partitioning (course §3.2.3.2; Lloyd et al. 2006) -------------- */

/* Whether the light reaches the frustum through this face from outside. */
static bool face_lit(const Light *light, const FrustumFace *ff, dvec3 on_face)
{
    if (light->kind == LIGHT_DIRECTIONAL) return d3_dot(ff->n, d3_from(light->direction)) < -1e-9;
    return d3_dot(ff->n, d3_sub(d3_from(light->position), on_face)) > 1e-9 * d3_len(d3_sub(d3_from(light->position), on_face));
}

/* One map per light-facing face, fitted to the part of B whose rays toward
 * the light leave the frustum through that face (B clipped by the planes
 * through the face's edges along the rays): the side faces warped along the
 * face, from its near edge to its far edge, the near and far faces (each at
 * one view depth) uniform. A point uses the face its ray leaves through. */
static bool fit_face_partition(LightView *lv, const FitJob *j, Error *err)
{
    bool point = j->light->kind != LIGHT_DIRECTIONAL;
    dvec3 light = point ? d3_from(j->light->position) : d3_from(j->light->direction);
    int k = 0;
    for (int face = 0; face < FRUSTUM_FACES; face++) {
        FrustumFace ff = frustum_face(j->view, face);
        const double inward[4] = {-ff.n.x, -ff.n.y, -ff.n.z, -ff.d};
        memcpy(lv->face_plane[face], inward, sizeof inward);
        lv->face_of_plane[face] = -1;
        if (!face_lit(j->light, &ff, ff.near_mid)) continue;
        Target tg;
        if (!target_init(j->scene, j->light, MAP_FIT_SCENE, NULL, NULL, j->view, j->view->near, j->view->far, &tg, err))
            return false;
        BodyPlane planes[9];
        int np = frustum_face_prism(&ff, point, light, planes);
        if (j->light->kind == LIGHT_SPOT) np += spot_cone_planes(j->light, planes + np);
        int n = body_points(j->view, j->view->near, j->view->far, j->scene, planes, np, tg.pts, BODY_MAX_POINTS);
        bool ok = true;
        if (n > 0) { /* else no visible point's ray leaves through this face */
            tg.n = n;
            target_depths(&tg, j->view, j->view->near, j->view->far);
            bool side = face >= FRUSTUM_BOTTOM;
            MapProjection flat = point ? MAP_PROJ_PERSPECTIVE : MAP_PROJ_ORTHO;
            const dvec3 axis[2] = {ff.near_mid, ff.far_mid};
            ok = fit_face_along(lv, k, j, &tg, side ? MAP_PROJ_AUTO : flat, side ? axis : NULL, err);
            lv->face_of_plane[face] = k++;
        }
        free(tg.pts);
        if (!ok) return false;
    }
    lv->num_faces = k;
    lv->face_partition = k > 0;
    lv->num_face_planes = FRUSTUM_FACES;
    return true;
}

/* ---- refusals -------------------------------------------------------------------- */

static bool check_request(const Light *light, MapProjection p, int res, const LightViewParams *lp, Error *err)
{
    if (res < 1 || res > RASTER_MAX_SIZE) return error_set(err, "map_size %d outside [1, %d]", res, RASTER_MAX_SIZE);
    bool directional = light->kind == LIGHT_DIRECTIONAL;
    if (directional && p != MAP_PROJ_AUTO && p != MAP_PROJ_ORTHO && !is_warp(p))
        return error_set(err, "projection %s needs a light with a position; a directional light takes ortho or a "
                              "warp (psm, lispsm, tsm, logpsm)", map_projection_name(p));
    if (!directional && p == MAP_PROJ_ORTHO)
        return error_set(err, "projection ortho is for directional lights; a %s light takes perspective, cube or "
                              "paraboloid", light_kind_name(light->kind));
    int m = lp->cascades > 0 ? lp->cascades : 1;
    if (m > LIGHTVIEW_MAX_CASCADES) return error_set(err, "cascades %d outside [1, %d]", m, LIGHTVIEW_MAX_CASCADES);
    if ((m > 1 || lp->split == SPLIT_FACES) && (p == MAP_PROJ_CUBE || p == MAP_PROJ_PARABOLOID))
        return error_set(err, "cascades need a single-face projection per slice, not %s", map_projection_name(p));
    if (!(lp->blend >= 0.0 && lp->blend <= 0.5)) return error_set(err, "cascade_blend %g outside [0, 0.5]", lp->blend);
    return true;
}

/* ---- the light view --------------------------------------------------------------- */

/* The farthest visible sample's view depth (course §3.2.1: a far plane
 * from visibility; exact here, the depths are in memory). */
static double visible_far(const ViewSamples *vs, double near, double far)
{
    double d = 0.0;
    for (int s = 0; vs && s < vs->count; s++)
        if (vs->object[s] >= 0) d = fmax(d, vs->depth_view[s]);
    return d > near ? fmin(d * (1.0 + 1e-6), far) : far; /* nothing visible: the camera's far plane */
}

/* Each slice is fitted to its own intersection body B_i (its visible samples
 * with fit=view): a partition follows the view whatever the fit asked for. */
static bool fit_cascades(LightView *lv, const FitJob *j, const ViewSamples *vs, const uint8_t *cls, double z_n,
                         double z_f, Error *err)
{
    const LightViewParams *lp = j->params;
    MapFit fit = j->fit == MAP_FIT_VIEW ? MAP_FIT_VIEW : MAP_FIT_BODY;
    int m = lp->cascades > 1 ? lp->cascades : 1;
    lightview_splits(lp, m, z_n, z_f, lv->split);
    lv->num_cascades = m;
    lv->num_faces = m;
    lv->view_eye = j->view->eye;
    lv->view_fwd = j->view->fwd;
    lv->select = lp->select;
    lv->blend = lp->blend;
    for (int i = 0; i < m; i++) {
        Target tg;
        if (!target_init(j->scene, j->light, fit, vs, cls, j->view, lv->split[i], lv->split[i + 1], &tg, err))
            return false;
        bool ok = fit_face(lv, i, j, &tg, err);
        free(tg.pts);
        if (!ok) return false;
    }
    return true;
}

bool lightview_fit_with(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                        const LightViewParams *params, const ViewSamples *vs, const uint8_t *cls, LightView *lv,
                        Error *err)
{
    memset(lv, 0, sizeof *lv);
    LightViewParams lp = params ? *params : lightview_params_default();
    if (!check_request(light, projection, res, &lp, err)) return false;
    ViewFrustum vf = view_frustum(&scene->camera);
    double z_f = fit == MAP_FIT_BODY_VISIBLE ? visible_far(vs, vf.near, vf.far) : vf.far;
    vf.far = z_f;
    const char *far_what = fit == MAP_FIT_BODY_VISIBLE ? "the farthest visible sample, fit=body_visible"
                                                       : "the camera's far plane";
    int m = lp.cascades > 1 ? lp.cascades : 1;
    if (lp.split != SPLIT_FACES && !lightview_check_splits(&lp, m, vf.near, z_f, far_what, err)) return false;
    lv->res = res;
    lv->origin_world = d3_from(light->position);
    lv->light_dir = d3_normalize_or(d3_from(light->direction), d3(0, -1, 0));
    lv->directional = light->kind == LIGHT_DIRECTIONAL;
    Target tg;
    if (!target_init(scene, light, fit, vs, cls, &vf, vf.near, vf.far, &tg, err)) return false;
    lv->projection = projection == MAP_PROJ_AUTO ? resolve_auto(light, &tg) : projection;
    if ((lp.cascades > 1 || lp.split == SPLIT_FACES) && lv->projection == MAP_PROJ_CUBE)
        lv->projection = MAP_PROJ_PERSPECTIVE; /* AUTO: each slice or face gets a single perspective face */
    FitJob j = {scene, light, lv->projection, fit, &lp, &vf};
    bool ok = true, done = false;
    if (lp.split == SPLIT_FACES) { /* no light-facing face (a point light inside the frustum): one map */
        ok = fit_face_partition(lv, &j, err);
        done = !ok || lv->num_faces > 0;
    }
    if (done) {
    } else if (lp.cascades > 1) {
        ok = fit_cascades(lv, &j, vs, cls, vf.near, vf.far, err);
    } else if (lv->projection == MAP_PROJ_CUBE) {
        ok = fit_cube(lv, light, &tg, err);
    } else if (lv->projection == MAP_PROJ_PARABOLOID) {
        ok = fit_paraboloid(lv, light, &tg);
    } else {
        lv->num_faces = 1;
        ok = fit_face(lv, 0, &j, &tg, err);
    }
    free(tg.pts);
    return ok;
}

bool lightview_fit(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                   const ViewSamples *vs, const uint8_t *cls, LightView *lv, Error *err)
{
    LightViewParams lp = lightview_params_default();
    return lightview_fit_with(scene, light, projection, fit, res, &lp, vs, cls, lv, err);
}
