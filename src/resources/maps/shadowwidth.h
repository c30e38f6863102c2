/* shadowwidth.h -- Kirsch & Döllner's shadow-width map (seed 003 §3, §4) as
 * a keyed resource: an inverted occlusion map (1 on shadow blockers, 0
 * elsewhere) turned by iterative minimum propagation into each texel's
 * distance to the nearest unblocked texel. Each step adds a difference d to a
 * neighbour's value and keeps the minimum, so a texel ends at
 * min(1, d x steps): the software version sweeps the 4 axis neighbours in
 * place; the texture-compositing version samples 3 or 6 neighbours per pass,
 * doubling the neighbour distance and the difference each pass until the
 * difference exceeds 1 (Fig. 4).
 *
 * Blockers: a texel is a blocker when some surface lies behind its first
 * surface (the map's peeled second layer is not empty there), so a receiver
 * that shadows nothing, such as a ground plane, stays unblocked while every
 * shape that casts onto something, itself included, is a blocker (§5: "best
 * treated as blocker"). The map is keyed by the depth maps it is derived from
 * (ShadowMap.key), so sweeps of the attenuation's constants reuse it. */
#ifndef SL_SHADOWWIDTH_H
#define SL_SHADOWWIDTH_H
#include "resources/maps/shadowmap.h"

typedef enum SwPropagation {
    SW_SOFTWARE4, /* in-place sweeps over the left, right, bottom and top neighbours */
    SW_DOUBLING3, /* passes over 3 neighbours 120 degrees apart, doubling distance and difference */
    SW_DOUBLING6, /* the same with 6 neighbours 60 degrees apart */
} SwPropagation;
#define SW_PROPAGATION_NAMES "software4", "doubling3", "doubling6"

typedef struct ShadowWidthSpec {
    SwPropagation propagation;
    double start_difference; /* d, added per texel step (software) or in the first pass (doubling); (0, 1] */
} ShadowWidthSpec;

typedef struct ShadowWidthMap {
    uint64_t key;
    int res, num_faces;      /* texels per side, faces (as the depth maps) */
    double start_difference;
    int passes;              /* sweeps or doubling passes run */
    long blockers;           /* texels of the inverted occlusion map set to 1 */
    float *width;            /* num_faces x res x res, min(1, d x steps to the nearest unblocked texel) */
} ShadowWidthMap;

/* The map for the depth maps of `depth_spec` (its first layer and the peeled
 * layer behind it). Each face of a cube or paraboloid map propagates on its
 * own: widths do not cross the seams. */
const ShadowWidthMap *res_shadow_width_map(ResourceManager *rm, const Scene *scene, int light_index,
                                           const ShadowMapSpec *depth_spec, const ShadowWidthSpec *spec, Error *err);

/* Width at texel (i, j) of a face in texel steps, clamped to the edge. */
static inline double shadow_width_texels(const ShadowWidthMap *w, int face, int i, int j)
{
    i = i < 0 ? 0 : i >= w->res ? w->res - 1 : i;
    j = j < 0 ? 0 : j >= w->res ? w->res - 1 : j;
    return w->width[((size_t)face * (size_t)w->res + (size_t)j) * (size_t)w->res + (size_t)i] / w->start_difference;
}

#endif
