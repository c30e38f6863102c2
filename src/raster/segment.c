/* segment.c -- texels within a radius of a segment (segment.h). */
#include "raster/segment.h"
#include <math.h>

static int clamp_index(double x, int lo, int hi) { return x < lo ? lo : x > hi ? hi : (int)x; }

void raster_segment_band(const RasterGrid *g, const double a[2], const double b[2], double radius, int row_begin,
                         int row_end, RasterSegmentFn fn, void *user)
{
    double ex = b[0] - a[0], ey = b[1] - a[1], len2 = ex * ex + ey * ey;
    if (!(isfinite(len2) && radius >= 0.0 && isfinite(radius)) || !(g->dx > 0.0 && g->dy > 0.0)) return;
    /* The band's bounding box in texel indices: centre x0 + (i + 0.5) dx in
     * [min - radius, max + radius]. */
    double lo_x = fmin(a[0], b[0]) - radius, hi_x = fmax(a[0], b[0]) + radius;
    double lo_y = fmin(a[1], b[1]) - radius, hi_y = fmax(a[1], b[1]) + radius;
    int i0 = clamp_index(ceil((lo_x - g->x0) / g->dx - 0.5), 0, g->width);
    int i1 = clamp_index(floor((hi_x - g->x0) / g->dx - 0.5), -1, g->width - 1);
    int j0 = clamp_index(ceil((lo_y - g->y0) / g->dy - 0.5), row_begin, row_end);
    int j1 = clamp_index(floor((hi_y - g->y0) / g->dy - 0.5), row_begin - 1, row_end - 1);
    double r2 = radius * radius;
    for (int j = j0; j <= j1; j++) {
        double py = g->y0 + (j + 0.5) * g->dy - a[1];
        for (int i = i0; i <= i1; i++) {
            double px = g->x0 + (i + 0.5) * g->dx - a[0];
            /* Closest point a + u e: u = clamp((p - a) . e / |e|^2, 0, 1); len2 = 0 is the disc about a. */
            double u = len2 > 0.0 ? (px * ex + py * ey) / len2 : 0.0;
            u = u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
            double dx = px - u * ex, dy = py - u * ey, d2 = dx * dx + dy * dy;
            if (d2 <= r2) fn(user, i, j, u, sqrt(d2));
        }
    }
}
