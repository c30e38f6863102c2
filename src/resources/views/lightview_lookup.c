/* lightview_lookup.c -- world -> map lookups of lightview.h: which face a
 * point uses (cube and paraboloid faces by direction, cascades by view
 * depth or by projection, course §3.2.3.1), its texel coordinates through
 * the face's projection or warp, the ray through a texel, a texel's world
 * size and the NDC depth slope (for biases). */
#include "resources/views/lightview.h"
#include <string.h>
#include "core/hash.h"
#include "resources/views/warp.h"

#define SELECT_MARGIN_TEXELS 8.0 /* selection by projection: a filter's footprint stays inside the map */

bool lightview_base_ndc(const MapFace *f, dvec3 p, double *x_b, double *y_b, double *z_ndc)
{
    dvec4 c = m4_apply(&f->base_clip, p);
    if (!(c.w > 0.0)) return false;
    *x_b = c.x / c.w;
    *y_b = c.y / c.w;
    *z_ndc = c.z / c.w;
    return isfinite(*x_b) && isfinite(*y_b);
}

/* A point's position in [0, 1) from its coordinates' bits: the dither of
 * cascade blending is a fixed pattern in world space, not noise per run. */
static double dither(dvec3 p)
{
    float v[3] = {(float)p.x, (float)p.y, (float)p.z};
    uint32_t b[3];
    memcpy(b, v, sizeof b);
    return (hash_u32(b[0] ^ hash_u32(b[1] ^ hash_u32(b[2]))) >> 8) / 16777216.0;
}

static int cascade_by_depth(const LightView *lv, dvec3 p)
{
    double d = d3_dot(d3_sub(p, lv->view_eye), lv->view_fwd);
    int m = lv->num_cascades, i = 0;
    while (i < m - 1 && d >= lv->split[i + 1]) i++;
    if (lv->blend > 0.0 && i < m - 1) { /* the far end of slice i fades into slice i + 1 */
        double band = lv->blend * (lv->split[i + 1] - lv->split[i]), t = (d - (lv->split[i + 1] - band)) / band;
        if (t > 0.0 && dither(p) < t) i++;
    }
    return i;
}

static int cascade_by_projection(const LightView *lv, dvec3 p)
{
    double lo = SELECT_MARGIN_TEXELS, hi = lv->res - SELECT_MARGIN_TEXELS;
    for (int i = 0; i < lv->num_cascades; i++) {
        MapCoord mc = lightview_locate_on(lv, i, p);
        if (mc.inside && mc.s >= lo && mc.s <= hi && mc.t >= lo && mc.t <= hi) return i;
    }
    return cascade_by_depth(lv, p);
}

/* Frustum-face partitions: the light-facing face the point's ray toward the
 * light leaves the frustum through (the nearest such plane along the ray). */
static int face_by_exit(const LightView *lv, dvec3 p)
{
    dvec3 dir = lv->directional ? d3_scale(lv->light_dir, -1)
                                : d3_normalize_or(d3_sub(lv->origin_world, p), d3_scale(lv->light_dir, -1));
    int best = 0;
    double t_best = INFINITY;
    for (int k = 0; k < lv->num_face_planes; k++) {
        const double *pl = lv->face_plane[k];
        double rate = pl[0] * dir.x + pl[1] * dir.y + pl[2] * dir.z; /* < 0: moving outward */
        if (lv->face_of_plane[k] < 0 || !(rate < 0.0)) continue;
        double t = (pl[0] * p.x + pl[1] * p.y + pl[2] * p.z + pl[3]) / -rate;
        if (t < t_best) {
            t_best = t;
            best = lv->face_of_plane[k];
        }
    }
    return best;
}

static int choose_face(const LightView *lv, dvec3 p)
{
    if (lv->face_partition) return face_by_exit(lv, p);
    if (lv->num_cascades > 1)
        return lv->select == CASCADE_BY_PROJECTION ? cascade_by_projection(lv, p) : cascade_by_depth(lv, p);
    dvec3 d = d3_sub(p, lv->origin_world);
    if (lv->projection == MAP_PROJ_PARABOLOID) return d3_dot(d, lv->cube_axes[0]) >= 0.0 ? 0 : 1;
    if (lv->projection != MAP_PROJ_CUBE) return 0;
    double ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
    if (ax >= ay && ax >= az) return d.x >= 0.0 ? 0 : 1;
    if (ay >= az) return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

static double depth_of(const MapFace *f, dvec3 p)
{
    const double *row = f->raster.depth_row;
    return row[0] * p.x + row[1] * p.y + row[2] * p.z + row[3];
}

MapCoord lightview_locate_on(const LightView *lv, int face, dvec3 p)
{
    const MapFace *f = &lv->face[face];
    MapCoord mc = {.face = face, .warp_w = 1.0};
    double xn, yn;
    if (f->paraboloid) {
        dvec4 v = m4_apply(&f->view_from_world, p);
        double r;
        paraboloid_ndc(d3(v.x, v.y, v.z), &xn, &yn, &r);
        mc.depth_linear = r;
        double range = f->raster.depth_far - f->raster.depth_near;
        mc.z_ndc = (r - f->raster.depth_near) / range;
        mc.inside = v.z <= 0.0;
    } else if (f->warp == MAP_WARP_LOG) {
        double xb, yb;
        mc.depth_linear = depth_of(f, p);
        if (!lightview_base_ndc(f, p, &xb, &yb, &mc.z_ndc)) return mc;
        warp_log_forward(&f->log, xb, yb, &xn, &yn);
        mc.inside = isfinite(xn) && isfinite(yn);
    } else {
        dvec4 c = m4_apply(&f->raster.clip_from_world, p);
        mc.depth_linear = depth_of(f, p);
        if (!(c.w > 0.0)) return mc; /* behind a perspective face's eye, or a warp's vanishing line */
        xn = c.x / c.w;
        yn = c.y / c.w;
        mc.z_ndc = c.z / c.w;
        mc.inside = true;
        if (f->warp == MAP_WARP_HOMOGRAPHY) { /* the clip z is the base's times w_min / w: undo it */
            mc.warp_w = c.w / (f->base_perspective ? mc.depth_linear : 1.0);
            mc.z_ndc *= mc.warp_w / f->w_min;
        }
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

/* Base NDC of map texel coordinates on a warped face. */
static void warped_to_base(const MapFace *f, double u, double v, double *xb, double *yb)
{
    if (f->warp == MAP_WARP_LOG) {
        warp_log_inverse(&f->log, u, v, xb, yb);
        return;
    }
    const double(*H)[3] = f->H_inv;
    double w = H[2][0] * u + H[2][1] * v + H[2][2];
    *xb = (H[0][0] * u + H[0][1] * v + H[0][2]) / w;
    *yb = (H[1][0] * u + H[1][1] * v + H[1][2]) / w;
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
    if (f->warp == MAP_WARP_LOG) warped_to_base(f, xn, yn, &xn, &yn); /* world_from_clip is the base's */
    dvec4 a = m4_apply4(&f->world_from_clip, (dvec4){xn, yn, 0.0, 1.0});
    dvec4 b = m4_apply4(&f->world_from_clip, (dvec4){xn, yn, 1.0, 1.0});
    *org = d3(a.x / a.w, a.y / a.w, a.z / a.w);
    *dir = d3_normalize_or(d3_sub(d3(b.x / b.w, b.y / b.w, b.z / b.w), *org), f->axis_world);
}

/* d(u, v) / d(x_b, y_b) at a warped face's texel coordinates, by central
 * differences of the forward map (exact to rounding for homographies). */
static void warp_jacobian(const MapFace *f, double xb, double yb, double J[2][2])
{
    double h = 1e-6;
    for (int k = 0; k < 2; k++) {
        double u0, v0, u1, v1, dx = k == 0 ? h : 0.0, dy = k == 1 ? h : 0.0;
        if (f->warp == MAP_WARP_LOG) {
            warp_log_forward(&f->log, xb - dx, yb - dy, &u0, &v0);
            warp_log_forward(&f->log, xb + dx, yb + dy, &u1, &v1);
        } else if (!warp_apply(f->H, xb - dx, yb - dy, &u0, &v0) || !warp_apply(f->H, xb + dx, yb + dy, &u1, &v1)) {
            u0 = v0 = u1 = v1 = 0.0;
        }
        J[0][k] = (u1 - u0) / (2.0 * h);
        J[1][k] = (v1 - v0) / (2.0 * h);
    }
}

/* World size of a texel on a warped face: the longer of the world steps
 * (perpendicular to the light's ray) that one texel along s or t takes. */
static double warped_texel_world(const LightView *lv, const MapFace *f, const MapCoord *mc)
{
    double u = 2.0 * mc->s / lv->res - 1.0, v = 2.0 * mc->t / lv->res - 1.0, xb, yb, J[2][2];
    warped_to_base(f, u, v, &xb, &yb);
    warp_jacobian(f, xb, yb, J);
    double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return INFINITY;
    /* columns of J^-1: base NDC per unit of u and of v */
    double cu = hypot(J[1][1], J[1][0]) / fabs(det), cv = hypot(J[0][1], J[0][0]) / fabs(det);
    double world_per_base = f->base_half * (f->base_perspective ? mc->depth_linear : 1.0);
    return fmax(cu, cv) * (2.0 / lv->res) * world_per_base;
}

double lightview_texel_world(const LightView *lv, const MapCoord *mc)
{
    const MapFace *f = &lv->face[mc->face];
    if (f->warp != MAP_WARP_NONE) return warped_texel_world(lv, f, mc);
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
    if (!f->perspective && !f->base_perspective) return 1.0 / (far - n); /* warped faces keep the base's z_ndc */
    double d = fmax(mc->depth_linear, n); /* z = f/(f-n) (1 - n/d): dz/dd = f n / ((f-n) d^2) */
    return far * n / ((far - n) * d * d);
}
