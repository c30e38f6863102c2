/* mat4.h -- 4x4 projective transforms in double precision, for light
 * projections (perspective, orthographic, warped) and their inverses.
 * Column-vector convention: p' = M p, M.m[row][col]; A * B applies B first.
 * Camera-like spaces are right-handed and look down -z (OpenGL style); clip
 * space keeps 0 <= z <= w (Vulkan/D3D depth range), so z_ndc = z/w is 0 at
 * the near plane and 1 at the far plane. */
#ifndef SL_MAT4_H
#define SL_MAT4_H
#include <stdbool.h>
#include "core/vec.h"

typedef struct dvec3 { double x, y, z; } dvec3;
typedef struct dvec4 { double x, y, z, w; } dvec4;
typedef struct mat4 { double m[4][4]; } mat4;

static inline dvec3 d3(double x, double y, double z) { return (dvec3){x, y, z}; }
static inline dvec3 d3_from(vec3 v) { return (dvec3){v.x, v.y, v.z}; }
static inline vec3 d3_to_f(dvec3 v) { return v3((float)v.x, (float)v.y, (float)v.z); }
static inline dvec3 d3_add(dvec3 a, dvec3 b) { return d3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline dvec3 d3_sub(dvec3 a, dvec3 b) { return d3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline dvec3 d3_scale(dvec3 a, double s) { return d3(a.x * s, a.y * s, a.z * s); }
static inline dvec3 d3_madd(dvec3 a, dvec3 b, double s) { return d3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline double d3_dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline dvec3 d3_cross(dvec3 a, dvec3 b)
{
    return d3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double d3_len(dvec3 a) { return sqrt(d3_dot(a, a)); }
/* Unit vector, or `fallback` when |a| is zero or not finite. */
static inline dvec3 d3_normalize_or(dvec3 a, dvec3 fallback)
{
    double l = d3_len(a);
    return (l > 0.0 && isfinite(l)) ? d3_scale(a, 1.0 / l) : fallback;
}

static inline mat4 m4_identity(void)
{
    return (mat4){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
}

static inline dvec4 m4_apply(const mat4 *M, dvec3 p)
{
    const double(*m)[4] = M->m;
    return (dvec4){m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                   m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                   m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3],
                   m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3]};
}

static inline dvec4 m4_apply4(const mat4 *M, dvec4 p)
{
    const double(*m)[4] = M->m;
    return (dvec4){m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3] * p.w,
                   m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3] * p.w,
                   m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3] * p.w,
                   m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3] * p.w};
}

mat4 m4_mul(const mat4 *A, const mat4 *B);
/* false when M is singular (|det| below 1e-300 of its scale). */
bool m4_invert(const mat4 *M, mat4 *inv);

/* World -> camera-like space with the eye at `eye`, looking along unit
 * `forward` (-z), `up` chosen by the caller (any vector not parallel to
 * forward; a fallback axis is used when it is). */
mat4 m4_look(dvec3 eye, dvec3 forward, dvec3 up);
/* Off-centre perspective: extents l, r, b, t on the near plane at distance
 * n, far plane at f (0 < n < f): clip z in [0, w], w = -z_view. */
mat4 m4_frustum(double l, double r, double b, double t, double n, double f);
/* Orthographic box: x in [l, r], y in [b, t], view depth -z in [n, f]. */
mat4 m4_ortho(double l, double r, double b, double t, double n, double f);

#endif
