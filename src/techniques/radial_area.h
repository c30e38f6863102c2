/* radial_area.h -- 2D geometry on a light's plane shared by the techniques
 * that measure a light's covered area edge by edge (Green's theorem over
 * the light, course §5.3.2): the wedge family (soft_shadow_volume.c) and
 * backprojection's contour occluders (backprojection.c, Guennebaud et al.
 * 2007). The covered area of a closed, oriented loop of edges a -> b is
 * the sum over its edges of the signed area of the triangle (0, a, b) cut
 * by the light, 0 any point of the plane: the loop's winding number about
 * x is the sum of the triangles' signed indicators at x, for every x. */
#ifndef SL_RADIAL_AREA_H
#define SL_RADIAL_AREA_H
#include <math.h>
#include <string.h>

typedef struct P2 { double x, y; } P2;
#define POLY_MAX 8 /* a rectangle cut by three half-planes, a triangle by four */

static inline double cross2(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }

/* Keep the part of the convex polygon where nx x + ny y + off >= 0
 * (Sutherland-Hodgman, one plane). */
static inline int clip_half_plane(P2 *poly, int n, double nx, double ny, double off)
{
    P2 out[POLY_MAX];
    int m = 0;
    for (int i = 0; i < n; i++) {
        P2 a = poly[i], b = poly[(i + 1) % n];
        double da = nx * a.x + ny * a.y + off, db = nx * b.x + ny * b.y + off;
        if (da >= 0.0 && m < POLY_MAX) out[m++] = a;
        if ((da >= 0.0) != (db >= 0.0) && m < POLY_MAX) {
            double t = da / (da - db); /* da != db: they have opposite signs */
            out[m++] = (P2){a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
        }
    }
    memcpy(poly, out, sizeof *poly * (size_t)m);
    return m;
}

static inline double angle_between(P2 a, P2 b) { return atan2(cross2(a, b), a.x * b.x + a.y * b.y); }

/* Signed area of triangle (0, a, b) cut by the disk of radius r at 0: the
 * sector where the segment is outside the disk, the triangle where inside
 * (the classic polygon-circle intersection, summed over a polygon's edges). */
static inline double tri_disk_area(P2 a, P2 b, double r)
{
    double r2 = r * r;
    P2 d = {b.x - a.x, b.y - a.y};
    double A = d.x * d.x + d.y * d.y, B = a.x * d.x + a.y * d.y, C = a.x * a.x + a.y * a.y - r2;
    if (C <= 0.0 && b.x * b.x + b.y * b.y <= r2) return 0.5 * cross2(a, b);
    double disc = B * B - A * C;
    if (A <= 0.0 || disc <= 0.0) return 0.5 * r2 * angle_between(a, b);
    double s = sqrt(disc), t1 = (-B - s) / A, t2 = (-B + s) / A;
    if (t2 <= 0.0 || t1 >= 1.0) return 0.5 * r2 * angle_between(a, b);
    t1 = t1 > 0.0 ? t1 : 0.0;
    t2 = t2 < 1.0 ? t2 : 1.0;
    P2 p1 = {a.x + d.x * t1, a.y + d.y * t1}, p2 = {a.x + d.x * t2, a.y + d.y * t2};
    return 0.5 * (r2 * angle_between(a, p1) + cross2(p1, p2) + r2 * angle_between(p2, b));
}

/* Signed area of triangle (0, a, b) cut by the square [-1, 1]^2 (0 its
 * centre): the triangle, made counter-clockwise, clipped to the square's
 * four sides, its shoelace area signed by the edge's orientation. */
static inline double tri_square_area(P2 a, P2 b)
{
    double s = cross2(a, b) >= 0.0 ? 1.0 : -1.0;
    P2 poly[POLY_MAX] = {{0.0, 0.0}, s > 0.0 ? a : b, s > 0.0 ? b : a};
    int n = 3;
    n = clip_half_plane(poly, n, 1.0, 0.0, 1.0);  /* x >= -1 */
    n = clip_half_plane(poly, n, -1.0, 0.0, 1.0); /* x <= 1 */
    n = clip_half_plane(poly, n, 0.0, 1.0, 1.0);  /* y >= -1 */
    n = clip_half_plane(poly, n, 0.0, -1.0, 1.0); /* y <= 1 */
    double area = 0.0;
    for (int i = 0; i < n; i++) area += 0.5 * cross2(poly[i], poly[(i + 1) % n]);
    return s * area;
}

#endif
