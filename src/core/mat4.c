/* mat4.c -- products, inverse (Gauss-Jordan with partial pivoting) and the
 * camera/projection constructors of mat4.h. */
#include "core/mat4.h"
#include <string.h>

mat4 m4_mul(const mat4 *A, const mat4 *B)
{
    mat4 C;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++) s += A->m[i][k] * B->m[k][j];
            C.m[i][j] = s;
        }
    return C;
}

bool m4_invert(const mat4 *M, mat4 *inv)
{
    double a[4][8], scale = 0.0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            a[i][j] = M->m[i][j];
            a[i][j + 4] = i == j ? 1.0 : 0.0;
            scale = fmax(scale, fabs(M->m[i][j]));
        }
    if (!(scale > 0.0) || !isfinite(scale)) return false;
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
        if (!(fabs(a[piv][c]) > 1e-300 * scale)) return false;
        if (piv != c)
            for (int j = 0; j < 8; j++) {
                double t = a[c][j];
                a[c][j] = a[piv][j];
                a[piv][j] = t;
            }
        double d = 1.0 / a[c][c];
        for (int j = 0; j < 8; j++) a[c][j] *= d;
        for (int r = 0; r < 4; r++) {
            if (r == c || a[r][c] == 0.0) continue;
            double f = a[r][c];
            for (int j = 0; j < 8; j++) a[r][j] -= f * a[c][j];
        }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) inv->m[i][j] = a[i][j + 4];
    return true;
}

mat4 m4_look(dvec3 eye, dvec3 forward, dvec3 up)
{
    dvec3 f = d3_normalize_or(forward, d3(0, 0, -1));
    dvec3 s = d3_cross(f, up);
    if (!(d3_len(s) > 1e-9 * d3_len(up))) s = d3_cross(f, fabs(f.y) < 0.9 ? d3(0, 1, 0) : d3(1, 0, 0));
    s = d3_normalize_or(s, d3(1, 0, 0));
    dvec3 u = d3_cross(s, f); /* right-handed: x = s, y = u, z = -f */
    mat4 M = {{{s.x, s.y, s.z, -d3_dot(s, eye)},
               {u.x, u.y, u.z, -d3_dot(u, eye)},
               {-f.x, -f.y, -f.z, d3_dot(f, eye)},
               {0, 0, 0, 1}}};
    return M;
}

mat4 m4_frustum(double l, double r, double b, double t, double n, double f)
{
    mat4 M;
    memset(&M, 0, sizeof M);
    M.m[0][0] = 2.0 * n / (r - l);
    M.m[0][2] = (r + l) / (r - l);
    M.m[1][1] = 2.0 * n / (t - b);
    M.m[1][2] = (t + b) / (t - b);
    M.m[2][2] = f / (n - f);     /* z_ndc = 0 at -z = n, 1 at -z = f */
    M.m[2][3] = f * n / (n - f);
    M.m[3][2] = -1.0;            /* w = -z_view: the view depth */
    return M;
}

mat4 m4_ortho(double l, double r, double b, double t, double n, double f)
{
    mat4 M;
    memset(&M, 0, sizeof M);
    M.m[0][0] = 2.0 / (r - l);
    M.m[0][3] = -(r + l) / (r - l);
    M.m[1][1] = 2.0 / (t - b);
    M.m[1][3] = -(t + b) / (t - b);
    M.m[2][2] = -1.0 / (f - n);  /* z_ndc = (-z - n) / (f - n) */
    M.m[2][3] = -n / (f - n);
    M.m[3][3] = 1.0;
    return M;
}
