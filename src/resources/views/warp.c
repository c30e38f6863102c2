/* warp.c -- perspective (PSM, LiSPSM, TSM) and logarithmic warps of a
 * face's base projection (warp.h; course §3.2.2). All work happens in the
 * base's NDC plane q = (x_b, y_b): the warp frame is x' = q.b, y' = q.a with
 * a the view direction's image, and the warp's body extent along a is
 * [y_min, y_min + D]. */
#include "resources/views/warp.h"
#include <stdlib.h>
#include <string.h>

#define N_UNIFORM 1e6       /* n beyond this many D is the uniform map (relative change < 1e-6) */
#define TSM_XI 0.6          /* Martin & Tan 2004: the focus point maps to the 80% line */

/* ---- 3x3 homographies ---------------------------------------------------------- */

static void h_mul(const double A[3][3], const double B[3][3], double C[3][3])
{
    double T[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) T[i][j] = A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j];
    memcpy(C, T, sizeof T);
}

static bool h_invert(const double M[3][3], double I[3][3])
{
    double c00 = M[1][1] * M[2][2] - M[1][2] * M[2][1], c01 = M[1][2] * M[2][0] - M[1][0] * M[2][2],
           c02 = M[1][0] * M[2][1] - M[1][1] * M[2][0];
    double det = M[0][0] * c00 + M[0][1] * c01 + M[0][2] * c02, scale = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) scale = fmax(scale, fabs(M[i][j]));
    if (!(fabs(det) > 1e-300 * scale * scale * scale) || !isfinite(det)) return false;
    double k = 1.0 / det;
    I[0][0] = c00 * k; I[0][1] = (M[0][2] * M[2][1] - M[0][1] * M[2][2]) * k; I[0][2] = (M[0][1] * M[1][2] - M[0][2] * M[1][1]) * k;
    I[1][0] = c01 * k; I[1][1] = (M[0][0] * M[2][2] - M[0][2] * M[2][0]) * k; I[1][2] = (M[0][2] * M[1][0] - M[0][0] * M[1][2]) * k;
    I[2][0] = c02 * k; I[2][1] = (M[0][1] * M[2][0] - M[0][0] * M[2][1]) * k; I[2][2] = (M[0][0] * M[1][1] - M[0][1] * M[1][0]) * k;
    return true;
}

bool warp_apply(const double H[3][3], double x, double y, double *u, double *v)
{
    double w = H[2][0] * x + H[2][1] * y + H[2][2];
    if (!(w > 0.0)) return false;
    *u = (H[0][0] * x + H[0][1] * y + H[0][2]) / w;
    *v = (H[1][0] * x + H[1][1] * y + H[1][2]) / w;
    return isfinite(*u) && isfinite(*v);
}

static double h_w(const double H[3][3], double x, double y) { return H[2][0] * x + H[2][1] * y + H[2][2]; }

/* ---- n: Lloyd's eta, Wimmer's n_opt and falloff, TSM's 80% rule ------------------ */

double warp_n_over_d(double eta, double alpha)
{
    if (!(alpha > 1.0 + 1e-12) || !(eta > -1.0)) return INFINITY; /* no depth range to warp, or uniform */
    double r = sqrt(alpha);
    if (eta < 0.0) return (1.0 + r - eta * (alpha - 1.0)) / ((alpha - 1.0) * (eta + 1.0));
    return 1.0 / ((r - 1.0) * (eta * r + 1.0));
}

/* The printed form (thesis §5.2.1) starts the ramp with 1 + cos and eta = 0
 * below gamma_a, which is discontinuous there; with 1 - cos and eta = -1
 * below gamma_a the ramp runs continuously from uniform to eta_b, as the
 * text describes (no warp while the light is within theta/3 of the view
 * axis, then the warp returns, fully by gamma_c). */
double warp_eta_lloyd(double gamma, double theta)
{
    const double eta_b = -0.2, eta_c = 0.0;
    double ga = theta / 3.0, gb = theta, gc = theta + 0.3 * (0.5 * M_PI - theta);
    if (gamma < ga) return -1.0;
    if (gamma < gb) return -1.0 + (eta_b + 1.0) * (1.0 - cos(0.5 * M_PI * (gamma - ga) / (gb - ga)));
    if (gamma < gc) return eta_b + (eta_c - eta_b) * sin(0.5 * M_PI * (gamma - gb) / (gc - gb));
    return eta_c;
}

/* The falloff's n over n_opt (>= 1; infinite: uniform). */
static double falloff_factor(WarpFalloff f, double gamma, double theta, double alpha)
{
    double n_opt = warp_n_over_d(0.0, alpha);
    if (f == WARP_FALLOFF_NONE || !isfinite(n_opt)) return 1.0;
    if (f == WARP_FALLOFF_SIN_GAMMA) return sin(gamma) > 1e-12 ? 1.0 / sin(gamma) : INFINITY; /* Wimmer 2004 */
    return warp_n_over_d(warp_eta_lloyd(gamma, theta), alpha) / n_opt;
}

/* ---- the warp frame ---------------------------------------------------------------- */

typedef struct Frame {
    double a[2], b[2];          /* warp axis (the view direction's image) and across, unit, in base NDC */
    double y_min, y_max, x_min, x_max;
    double x_c;                 /* the eye's lateral position (the warp centre's) */
    double z0, z1;              /* view depths at the near and far ends of the body along a */
    double world_per_ndc;       /* world units per base NDC unit at the body's near end */
    double gamma;
    bool axis_ok;
} Frame;

static void base_ray(const MapFace *f, double x, double y, dvec3 *org, dvec3 *dir)
{
    dvec4 a = m4_apply4(&f->base_inv, (dvec4){x, y, 0.0, 1.0}), b = m4_apply4(&f->base_inv, (dvec4){x, y, 1.0, 1.0});
    *org = d3(a.x / a.w, a.y / a.w, a.z / a.w);
    *dir = d3_normalize_or(d3_sub(d3(b.x / b.w, b.y / b.w, b.z / b.w), *org), f->axis_world);
}

static dvec3 base_unproject(const MapFace *f, double x, double y, double z)
{
    dvec4 a = m4_apply4(&f->base_inv, (dvec4){x, y, z, 1.0});
    return d3(a.x / a.w, a.y / a.w, a.z / a.w);
}

static void frame_axis(const MapFace *f, const WarpSetup *w, Frame *fr)
{
    double xa, ya, za, xb, yb, zb;
    dvec3 pa = d3_madd(w->view->eye, w->view->fwd, w->z_min), pb = d3_madd(w->view->eye, w->view->fwd, w->z_max);
    if (w->has_axis) {
        pa = w->axis_from;
        pb = w->axis_to;
    }
    dvec3 dir = d3_normalize_or(d3_sub(pb, pa), w->view->fwd);
    fr->gamma = asin(fmin(1.0, d3_len(d3_cross(dir, w->light_axis))));
    fr->axis_ok = false;
    fr->a[0] = 0.0; fr->a[1] = 1.0;
    if (lightview_base_ndc(f, pa, &xa, &ya, &za) && lightview_base_ndc(f, pb, &xb, &yb, &zb)) {
        double dx = xb - xa, dy = yb - ya, len = sqrt(dx * dx + dy * dy);
        if (len > 1e-9 && isfinite(len)) { /* base NDC spans [-1, 1]: an image under 1e-9 is no direction */
            fr->a[0] = dx / len;
            fr->a[1] = dy / len;
            fr->axis_ok = true;
        }
    }
    fr->b[0] = fr->a[1];
    fr->b[1] = -fr->a[0];
}

/* Lloyd 2007 §5.1.2.2 (as reproduced by open implementations of it): the
 * body's near end along a is p0, the point on the light ray through
 * (x_c, y_min) at the body's nearest view depth; p1 is p0 moved along a to
 * y_max at the same light depth; z_0, z_1 are their view depths, clamped to
 * the body's range. When the light is perpendicular to the view, z_0 = z_n
 * and z_1 = z_f and n_opt = z_n + sqrt(z_n z_f) (Wimmer 2004). */
static void frame_depths(const MapFace *f, const WarpSetup *w, Frame *fr)
{
    double qx = fr->x_c * fr->b[0] + fr->y_min * fr->a[0], qy = fr->x_c * fr->b[1] + fr->y_min * fr->a[1];
    dvec3 org, dir;
    base_ray(f, qx, qy, &org, &dir);
    double along = d3_dot(dir, w->view->fwd), t = 0.0;
    if (fabs(along) > 1e-9) t = (w->z_min - view_depth(w->view, org)) / along;
    dvec3 p0 = d3_madd(org, dir, t);
    double x0, y0, z0n;
    if (!lightview_base_ndc(f, p0, &x0, &y0, &z0n)) z0n = 0.5;
    double D = fr->y_max - fr->y_min;
    dvec3 p1 = base_unproject(f, qx + D * fr->a[0], qy + D * fr->a[1], z0n);
    if (w->has_axis) { /* a frustum face: its own near and far edges (the light may look along the view) */
        p0 = w->axis_from;
        p1 = w->axis_to;
    }
    /* The base is square: an ortho NDC unit is base_half world units anywhere, a perspective one
     * base_half tangents, i.e. base_half x the light depth world units there (at least the near plane's). */
    double light_depth = -m4_apply(&f->view_from_world, p0).z;
    fr->world_per_ndc = f->base_half * (f->base_perspective ? fmax(light_depth, f->raster.depth_near) : 1.0);
    fr->z0 = fmin(fmax(view_depth(w->view, p0), w->z_min), w->z_max);
    fr->z1 = fmin(fmax(view_depth(w->view, p1), w->z_min), w->z_max);
    if (!isfinite(fr->z0)) fr->z0 = w->z_min;
    if (!isfinite(fr->z1)) fr->z1 = w->z_max;
    if (fr->z1 < fr->z0) { double s = fr->z0; fr->z0 = fr->z1; fr->z1 = s; } /* looking back along a */
    double pn = w->params->pseudo_near;
    if (pn > 0.0) fr->z0 = fmax(fr->z0, fmin(pn, fr->z1)); /* Lloyd 2007 §5.1.9: n as if z_n were the pseudo-near */
    fr->z0 = fmax(fr->z0, 1e-300);
}

static bool frame_fit(const MapFace *f, const WarpSetup *w, double (*q)[2], int *nq, Frame *fr)
{
    frame_axis(f, w, fr);
    fr->x_min = fr->y_min = INFINITY;
    fr->x_max = fr->y_max = -INFINITY;
    *nq = 0;
    for (int i = 0; i < w->n; i++) {
        double x, y, z;
        if (!lightview_base_ndc(f, w->pts[i], &x, &y, &z)) continue;
        q[*nq][0] = x;
        q[*nq][1] = y;
        double xp = x * fr->b[0] + y * fr->b[1], yp = x * fr->a[0] + y * fr->a[1];
        fr->x_min = fmin(fr->x_min, xp); fr->x_max = fmax(fr->x_max, xp);
        fr->y_min = fmin(fr->y_min, yp); fr->y_max = fmax(fr->y_max, yp);
        (*nq)++;
    }
    if (*nq == 0) return false;
    double xe, ye, ze;
    fr->x_c = 0.5 * (fr->x_min + fr->x_max);
    if (lightview_base_ndc(f, w->view->eye, &xe, &ye, &ze)) fr->x_c = xe * fr->b[0] + ye * fr->b[1];
    frame_depths(f, w, fr);
    return true;
}

/* TSM (Martin & Tan 2004, §4-5): the trapezoid's top and base lines are the
 * body's near and far ends along the centre line (= a), lambda = D apart;
 * the focus point (delta' from the top) maps to the 80% line when the
 * projection centre lies eta = lambda delta' (1 - xi) / (lambda (1 + xi) -
 * 2 delta') behind the top line (xi = 0.6 in our orientation, top at -1;
 * the paper's xi = -0.6 with the top at +1). That centre is LiSPSM's with
 * n = eta (course §3.2.2.1: "a different choice for n"). */
static double tsm_n(const MapFace *f, const WarpSetup *w, const Frame *fr)
{
    double frac = w->params->tsm_focus > 0.0 ? w->params->tsm_focus : 0.5;
    dvec3 p = d3_madd(w->view->eye, w->view->fwd, w->z_min + frac * (w->z_max - w->z_min));
    double x, y, z, D = fr->y_max - fr->y_min;
    if (!lightview_base_ndc(f, p, &x, &y, &z)) return INFINITY;
    double delta = fmin(fmax(x * fr->a[0] + y * fr->a[1] - fr->y_min, 1e-6 * D), D);
    double den = D * (1.0 + TSM_XI) - 2.0 * delta;
    return den > 1e-12 * D ? D * delta * (1.0 - TSM_XI) / den : INFINITY; /* focus past 80%: uniform does it */
}

/* n (base NDC units, INFINITY = uniform) for the perspective warps: the
 * falloff's n times warp_n, TSM's from its focus, or a free n in world
 * units (course Fig. 3.6: "the parameter n is free"), used as given. */
static double warp_n(const MapFace *f, const WarpSetup *w, const Frame *fr, double theta)
{
    double D = fr->y_max - fr->y_min, alpha = fr->z1 / fr->z0;
    if (!fr->axis_ok || !(D > 0.0) || w->kind == MAP_PROJ_ORTHO) return INFINITY;
    double k = falloff_factor(w->params->falloff, fr->gamma, theta, alpha);
    double mult = w->params->warp_n > 0.0 ? w->params->warp_n : 1.0, n_world = w->params->warp_n_world;
    double n;
    if (n_world > 0.0 && (w->kind == MAP_PROJ_LISPSM || w->kind == MAP_PROJ_LOGPSM))
        n = n_world / fr->world_per_ndc;
    else if (w->kind == MAP_PROJ_TSM)
        n = tsm_n(f, w, fr) * k;
    else if (w->kind == MAP_PROJ_LOGPSM)
        n = D * warp_n_over_d(1.0, alpha) * k * mult; /* PSM-like: constant lateral error */
    else
        n = D * warp_n_over_d(0.0, alpha) * k * mult; /* LiSPSM: n_opt, Wimmer 2004 */
    return n > N_UNIFORM * D || !isfinite(n) ? INFINITY : fmax(n, 1e-9 * D);
}

/* ---- homographies ------------------------------------------------------------------- */

/* Base NDC -> (x' - x_c, y'), then the perspective warp with centre at
 * (x_c, y_min - n): (u, v) = ((x' - x_c) / w, -1 / w), w = y' - y_min + n
 * (course Fig. 3.6); the identity frame when n is infinite. */
static void frame_homography(const Frame *fr, double n, double H[3][3])
{
    double F[3][3] = {{fr->b[0], fr->b[1], -fr->x_c}, {fr->a[0], fr->a[1], 0.0}, {0, 0, 1}};
    if (!isfinite(n)) {
        memcpy(H, F, sizeof F);
        return;
    }
    double K[3][3] = {{1, 0, 0}, {0, 0, -1}, {0, 1, n - fr->y_min}};
    h_mul(K, F, H);
}

/* Stamminger & Drettakis 2002: the map is a light view taken in the eye's
 * post-perspective space, from the light's image L' there toward the
 * body's centre C'. Every light ray becomes a line through L', so a base
 * point q (the ray it names) maps to where that line meets the image plane
 * Pi through C' normal to the view axis L' -> C': in homogeneous terms
 * Y = (pi.X) L' - (pi.L') X for any X on the line, linear in q. */
static bool psm_homography(const MapFace *f, const WarpSetup *w, const double (*q)[2], int nq, double H[3][3])
{
    const ViewFrustum *v = w->view;
    double near = fmax(v->near, w->params->pseudo_near), far = fmax(v->far, near * (1.0 + 1e-9));
    mat4 view = m4_look(v->eye, v->fwd, v->up);
    mat4 proj = m4_frustum(-v->tan_x * near, v->tan_x * near, -v->tan_y * near, v->tan_y * near, near, far);
    mat4 Q = m4_mul(&proj, &view);
    dvec4 L = w->directional ? m4_apply4(&Q, (dvec4){w->light_axis.x, w->light_axis.y, w->light_axis.z, 0.0})
                             : m4_apply4(&Q, (dvec4){w->light_pos.x, w->light_pos.y, w->light_pos.z, 1.0});
    /* Post-perspective body and its centre C'. */
    dvec3 lo = d3(INFINITY, INFINITY, INFINITY), hi = d3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < w->n; i++) {
        dvec4 x = m4_apply(&Q, w->pts[i]);
        if (!(x.w > 0.0)) continue;
        dvec3 p = d3(x.x / x.w, x.y / x.w, x.z / x.w);
        lo = d3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = d3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    if (!(lo.x <= hi.x)) return false;
    dvec3 C = d3_scale(d3_add(lo, hi), 0.5), Lxyz = d3(L.x, L.y, L.z);
    bool at_infinity = fabs(L.w) <= 1e-12 * d3_len(Lxyz);
    dvec3 dir = at_infinity ? d3_normalize_or(Lxyz, d3(0, 1, 0))
                            : d3_normalize_or(d3_sub(C, d3_scale(Lxyz, 1.0 / L.w)), d3(0, 1, 0));
    double pi[4] = {dir.x, dir.y, dir.z, -d3_dot(dir, C)}, Lv[4] = {L.x, L.y, L.z, L.w};
    double piL = pi[0] * Lv[0] + pi[1] * Lv[1] + pi[2] * Lv[2] + pi[3] * Lv[3];
    /* v follows the post-perspective depth axis, u runs across, as in the other warps */
    dvec3 zaxis = d3_sub(d3(0, 0, 1), d3_scale(dir, dir.z));
    dvec3 e2 = d3_normalize_or(zaxis, d3_normalize_or(d3_cross(dir, d3(1, 0, 0)), d3(0, 1, 0)));
    dvec3 e1 = d3_cross(e2, dir);
    double R[3][4] = {{e1.x, e1.y, e1.z, -d3_dot(e1, C)}, {e2.x, e2.y, e2.z, -d3_dot(e2, C)}, {0, 0, 0, 1}};
    /* G: q -> X = Q p(q), p(q) on the ray of q (base z_ndc 1/2, homogeneous). */
    double G[4][3];
    for (int c = 0; c < 3; c++) {
        dvec4 col = c == 0 ? (dvec4){1, 0, 0, 0} : c == 1 ? (dvec4){0, 1, 0, 0} : (dvec4){0, 0, 0.5, 1};
        dvec4 x = m4_apply4(&Q, m4_apply4(&f->base_inv, col));
        G[0][c] = x.x; G[1][c] = x.y; G[2][c] = x.z; G[3][c] = x.w;
    }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double s = 0.0; /* R Y G, Y = L pi^T - (pi.L) I */
            for (int k = 0; k < 4; k++) {
                double piX = pi[0] * G[0][c] + pi[1] * G[1][c] + pi[2] * G[2][c] + pi[3] * G[3][c];
                s += R[r][k] * (Lv[k] * piX - piL * G[k][c]);
            }
            H[r][c] = s;
        }
    /* One sign of w over the body, or the vanishing line crosses it. */
    int pos = 0, neg = 0;
    for (int i = 0; i < nq; i++) {
        double wq = h_w(H, q[i][0], q[i][1]);
        pos += wq > 0.0;
        neg += wq < 0.0;
    }
    if (neg == nq)
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) H[r][c] = -H[r][c];
    return pos == nq || neg == nq;
}

/* Prepend the affine that maps the points' image to [-1, 1]^2 with the
 * margin; w_min = the least w over the points and the map's corners. */
static bool fit_homography(double H[3][3], const double (*q)[2], int nq, int res, double *w_min)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    *w_min = INFINITY;
    for (int i = 0; i < nq; i++) {
        double u, v;
        if (!warp_apply(H, q[i][0], q[i][1], &u, &v)) return false;
        lo[0] = fmin(lo[0], u); hi[0] = fmax(hi[0], u);
        lo[1] = fmin(lo[1], v); hi[1] = fmax(hi[1], v);
        *w_min = fmin(*w_min, h_w(H, q[i][0], q[i][1]));
    }
    double A[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 1}};
    for (int k = 0; k < 2; k++) {
        double c = 0.5 * (lo[k] + hi[k]), half = 0.5 * fmax(hi[k] - lo[k], 1e-12 * fmax(fabs(c), 1e-300));
        half *= 1.0 + 2.0 * LIGHTVIEW_MARGIN_TEXELS / res;
        A[k][k] = 1.0 / half;
        A[k][2] = -c / half;
    }
    h_mul(A, H, H);
    double Hi[3][3];
    if (!h_invert(H, Hi)) return false;
    for (int k = 0; k < 4; k++) { /* the map's corners, where they lie in front */
        double x, y, u = k & 1 ? 1.0 : -1.0, v = k & 2 ? 1.0 : -1.0;
        if (warp_apply(Hi, u, v, &x, &y) && h_w(H, x, y) > 0.0) *w_min = fmin(*w_min, h_w(H, x, y));
    }
    return *w_min > 0.0 && isfinite(*w_min);
}

/* Fold H into the clip rows: x, y, w from the base's (x, y, w) rows, z from
 * the base's z row scaled by w_min, so 0 <= z_ndc <= base z_ndc <= 1. */
static bool compose(MapFace *f, const double H[3][3], double w_min, Error *err)
{
    const mat4 *B = &f->base_clip;
    mat4 M;
    const int rows[3] = {0, 1, 3};
    for (int c = 0; c < 4; c++) {
        for (int r = 0; r < 3; r++)
            M.m[rows[r]][c] = H[r][0] * B->m[0][c] + H[r][1] * B->m[1][c] + H[r][2] * B->m[3][c];
        M.m[2][c] = w_min * B->m[2][c];
    }
    f->raster.clip_from_world = M;
    if (!m4_invert(&M, &f->world_from_clip) || !h_invert(H, f->H_inv))
        return error_set(err, "the warped light projection is singular");
    memcpy(f->H, H, sizeof f->H);
    f->w_min = w_min;
    f->warp = MAP_WARP_HOMOGRAPHY;
    f->perspective = false;
    return true;
}

/* ---- the logarithmic map ------------------------------------------------------------- */

static double log_along(const LogWarp *g, double y)
{
    double t = (y - g->y_min) / g->D;
    if (!isfinite(g->n)) return t;
    return log1p((y - g->y_min) / g->n) / log1p(g->D / g->n);
}

static double log_lateral(const LogWarp *g, double x, double y)
{
    return isfinite(g->n) ? (x - g->x_c) / (y - g->y_min + g->n) : x - g->x_c;
}

void warp_log_forward(const LogWarp *g, double x_b, double y_b, double *u, double *v)
{
    double x = x_b * g->b[0] + y_b * g->b[1], y = x_b * g->a[0] + y_b * g->a[1];
    *u = g->ku * log_lateral(g, x, y) + g->cu;
    *v = g->kv * log_along(g, y) + g->cv;
}

void warp_log_inverse(const LogWarp *g, double u, double v, double *x_b, double *y_b)
{
    double t = (v - g->cv) / g->kv, lat = (u - g->cu) / g->ku;
    double y = isfinite(g->n) ? g->y_min + g->n * expm1(t * log1p(g->D / g->n)) : g->y_min + t * g->D;
    double x = g->x_c + lat * (isfinite(g->n) ? y - g->y_min + g->n : 1.0);
    *x_b = x * g->b[0] + y * g->a[0];
    *y_b = x * g->b[1] + y * g->a[1];
}

static void fit_log(MapFace *f, const Frame *fr, double n, const double (*q)[2], int nq, int res)
{
    LogWarp *g = &f->log;
    memcpy(g->a, fr->a, sizeof g->a);
    memcpy(g->b, fr->b, sizeof g->b);
    g->x_c = fr->x_c;
    g->y_min = fr->y_min;
    g->D = fmax(fr->y_max - fr->y_min, 1e-12);
    g->n = n;
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < nq; i++) {
        double x = q[i][0] * g->b[0] + q[i][1] * g->b[1], y = q[i][0] * g->a[0] + q[i][1] * g->a[1];
        double l = log_lateral(g, x, y);
        lo = fmin(lo, l);
        hi = fmax(hi, l);
    }
    double pad = 1.0 + 2.0 * LIGHTVIEW_MARGIN_TEXELS / res, half = 0.5 * fmax(hi - lo, 1e-12) * pad;
    g->ku = 1.0 / half;
    g->cu = -0.5 * (lo + hi) / half;
    g->kv = 2.0 / pad; /* v in [0, 1] over the body -> [-1, 1] with the margin */
    g->cv = -0.5 * g->kv;
    f->warp = MAP_WARP_LOG;
    f->perspective = false;
    f->raster.clip_from_world = f->base_clip;
    f->world_from_clip = f->base_inv;
}

/* ---- the face ------------------------------------------------------------------------- */

bool warp_face(MapFace *f, int res, const WarpSetup *w, Error *err)
{
    double(*q)[2] = malloc(sizeof *q * (size_t)(w->n > 0 ? w->n : 1));
    if (!q) return error_set(err, "out of memory warping the light's map");
    Frame fr;
    int nq;
    double theta = atan(fmin(w->view->tan_x, w->view->tan_y));
    bool ok = frame_fit(f, w, q, &nq, &fr);
    double n = ok ? warp_n(f, w, &fr, theta) : INFINITY, H[3][3], w_min = 1.0;
    f->warp_gamma = ok ? fr.gamma : 0.0;
    if (!ok) { /* nothing of the body in front of the base: keep the base as it is */
        free(q);
        f->warp = MAP_WARP_NONE;
        f->warp_n = INFINITY;
        return true;
    }
    if (w->kind == MAP_PROJ_LOGPSM) {
        fit_log(f, &fr, n, (const double(*)[2])q, nq, res);
        f->warp_n = n;
        free(q);
        return true;
    }
    bool psm = w->kind == MAP_PROJ_PSM && fr.axis_ok && psm_homography(f, w, (const double(*)[2])q, nq, H) &&
               fit_homography(H, (const double(*)[2])q, nq, res, &w_min);
    if (w->kind == MAP_PROJ_PSM && !psm) { /* L' inside the body: the PSM-like end of LiSPSM's range */
        f->warp_fallback = true;
        double D = fr.y_max - fr.y_min;
        n = fr.axis_ok && D > 0.0 ? D * warp_n_over_d(1.0, fr.z1 / fr.z0) : INFINITY;
    }
    if (!psm) {
        frame_homography(&fr, n, H);
        if (!fit_homography(H, (const double(*)[2])q, nq, res, &w_min)) {
            f->warp_fallback = true;
            frame_homography(&fr, INFINITY, H);
            n = INFINITY;
            if (!fit_homography(H, (const double(*)[2])q, nq, res, &w_min)) w_min = 1.0;
        }
    }
    f->warp_n = psm ? 0.0 : n;
    free(q);
    return compose(f, H, w_min, err);
}
