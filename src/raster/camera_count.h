/* camera_count.h -- the camera-space counting pass of shadow volumes (course
 * §2.2): world-space triangles (volume quads and caps, homogeneous vertices
 * allowed) drawn by the engine's rasterizer (raster.h, its clipping, snapping
 * and edge functions) with the camera's projection onto the view-sample grid,
 * each fragment tested against the sample's own depth and added to the
 * sample's int32 counter (+count front-facing, -count back-facing).
 *
 * Projection: an infinite reversed-z perspective (Everitt & Kilgard 2002's
 * infinite far plane, with depth stored as z_ndc = n / d for view depth d
 * and near distance n: 1 on the near plane, 0 at infinity), so a vertex at
 * infinity (w = 0) projects to a finite z and float keeps relative precision
 * at every distance. The near plane clips, as in a GPU's z-pass. */
#ifndef SL_CAMERA_COUNT_H
#define SL_CAMERA_COUNT_H
#include "raster/raster.h"
#include "rt/view.h"

typedef enum CountTest {
    COUNT_NEARER,  /* z-pass: fragments in front of the sample's test point */
    COUNT_FARTHER, /* z-fail: fragments behind it */
} CountTest;

typedef struct CameraCount {
    int width, height;      /* the view-sample grid */
    RasterView view;
    float *ref;             /* n / d_test per texel (raster rows: texel row j is sample row height-1-j) */
    int32_t *count;         /* per texel, raster rows */
    DepthBuffer db;         /* the rasterizer's working memory (no depth of its own) */
} CameraCount;

/* Set up the pass on the samples' grid; test_depth[s] is the view depth
 * (world units along the view axis) each sample is tested at (<= 0 or not
 * finite: at infinity, e.g. the background). Counters start at 0. */
bool camera_count_init(CameraCount *cc, const Camera *cam, const ViewSamples *vs, const float *test_depth, Error *err);
void camera_count_free(CameraCount *cc);

/* Add the meshes' fragments passing `test` to the counters. */
bool camera_count_render(CameraCount *cc, const RasterMesh *meshes, const RasterMeshExtra *extra, int num_meshes,
                         CountTest test, RasterStats *stats, Error *err);

/* ZP+ (Hornus et al. 2005; course §2.2): add to every counter the number of
 * volumes holding the sample's point on the near plane, so that z-pass is
 * right with the camera inside volumes. `caps` are the volumes' near caps
 * (triangles turned toward the homogeneous centre L, each with its count);
 * their parts between L and the near plane are projected from L onto the
 * near plane and drawn from the camera, each adding its count whatever its
 * orientation there. A centre on the near plane's plane adds nothing. */
bool camera_count_near_caps(CameraCount *cc, const Camera *cam, const RasterMesh *caps, const RasterMeshExtra *extra,
                            const double L[4], RasterStats *stats, Error *err);

/* The counter of view sample s (sample order: row 0 at the top). */
static inline int32_t camera_count_at(const CameraCount *cc, int s)
{
    int x = s % cc->width, y = s / cc->width;
    return cc->count[(size_t)(cc->height - 1 - y) * (size_t)cc->width + (size_t)x];
}

#endif
