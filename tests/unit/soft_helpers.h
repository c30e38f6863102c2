/* soft_helpers.h -- what the tests of the single-map soft-shadow techniques
 * (accumulation, brabec, pcss) share: labs on small views of the project's
 * scenes, renders from "name=value" lists, errors against a cheap Embree
 * reference, agreement with another image, and the parallel-planes scene
 * (a long strip over the ground, light straight above) where the papers'
 * assumptions hold. */
#ifndef SL_SOFT_HELPERS_H
#define SL_SOFT_HELPERS_H
#include "lab/lab.h"

/* scenes/NAME at 160 x 120 (overrides NULL-terminated, may be NULL). */
Lab *soft_open(const char *name, const char *const *overrides);
/* The strip scene: light (Lua table text) at height 4, a 1.5 x 8 strip at
 * `strip_height` (receiver = false), the 8 x 8 ground; 128 x 96. */
Lab *soft_strip(const char *light, double strip_height);

/* Texel width along x (tangent units) of the map `tech` reads with its
 * defaults and this map size (the same resource its render acquires). */
double soft_map_dx(Lab *lab, const char *tech, int map_size);

/* Render `tech` on light 1 with the NULL-terminated "name=value" list. */
bool soft_render(Lab *lab, const char *tech, const char *const *params, RenderResult *out);
/* Render `tech` as soft_render does, then find `kind` in the resources its
 * prepare acquired (RenderResult.tech_resources, the run's resource log):
 * whether it was built (false: reused) and its bytes; false when the render
 * fails or it acquired no such resource. */
bool soft_render_event(Lab *lab, const char *tech, const char *const *params, const char *kind, bool *built,
                       size_t *bytes);
/* Metrics against a `samples`-sample stratified reference (seed 1, no disk cache). */
bool soft_metrics(Lab *lab, const Image *v, int samples, Metrics *m);

/* Over the light-facing samples: how many differ by more than 0.5, the mean |a - b|. */
typedef struct Agreement { long candidates, differ; double mean_abs; } Agreement;
Agreement soft_agreement(Lab *lab, const Image *a, const Image *b);

#endif
