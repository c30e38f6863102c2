/* vec.h -- small value types for 3D math (float, as Embree stores geometry),
 * plus a 4x4 affine transform for procedural primitives. All inline. */
#ifndef SL_VEC_H
#define SL_VEC_H
#include <math.h>

typedef struct vec3 { float x, y, z; } vec3;

static inline vec3 v3(float x, float y, float z) { return (vec3){x, y, z}; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_madd(vec3 a, vec3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }
static inline int v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* Unit vector; returns `fallback` when |a| is zero or not finite, so callers
 * never divide by a zero length. */
static inline vec3 v3_normalize_or(vec3 a, vec3 fallback)
{
    float l = v3_len(a);
    return (l > 0.0f && isfinite(l)) ? v3_scale(a, 1.0f / l) : fallback;
}

/* Orthonormal basis (t, b) around unit n (Duff et al. 2017, branchless). */
static inline void v3_basis(vec3 n, vec3 *t, vec3 *b)
{
    float s = copysignf(1.0f, n.z);
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    *t = v3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    *b = v3(c, s + n.y * n.y * a, -n.y);
}

/* Row-major 3x4 affine transform: p' = M p + t. */
typedef struct mat34 { float m[3][4]; } mat34;

static inline mat34 m34_identity(void)
{
    return (mat34){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
}
static inline vec3 m34_point(const mat34 *M, vec3 p)
{
    return v3(M->m[0][0] * p.x + M->m[0][1] * p.y + M->m[0][2] * p.z + M->m[0][3],
              M->m[1][0] * p.x + M->m[1][1] * p.y + M->m[1][2] * p.z + M->m[1][3],
              M->m[2][0] * p.x + M->m[2][1] * p.y + M->m[2][2] * p.z + M->m[2][3]);
}
/* A * B (apply B first). */
static inline mat34 m34_mul(const mat34 *A, const mat34 *B)
{
    mat34 C;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            float s = j == 3 ? A->m[i][3] : 0.0f;
            for (int k = 0; k < 3; k++) s += A->m[i][k] * B->m[k][j];
            C.m[i][j] = s;
        }
    }
    return C;
}

#endif
