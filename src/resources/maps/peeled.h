/* peeled.h -- depth-peeled layers of a shadow map (course §5.2.3.3,
 * "depth-peeled layers capture all occluders, at linear cost"; Fig. 1.8):
 * layer 0 is the map itself, the nearest surface from the light's centre
 * per texel; layer k the nearest surface behind layer k - 1 by more than
 * the rasterizer's peel epsilon (shadowmap_peel_epsilon: 1e-5 of the face's
 * depth range, plus a quantisation step on quantised maps), so the k-th
 * nearest surface. A texel with fewer surfaces is empty (+INFINITY) in the
 * layers past its last. Each layer is a keyed resource of its own (the
 * map's key, k), built by the engine's rasterizer only when asked for, so
 * a run with 4 layers reuses the 2 of another and records each one's bytes. */
#ifndef SL_PEELED_H
#define SL_PEELED_H
#include "resources/maps/shadowmap.h"

#define PEELED_MAX_LAYERS 8

/* Layer k (0 <= k < PEELED_MAX_LAYERS) of map, whose layer must be
 * MAP_LAYER_FIRST; layer 0 is map itself. */
const ShadowMap *res_peeled_layer(ResourceManager *rm, const Scene *scene, const ShadowMap *map, int k, Error *err);

#endif
