/* lightbody.h -- the camera's view frustum as light fitting sees it, and the
 * intersection body B of course §3.2.1 (Brabec 2005; Wimmer 2004): the part
 * of a depth slice of the view frustum that lies inside the scene's bounds
 * (and a spot light's cone), as the vertex set of a convex polyhedron. A
 * map fitted to B's projection covers every visible receiver; casters
 * between the light and B are kept by extending the depth range toward the
 * light (for a directional or point light, hull(B, light) projects onto the
 * map exactly as B does). Spaces: world; view depth = distance along the
 * camera's axis (world units). */
#ifndef SL_LIGHTBODY_H
#define SL_LIGHTBODY_H
#include "core/mat4.h"
#include "scene/scene.h"

/* Enough for a box slice clipped by 6 box planes and 5 cone planes. */
#define BODY_MAX_POINTS 512

typedef struct ViewFrustum {
    dvec3 eye, fwd, right, up; /* unit camera frame, right-handed like view.c's */
    double tan_x, tan_y;       /* half extents on the plane at unit depth */
    double near, far;          /* view depths */
} ViewFrustum;

ViewFrustum view_frustum(const Camera *cam);
static inline double view_depth(const ViewFrustum *f, dvec3 p) { return d3_dot(d3_sub(p, f->eye), f->fwd); }
/* The point at image-plane position (sx, sy) in [-1, 1]^2 and view depth d. */
dvec3 frustum_point(const ViewFrustum *f, double sx, double sy, double d);

/* An oriented plane: points with d3_dot(n, p) + d >= 0 are kept. */
typedef struct BodyPlane { dvec3 n; double d; } BodyPlane;

/* Vertices of the slice [d0, d1] of the frustum clipped by the scene's
 * bounds (grown by 1e-6 of the scene's extent, so a flat scene still gives
 * a thin body) and the extra planes; 0 when the slice misses them. */
int body_points(const ViewFrustum *f, double d0, double d1, const Scene *scene, const BodyPlane *extra, int n_extra,
                dvec3 *out, int max_out);
/* The six faces of the frustum, in this order (frustum-face partitioning,
 * course §3.2.3.2). */
enum { FRUSTUM_NEAR, FRUSTUM_FAR, FRUSTUM_BOTTOM, FRUSTUM_TOP, FRUSTUM_LEFT, FRUSTUM_RIGHT, FRUSTUM_FACES };
/* Face `face` of the frustum: its outward unit normal and offset (n.p + d
 * = 0 on the plane, > 0 outside), its four corners in order, and their
 * mid-points at the near and at the far end (side faces; the face's centre
 * twice for the near and far faces). */
typedef struct FrustumFace { dvec3 n; double d; dvec3 corner[4]; dvec3 near_mid, far_mid; } FrustumFace;
FrustumFace frustum_face(const ViewFrustum *f, int face);
/* The planes through the face's edges along the light's rays (direction
 * `dir`, or through the light's centre when `point`): with the face's own
 * plane they bound the points whose ray toward the light leaves the
 * frustum through this face. */
int frustum_face_prism(const FrustumFace *ff, bool point, dvec3 light, BodyPlane *out);

/* The four side planes and the apex plane of a spot light's cone. */
int spot_cone_planes(const Light *light, BodyPlane *out);

#endif
