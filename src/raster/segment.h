/* segment.h -- the light-space primitive of the outer-penumbra methods
 * (course §5.3.1: smoothies' quads and corner fans, penumbra maps' sheets
 * and cones): every texel of a map face whose centre lies within a radius of
 * a segment, visited with the closest point's parameter along the segment
 * and the distance to it. The band of a segment is the union of the quad
 * extruded on both sides of it and the discs about its ends, so the
 * segments of a silhouette polyline, drawn each with its own fragments and
 * blended by the caller (smoothies: min of alpha), cover the quads and the
 * fans at its vertices with no gap and no seam.
 *
 * Plane: texel (i, j) of a grid has its centre at (x0 + (i + 0.5) dx,
 * y0 + (j + 0.5) dy) in the plane's own units (a perspective face's tangent
 * plane at unit depth: softmap.h's frame), so distances are isotropic even
 * where dx != dy. */
#ifndef SL_SEGMENT_H
#define SL_SEGMENT_H

typedef struct RasterGrid {
    int width, height;
    double x0, y0, dx, dy;
} RasterGrid;

/* A fragment: texel (i, j), u in [0, 1] the parameter of the segment's
 * closest point to the texel centre, dist the distance to it (plane units). */
typedef void (*RasterSegmentFn)(void *user, int i, int j, double u, double dist);

/* Visit, in rows [row_begin, row_end) of g, every texel whose centre is
 * within `radius` (plane units, inclusive) of the segment a-b (a == b: a
 * disc). Rows are the caller's unit of parallelism: bands of rows drawn by
 * different threads write disjoint texels. Non-finite input draws nothing. */
void raster_segment_band(const RasterGrid *g, const double a[2], const double b[2], double radius, int row_begin,
                         int row_end, RasterSegmentFn fn, void *user);

#endif
