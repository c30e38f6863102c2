/* light.h -- sampling of every light kind, shared by the Embree reference
 * and by stochastic techniques (pbrt's split: sampling here, integration in
 * the caller). Also the classification of a surface point against a light:
 * back-facing points are "unlit by shading", not "in shadow" (course §1, Eq. 1.1
 * restricts occluders to the positive half-space H+(p)). The same convention
 * holds for a light the tangent plane cuts: the part below the plane is
 * shading (the horizon), not shadow, so the reference measures visibility
 * over the part above it and such a sample is scored in its own metrics
 * region, `terminator` (light_crosses_horizon). */
#ifndef SL_LIGHT_H
#define SL_LIGHT_H
#include "scene/scene.h"

/* Class of a view sample with respect to one light. Only SAMPLE_LIT_CANDIDATE
 * samples enter shadow metrics. */
typedef enum SampleClass {
    SAMPLE_BACKGROUND = 0,    /* the primary ray hit nothing */
    SAMPLE_LIT_CANDIDATE = 1, /* faces (part of) the light: visibility is measured over that part */
    SAMPLE_BACKFACING = 2,    /* normal faces away from the whole light */
    SAMPLE_OUTSIDE_LIGHT = 3, /* outside a spot cone or behind a one-sided area light */
    SAMPLE_NOT_RECEIVER = 4,  /* on an object flagged receiver = false */
} SampleClass;
#define SAMPLE_CLASS_COUNT 5
const char *sample_class_name(SampleClass c);

/* One sample of a light seen from a point p. */
typedef struct LightSample {
    vec3 dir_world;   /* unit direction from p to the light sample */
    float dist;       /* distance to the sample point (world units); INFINITY for directional */
    vec3 vis_weight;  /* weight of this sample's visibility: 1, or the emission image's RGB */
    vec3 irradiance;  /* radiance estimator without the receiver cosine:
                         L_e cos_q / (r^2 pdf_area), or its solid-angle equivalent */
} LightSample;

/* Sample the light from p_world with the 2D sample (u, v) in [0,1)^2. Delta
 * lights (point, spot, directional) ignore (u, v). */
LightSample light_sample(const Light *light, vec3 p_world, float u, float v);
/* The light's centre sample (the point-light limit that `hard` tests). */
LightSample light_sample_center(const Light *light, vec3 p_world);
bool light_is_delta(const Light *light);
/* The colour of light sample (u, v), its visibility's weight (LightSample
 * vis_weight): a textured rect's emission texel RGB there, white for every
 * other light. */
vec3 light_sample_colour(const Light *light, float u, float v);
/* Visibility per channel (out[0..nc), nc 1 or 3) of n light samples with
 * those colours, of which the bits set in `kept` count and those set in
 * `blocked` are blocked (bit i of word i / 64): the kept unblocked samples'
 * colours summed over all kept samples' colours, channel by channel, the
 * reference's own ratio (rt/reference.c finish: sum w x / sum w with w the
 * sample's vis_weight; a channel whose colours sum to 0 has nothing to
 * block and is 1, and so is a set with no kept sample). */
void light_bitmask_visibility(const vec3 *colour, const uint64_t *kept, const uint64_t *blocked, int n, int nc,
                              float *out);
/* A planar light's (rect, textured rect, disk) own frame: its centre and two
 * orthonormal axes in its plane (world); false for the others, whose
 * samples are not fixed points (a sphere light's are directions in the cone
 * from each p). */
bool light_plane_axes(const Light *light, vec3 *centre, vec3 *e1, vec3 *e2);
/* Sample (u, v)'s point on a planar light in those axes' coordinates (world
 * units): the point light_sample aims at, whatever p. */
void light_plane_point(const Light *light, float u, float v, double st[2]);
SampleClass light_classify(const Light *light, vec3 p_world, vec3 n_world);
/* True when the tangent plane of (p_world, n_world) cuts the light: part of
 * its points (a sphere light: of the cone of directions it subtends) lies
 * strictly above the plane and part strictly below. Never for delta lights. */
bool light_crosses_horizon(const Light *light, vec3 p_world, vec3 n_world);
/* The light's sample highest above that plane (the delta lights' only one):
 * the reference's one ray toward a part of the light above the horizon too
 * thin for any of its pattern's samples. */
LightSample light_sample_highest(const Light *light, vec3 p_world, vec3 n_world);

#endif
