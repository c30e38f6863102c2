/* clip.c -- Sutherland-Hodgman in homogeneous coordinates (see clip.h). */
#include "raster/clip.h"
#include <string.h>

/* Signed distance of v to plane i (>= 0 inside): w+x, w-x, w+y, w-y, z, w-z. */
static double plane_dist(const ClipVertex *v, int i)
{
    switch (i) {
    case 0: return v->w + v->x;
    case 1: return v->w - v->x;
    case 2: return v->w + v->y;
    case 3: return v->w - v->y;
    case 4: return v->z;
    default: return v->w - v->z;
    }
}

unsigned clip_outcode(const ClipVertex *v, ClipPlanes planes)
{
    if (planes == CLIP_FRONT_ONLY) return v->z < 0.0 ? 1u << 4 : 0u;
    unsigned code = 0;
    for (int i = 0; i < 6; i++)
        if (plane_dist(v, i) < 0.0) code |= 1u << i;
    return code;
}

/* Lexicographic order of the coordinates: the canonical direction of an edge. */
static bool vertex_less(const ClipVertex *a, const ClipVertex *b)
{
    if (a->x != b->x) return a->x < b->x;
    if (a->y != b->y) return a->y < b->y;
    if (a->z != b->z) return a->z < b->z;
    return a->w < b->w;
}

/* The point of edge (p, q) on plane i, from the canonical endpoint. */
static ClipVertex intersect(const ClipVertex *p, const ClipVertex *q, int i)
{
    const ClipVertex *lo = vertex_less(p, q) ? p : q, *hi = lo == p ? q : p;
    double dl = plane_dist(lo, i), dh = plane_dist(hi, i);
    double t = dl / (dl - dh); /* dl and dh have opposite signs here, so dl - dh != 0 */
    return (ClipVertex){lo->x + t * (hi->x - lo->x), lo->y + t * (hi->y - lo->y), lo->z + t * (hi->z - lo->z),
                        lo->w + t * (hi->w - lo->w), lo->a + t * (hi->a - lo->a)};
}

static int clip_plane(const ClipVertex *in, int n, int plane, ClipVertex *out)
{
    int m = 0;
    for (int k = 0; k < n; k++) {
        const ClipVertex *p = &in[k], *q = &in[(k + 1) % n];
        double dp = plane_dist(p, plane), dq = plane_dist(q, plane);
        if (dp >= 0.0) out[m++] = *p;
        if ((dp >= 0.0) != (dq >= 0.0)) out[m++] = intersect(p, q, plane);
    }
    return m;
}

int clip_triangle(const ClipVertex tri[3], unsigned crossing, ClipVertex *poly)
{
    ClipVertex buf[CLIP_MAX_VERTS];
    memcpy(poly, tri, 3 * sizeof *tri);
    int n = 3;
    for (int i = 0; i < 6 && n > 0; i++) {
        if (!(crossing & (1u << i))) continue;
        n = clip_plane(poly, n, i, buf);
        memcpy(poly, buf, (size_t)n * sizeof *buf);
    }
    return n;
}
