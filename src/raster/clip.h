/* clip.h -- homogeneous clipping of one triangle against the view frustum
 * (Sutherland-Hodgman over the planes 0 <= z <= w, -w <= x, y <= w; Blinn &
 * Newell 1978), or against the front half-space only (paraboloid maps). The
 * point where an edge crosses a plane is computed from the edge's endpoints
 * in a canonical order, so two triangles sharing the edge get bit-identical
 * vertices there and stay watertight after clipping. */
#ifndef SL_CLIP_H
#define SL_CLIP_H
#include <stdbool.h>

/* A vertex in clip space with the linear-depth attribute a carried along. */
typedef struct ClipVertex { double x, y, z, w, a; } ClipVertex;

#define CLIP_MAX_VERTS 9 /* a triangle cut by 6 planes has at most 3 + 6 vertices */

/* Which planes to test: every frustum plane, or only "in front" (z_view < 0
 * for the paraboloid's hemisphere, given as clip z >= 0 with x, y free). */
typedef enum ClipPlanes { CLIP_FRUSTUM, CLIP_FRONT_ONLY } ClipPlanes;

/* Bit i set when v is outside plane i. */
unsigned clip_outcode(const ClipVertex *v, ClipPlanes planes);
/* Clip triangle tri[3] into poly (returns the vertex count, 0 when nothing
 * is left). Only planes in `crossing` (an outcode union) are tested. */
int clip_triangle(const ClipVertex tri[3], unsigned crossing, ClipVertex *poly);

#endif
