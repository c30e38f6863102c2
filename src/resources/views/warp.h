/* warp.h -- the perspective and logarithmic warps of course §3.2.2, built on
 * a face whose base projection (ortho for a directional light, the light's
 * perspective otherwise) is already fitted to the points it must cover.
 * Every warp is a map of the base's NDC plane, which the light's rays cross
 * once each, so casters anywhere along a ray land in the texel of the
 * receivers on it (no PSM "behind the eye" inversion can arise). The warp
 * frame: axis a = the view direction as seen in the base plane, b across.
 * Used by lightview.c; the formulas cite their papers next to them. */
#ifndef SL_WARP_H
#define SL_WARP_H
#include "resources/views/lightbody.h"
#include "resources/views/lightview.h"

typedef struct WarpSetup {
    MapProjection kind;             /* MAP_PROJ_ORTHO (uniform, fitted in the warp's frame), PSM, LISPSM, TSM, LOGPSM */
    const LightViewParams *params;
    const ViewFrustum *view;
    bool directional;
    dvec3 light_axis;               /* directional: travel direction; else the base's axis */
    dvec3 light_pos;                /* the light's centre (not directional) */
    const dvec3 *pts;               /* what the face must cover (world) */
    int n;
    double z_min, z_max;            /* their view-depth range (world units), within the camera's */
    /* The warp's axis: the image of the view axis, or of the segment
     * axis_from -> axis_to when has_axis (a frustum face's, course §3.2.3.2). */
    bool has_axis;
    dvec3 axis_from, axis_to;
} WarpSetup;

/* Turn the fitted base face f into the warped face (res: texels per side,
 * for the margin). Degenerate inputs (light along the view, flat or empty
 * body, the warp's centre on the body) fall back toward the uniform map. */
bool warp_face(MapFace *f, int res, const WarpSetup *w, Error *err);

/* Lloyd 2007 thesis §5.1.2.2: n (in units of D, the body's extent along the
 * warp axis) from the warp strength eta in [-1, 1] and alpha = z_1 / z_0,
 * the view depths at the body's near and far ends along the axis: eta = -1
 * uniform, 0 the optimum n_opt = D / (sqrt(alpha) - 1), 1 PSM-like. */
double warp_n_over_d(double eta, double alpha);
/* Lloyd 2007 §5.2.1: eta as a function of gamma (the angle between the view
 * and light directions, radians) for a view of half field of view theta. */
double warp_eta_lloyd(double gamma, double theta);

/* The logarithmic map: base NDC (x_b, y_b) <-> map NDC (u, v). */
void warp_log_forward(const LogWarp *g, double x_b, double y_b, double *u, double *v);
void warp_log_inverse(const LogWarp *g, double u, double v, double *x_b, double *y_b);

/* A 3x3 homography applied to (x, y, 1): false where its w is not positive. */
bool warp_apply(const double H[3][3], double x, double y, double *u, double *v);

#endif
