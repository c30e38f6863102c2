/* raster.h -- the depth-only triangle rasterizer for light-space maps
 * (course §2.1: "render depth from the light"). Triangles are transformed
 * once per vertex, clipped in homogeneous space against the full frustum
 * (0 <= z <= w, |x|, |y| <= w), snapped to 8 sub-texel bits and filled with
 * exact integer edge functions and the top-left rule, so a closed mesh
 * covers each texel exactly once. Work is binned into 64x64-texel tiles and
 * the tiles are filled in parallel (OpenMP).
 *
 * Map space: texel (i, j) covers u in [i/W, (i+1)/W], v in [j/H, (j+1)/H]
 * with u = (x_ndc + 1)/2, v = (y_ndc + 1)/2; row j = 0 is v = 0 (y_ndc = -1,
 * the texture convention), and depth is sampled at texel centres.
 *
 * Counting (stencil-style, for shadow volumes, course §2.2): instead of
 * keeping a depth, each fragment whose value is below (or above) the texel's
 * reference value adds its triangle's signed count to the texel's int32
 * counter: +count where the triangle is counter-clockwise on the map
 * (front-facing), -count where it is clockwise. Vertices may be homogeneous
 * (w = 0: a point at infinity), so volumes extruded to infinity clip exactly
 * (Everitt & Kilgard 2002). */
#ifndef SL_RASTER_H
#define SL_RASTER_H
#include <stddef.h>
#include <stdint.h>
#include "core/error.h"
#include "core/mat4.h"

#define RASTER_MAX_SIZE 16384 /* texels per side */
#define RASTER_SUBPIXEL_BITS 8

/* One indexed triangle mesh in world space (CCW = front, right-hand rule). */
typedef struct RasterMesh {
    const vec3 *positions;
    const uint32_t *indices; /* 3 per triangle */
    int num_vertices, num_triangles;
} RasterMesh;

/* What a mesh may add for shadow volumes (RasterOptions.extra). */
typedef struct RasterMeshExtra {
    /* Homogeneous weight per vertex, the point (positions[i], weights[i]):
     * 0 is the point at infinity in direction positions[i]. NULL: all 1. */
    const float *weights;
    /* Counting tests: the signed count each triangle adds (NULL: all 1). */
    const int16_t *counts;
} RasterMeshExtra;

typedef enum RasterCull { RASTER_CULL_NONE, RASTER_CULL_BACK, RASTER_CULL_FRONT } RasterCull;
/* Which surface a texel keeps: the nearest (shadow maps) or the farthest
 * (back-face and farthest-layer maps). */
typedef enum RasterTest {
    RASTER_NEAREST,
    RASTER_FARTHEST,
    RASTER_COUNT_LESS,    /* count fragments whose value < RasterOptions.count_ref[texel] */
    RASTER_COUNT_GREATER, /* count fragments whose value > count_ref[texel] */
} RasterTest;
/* What a texel stores: linear depth (an affine function of the world
 * position, e.g. distance along the light's axis in world units) or the
 * post-projective z_ndc in [0, 1]. */
typedef enum RasterDepth { RASTER_DEPTH_LINEAR, RASTER_DEPTH_NDC } RasterDepth;
/* How vertices reach the map: a projective matrix (exact for triangles), or
 * the dual-paraboloid mapping of Brabec et al. (course §2.1.1): per vertex
 * only, so edges are straight in the map while they should be curved. */
typedef enum RasterMapping { RASTER_PROJECTIVE, RASTER_PARABOLOID } RasterMapping;

typedef struct RasterView {
    RasterMapping mapping;
    /* RASTER_PROJECTIVE: world -> clip. RASTER_PARABOLOID: world -> light view
     * space (right-handed, the hemisphere looks down -z). */
    mat4 clip_from_world;
    /* Linear depth of a world point, d = row . (x, y, z, 1), for
     * RASTER_PROJECTIVE (paraboloid maps store the distance to the centre). */
    double depth_row[4];
    double depth_near, depth_far; /* linear depth range (quantisation, paraboloid z) */
} RasterView;

typedef struct RasterOptions {
    RasterCull cull;
    RasterTest test;
    RasterDepth depth;
    int depth_bits;       /* 0: float32 as computed; 16 or 24: quantised over the range */
    bool conservative;    /* cover every texel the triangle touches (depth clamped to its range) */
    bool triangle_ids;    /* also store the winning triangle's index per texel */
    /* Depth peeling: when non-NULL (same size as the map), fragments at or in
     * front of peel[texel] + peel_epsilon are discarded (the test is strictly
     * greater), so the map keeps the next layer behind it. peel_epsilon is in
     * the map's value space (linear: world units along the light's axis;
     * ndc: z_ndc) and >= 0; 0 peels behind the exact values. */
    const float *peel;
    float peel_epsilon;
    /* Counting tests: the reference value per texel (same size and value
     * space as the map: linear depth or z_ndc), e.g. the view samples' own
     * depth. Fragments equal to it are not counted. */
    const float *count_ref;
    /* Counting tests: per texel, the counter the fragments add to. It is
     * not cleared: the caller sets the starting counts. An update that would
     * leave int32 is not made, and the render fails, saying how many. */
    int32_t *count;
    /* One per mesh, or NULL: every vertex weight 1, every count 1. */
    const RasterMeshExtra *extra;
} RasterOptions;

/* The output: depth per texel (+INFINITY where nothing was drawn with the
 * nearest test, -INFINITY with the farthest), and optionally triangle ids
 * (-1 where empty; ids count triangles across the meshes in order). */
typedef struct RasterScratch RasterScratch; /* opaque: raster.c */
typedef struct DepthBuffer {
    int width, height;
    float *depth;
    int32_t *triangle;
    /* Working memory raster_depth keeps between renders into this buffer
     * (transformed vertices, set-up triangles, tile bins: about 130 bytes
     * per triangle), so a sweep or a cube map's faces do not fault fresh
     * pages in at every render. NULL until the first render; released by
     * depth_buffer_free, or by raster_scratch_free for buffers whose depth
     * the caller owns. */
    RasterScratch *scratch;
} DepthBuffer;

/* What a render did, for records and benchmarks. */
typedef struct RasterStats {
    long triangles_in, triangles_culled, triangles_clipped, triangles_drawn;
    long texels_written;
} RasterStats;

#define RASTER_STREAM_MIN_BYTES ((size_t)32 << 20) /* maps larger (4096^2 floats) are stored around the caches */

/* Depth maps and triangle ids (depth_buffer_init's, the shadow-map
 * resource's) come from core/bufpool.h: each starts on a cache line and is
 * a whole number of lines long, so the tiles that different threads fill
 * share no line when a map row's tile spans start on one (a tile row is
 * four lines), and a map freed and allocated again at its size (the next
 * build of a sweep or a frame) reuses its pages. Free them with
 * bufpool_free (depth_buffer_free does). camera_count.c's counters are
 * still calloc'd. */
bool depth_buffer_init(DepthBuffer *db, int width, int height, bool triangle_ids, Error *err);
void depth_buffer_free(DepthBuffer *db);
void raster_scratch_free(RasterScratch *scratch);

/* Render the meshes into db (already sized; cleared here). */
bool raster_depth(const RasterMesh *meshes, int num_meshes, const RasterView *view, const RasterOptions *opt,
                  DepthBuffer *db, RasterStats *stats, Error *err);

/* Paraboloid mapping of a light-view-space point on the front (-z) hemisphere:
 * (x, y) / (1 + |z| / r) / r with r = |p|, the map's (x_ndc, y_ndc). */
static inline void paraboloid_ndc(dvec3 p_view, double *x_ndc, double *y_ndc, double *r)
{
    *r = d3_len(p_view);
    double k = *r > 0.0 ? 1.0 / (*r - p_view.z) : 0.0; /* -z >= 0 on the front hemisphere */
    *x_ndc = p_view.x * k;
    *y_ndc = p_view.y * k;
}

#endif
