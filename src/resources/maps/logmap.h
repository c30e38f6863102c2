/* logmap.h -- the second builder of the depth-map resource: logarithmic
 * faces (LogPSM, course §3.2.2.2) cannot be rasterised -- hardware and
 * src/raster interpolate hyperbolically -- so each texel's depth is found
 * exactly by one Embree ray through the inverse parametrisation: texel
 * centre -> base NDC -> the light's ray -> the nearest caster on it. */
#ifndef SL_LOGMAP_H
#define SL_LOGMAP_H
#include "resources/maps/shadowmap.h"
#include "rt/rt.h"

/* Fill m->depth (and m->triangle) of every face of m->view from the casters. */
bool logmap_cast(ShadowMap *m, const Scene *scene, const RtScene *casters, Error *err);
/* Why a spec cannot be ray cast (NULL when it can): the options of the
 * rasterizer that have no ray-cast counterpart here. */
const char *logmap_refusal(const ShadowMapSpec *spec);

#endif
