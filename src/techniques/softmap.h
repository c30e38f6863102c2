/* softmap.h -- what the single-map soft-shadow techniques share
 * (accumulation: seed 000; brabec: course §5.2.1; pcss: course §5.2.2):
 * the light's shape in each map face's frame, the face's tangent frame (the
 * plane at unit depth, where a perspective map's texels form a regular grid
 * of size dx x dy), linear depths from any stored format, and a progressive
 * Poisson-disk pattern. Perspective faces only (perspective and cube maps):
 * every formula below is a similar-triangles argument about the light's centre.
 *
 * Frame of a face: origin at the light's centre, z along the face's axis
 * (depth = linear view depth, world units), x and y the face's axes. A texel
 * or receiver at tangent (u, v) and depth z sits at (u z, v z, z). */
#ifndef SL_SOFTMAP_H
#define SL_SOFTMAP_H
#include "resources/maps/prefilter.h"
#include "techniques/smap.h"

#define SOFTMAP_MAX_POISSON 1024

/* The light as the face sees it: an affine image of the unit disk (sphere,
 * disk) or of the square [-1, 1]^2 (rect) in the light's plane z = 0,
 * x = M xi, world units. A sphere is its central cross-section (seed 000
 * §1.1 assumption 1); disks and rectangles are their orthogonal projections
 * onto the plane, exact when they face the map's axis (the auto projection
 * of disk and rect lights looks along their normal). */
typedef struct SoftLight {
    double M[2][2], Minv[2][2];
    bool square;
    double area_world;      /* |det M| pi, or |det M| 4 */
    double half_x, half_y;  /* half-extents of its bounding box along the face's x and y */
    double radius_world;    /* radius of the disk of the same area (radial searches) */
} SoftLight;

typedef struct SoftFace {
    double l, b;            /* tangents of texel edge 0 along x and y */
    double dx, dy;          /* texel size in tangent units */
    double near_world;      /* the face's near plane depth */
    SoftLight light;
} SoftFace;

typedef struct SoftMap {
    const ShadowMap *map;
    const MinMaxPyramid *pyramid; /* the map's min-max mip pyramid: early outs */
    SoftFace face[LIGHTVIEW_MAX_FACES];
} SoftMap;

/* Set up for `map` of `light` and acquire its min-max pyramid (a keyed
 * resource of its own, shared with every technique that reads it); refuses
 * maps whose faces are not plain perspective frusta from the light's centre
 * (warps, paraboloids), naming the technique and the projection. */
bool softmap_init(SoftMap *sm, ResourceManager *rm, const ShadowMap *map, const Light *light, const char *tech,
                  Error *err);
/* The same without the pyramid (sm->pyramid NULL: softmap_may_block is not
 * for it), for techniques that read only the faces' frames and depths. */
bool softmap_frames(SoftMap *sm, const ShadowMap *map, const Light *light, const char *tech, Error *err);

/* Can any texel of [i0, i1] x [j0, j1] block the receiver? false when the
 * pyramid's minimum depth over the window is no closer than the largest
 * reference depth over it (course §5.2.3.4's early out, z_p <= z_min: lit).
 * The reference is affine in (s, t), or its reciprocal is, so its largest
 * value over the window is at a corner. Exact: it never skips a blocker.
 * z_min_linear (may be NULL) receives a lower bound of every depth in the
 * window (world units), for searches that narrow through it. */
bool softmap_may_block(const SoftMap *sm, const SmapReceiver *r, int i0, int j0, int i1, int j1,
                       double *z_min_linear);
/* The same decision from a minimum `zmin` (stored depth) that some other
 * min-max structure gives for that window (the multiscale maps of course
 * §5.2.3.4). */
bool softmap_bounds_may_block(const SoftMap *sm, const SmapReceiver *r, float zmin, int i0, int j0, int i1, int j1,
                              double *z_min_linear);

/* Linear depth (world units along the face's axis) of texel (i, j);
 * +INFINITY where no caster was drawn. */
static inline double softmap_depth(const SoftMap *sm, int face, int i, int j)
{
    return smap_linear_depth(sm->map, face, shadowmap_texel(sm->map, face, i, j));
}

/* Is the light-plane point x (world, relative to the light's centre) on the light? */
static inline bool softlight_contains(const SoftLight *L, double x, double y)
{
    double a = L->Minv[0][0] * x + L->Minv[0][1] * y, b = L->Minv[1][0] * x + L->Minv[1][1] * y;
    return L->square ? fabs(a) < 1.0 && fabs(b) < 1.0 : a * a + b * b < 1.0;
}

/* The receiver's offset to texel (i, j)'s centre, in texels. */
static inline double softmap_di(const SmapReceiver *r, int i) { return i + 0.5 - r->mc.s; }
static inline double softmap_dj(const SmapReceiver *r, int j) { return j + 0.5 - r->mc.t; }

/* The first texel of a window of `width` texels centred on coordinate c:
 * the texels whose centres are nearest (course §4.1.2's K x K box). */
static inline int softmap_window_start(double c, int width) { return (int)floor(c - 0.5 * width + 0.5); }

/* n points in the unit disk by dart throwing with a shrinking radius (Cook
 * 1986; McCool & Fiume 1992): each accepted point keeps the current minimum
 * distance to the others, so the pattern is a Poisson-disk set whose radius
 * adapts to n. Deterministic. */
void softmap_poisson(float (*pts)[2], int n);

/* A per-sample rotation (cos, sin) for rotated Poisson patterns; (1, 0) when off. */
void softmap_rotation(bool rotate, uint32_t sample, double *cs, double *sn);

#endif
