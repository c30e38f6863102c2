/* outer.h -- the soft-edged outer objects of seed 002 (Parker, Shirley &
 * Smits, "Single Sample Soft Shadows": §3 and its appendix): an outer sphere
 * around each analytic sphere, an outer "triangle with rounded corners"
 * around each caster triangle, of size b = D t0 / ||l - o||. One shadow ray
 * toward the light's centre finds every outer object it grazes (tau < 1) in
 * an Embree-built BVH and combines their attenuations s(tau). The opaque inner
 * objects, the casters themselves, are traced apart on the casters' BVH. */
#ifndef SL_OUTER_H
#define SL_OUTER_H
#include "rt/rt.h"

typedef struct OuterScene OuterScene;

/* Seed 002 §3: how the attenuations of several grazed occluders combine. */
typedef enum OuterCombine {
    OUTER_MIN,     /* s = min(s1, s2): "thresholding", the paper's choice */
    OUTER_PRODUCT, /* s = s1 s2 */
    OUTER_SUM,     /* s = 1 - ((1 - s1) + (1 - s2)), clamped at 0 */
} OuterCombine;

/* Seed 002 §3: s as a function of tau, 0 at the inner object, 1 at the outer boundary. */
typedef enum OuterFalloff {
    OUTER_POLYNOMIAL, /* s = 3 tau^2 - 2 tau^3 (the Bernstein interpolant the paper uses) */
    OUTER_SINUSOID,   /* s = (1 + sin(pi tau - pi/2)) / 2 (straight edge, spherical light) */
} OuterFalloff;

/* One shadow ray and the light it points at. */
typedef struct OuterRay {
    vec3 org_world;       /* o: the (offset) receiver point */
    vec3 dir_world;       /* v: unit direction toward the light's centre l */
    float light_dist;     /* ||l - o|| (world units): the ray stops there */
    float light_diameter; /* D (world units) */
    OuterCombine combine;
    OuterFalloff falloff;
} OuterRay;

/* Parker's ratio (seed 002 §3, appendix): the outer object of an occluder
 * t0 from the receiver along a shadow ray of length L = ||l - o|| has size
 * b = D t0 / L (similar triangles through the light's rim), so b / D = t0 / L.
 * Every outer-penumbra method scales by it: single_sample_rt's shells, and
 * smoothies' alpha / (1 - z_s / z_r) (Chan & Durand 2003), which is alpha
 * over this ratio with t0 = z_r - z_s, L = z_r along the light's axis.
 * The caller keeps L > 0. */
static inline float parker_ratio(float t0, float light_dist) { return t0 / light_dist; }

/* D, the light's diameter as seed 002 uses it ("roughly spherical lights"),
 * world units: 2R for spheres and disks; a rectangle's mean width. */
float outer_light_diameter(const Light *light);

/* The outer objects of every caster: an analytic sphere for each caster with
 * is_sphere when `analytic_spheres`, else (and for every other caster) one
 * outer triangle per mesh triangle. They do not depend on the light: b is
 * formed per ray. */
OuterScene *outer_scene_create(const Scene *scene, bool analytic_spheres, Error *err);
void outer_scene_release(OuterScene *os);
size_t outer_scene_bytes(const OuterScene *os);
int outer_scene_spheres(const OuterScene *os);
int outer_scene_triangles(const OuterScene *os);

/* Combined attenuation s in [0, 1] of the outer objects along the ray: 1 when
 * none is grazed, or when D or ||l - o|| is 0. Thread-safe. */
float outer_scene_attenuation(const OuterScene *os, const OuterRay *ray);

/* tau of one occluder for the ray: 0 on or inside the inner object, in
 * (0, 1) inside the outer shell, >= 1 (or +inf) when it does not shadow.
 * The sphere (centre c, radius R) follows the appendix exactly. Neither
 * divides by zero: t0 -> 0, ||l - o|| -> 0 and b -> 0 give +inf. */
float outer_sphere_tau(vec3 c_world, float radius, const OuterRay *ray);
float outer_triangle_tau(vec3 p0, vec3 p1, vec3 p2, const OuterRay *ray);
/* s(tau) in [0, 1]; tau outside [0, 1] (and NaN) clamps. */
float outer_falloff(float tau, OuterFalloff falloff);
float outer_combine(float s_so_far, float s_next, OuterCombine combine);

#endif
