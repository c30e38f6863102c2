/* multimap.h -- what the multiple-shadow-map techniques of course §5.2.4
 * share (light_sampling.c, multimap.c): the N points on the light, the
 * reference's own for rect and disk lights, and the hard map rendered from
 * each through the resource manager (keyed by the point, so a sweep over N
 * reuses the first N's and every technique of the family reads the same
 * maps), and the parameters that choose them. */
#ifndef SL_MULTIMAP_H
#define SL_MULTIMAP_H
#include "core/sampling.h"
#include "techniques/smap.h"

#define LS_MAX_SAMPLES 1024

enum { LS_PAT_R2, LS_PAT_RANDOM };
extern const char *const ls_pattern_names[];

/* N and where the samples lie; expanded into each technique's table. */
#define LS_SAMPLE_PARAMS                                                                                           \
    {"samples", PARAM_INT, 16, 1, LS_MAX_SAMPLES, "maps",                                                          \
     "N: light samples, one shadow map of map_size^2 each (memory and build time grow as N; N maps above 2 GiB "  \
     "together are refused)",                                                                                      \
     NULL},                                                                                                        \
    {"pattern", PARAM_ENUM, LS_PAT_R2, 0, 1, "",                                                                   \
     "where on the light the samples lie: r2 (Roberts' low-discrepancy sequence, the reference's default "        \
     "pattern: error falls faster than 1/sqrt(N)) or random (independent uniform points: 1/sqrt(N))",             \
     ls_pattern_names}

/* The hard map of the scene seen from a point light at `point` (world),
 * the spec's projection and fit: the light's own key plus the point. */
const ShadowMap *ls_point_map(const TechContext *ctx, const ShadowMapSpec *spec, vec3 point, Error *err);

/* The n light samples (world) of pattern `pattern` (an LS_PAT_ value) and
 * the map from each; refused, naming samples and map_size, when the n maps
 * together exceed SHADOWMAP_MAX_BYTES. */
bool ls_sample_maps(const TechContext *ctx, const ShadowMapSpec *spec, int n, int pattern,
                    vec3 *point, const ShadowMap **map, Error *err);

#endif
