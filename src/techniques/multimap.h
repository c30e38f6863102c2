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

/* The world point at linear depth z (world units along the face's axis, or
 * a paraboloid's radius) on the ray through texel coordinates (s, t) of a
 * face; false where the ray runs parallel to the face's depth planes. */
bool mm_texel_point(const LightView *v, int face, double s, double t, double z, dvec3 *x);

/* The penumbra deep shadow map (penumbra_deep_map.c), declared here so the
 * tests can read the built resource (kind "penumbra_deep_map"): per texel of
 * the centre's map (faces x res^2, texel (face, i, j) at (face res + j) res
 * + i), a piecewise-linear visibility of linear depth along the texel's
 * centre ray, vertices sorted by depth; two vertices at one depth are a
 * step (the function is right-continuous there). */
typedef struct DeepVertex {
    float z; /* linear depth along the centre face's axis, world units */
    float v; /* visibility, [0, 1] */
} DeepVertex;

typedef struct DeepMap {
    int n;              /* light samples */
    double error;       /* the compression's bound (max |deviation| in visibility) */
    int max_vertices;   /* per texel */
    int res, num_faces;
    size_t texels;
    uint32_t *first;    /* [texels + 1]: texel t's vertices are vertex[first[t] .. first[t + 1]) */
    DeepVertex *vertex;
    uint8_t *unknown;   /* a sample's map read NaN on the texel's ray: its visibility is unknown */
    long capped;        /* texels that needed more than max_vertices at `error` (compressed looser) */
    long events;        /* visibility events found (steps of the uncompressed functions) */
} DeepMap;

#endif
