/* camera_count.c -- the camera's counting pass (see camera_count.h). */
#include "raster/camera_count.h"
#include <stdlib.h>
#include <string.h>

/* World -> clip: x = right.(p - e h) / tan_x, y = up.(p - e h) / tan_y,
 * z = n h, w = forward.(p - e h) = d h, so x/w, y/w are the grid's NDC
 * (camera_axes) and z/w = n / d. */
static mat4 camera_clip_from_world(const Camera *cam, int w, int h)
{
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, w, h, &f, &r, &u, &tx, &ty);
    dvec3 e = d3_from(cam->position), df = d3_from(f), dr = d3_scale(d3_from(r), 1.0 / tx),
          du = d3_scale(d3_from(u), 1.0 / ty);
    return (mat4){{{dr.x, dr.y, dr.z, -d3_dot(dr, e)},
                   {du.x, du.y, du.z, -d3_dot(du, e)},
                   {0.0, 0.0, 0.0, cam->near_dist},
                   {df.x, df.y, df.z, -d3_dot(df, e)}}};
}

bool camera_count_init(CameraCount *cc, const Camera *cam, const ViewSamples *vs, const float *test_depth, Error *err)
{
    memset(cc, 0, sizeof *cc);
    if (!(cam->near_dist > 0.0f)) return error_set(err, "camera near = %g: the counting pass needs near > 0", cam->near_dist);
    size_t n = (size_t)vs->count;
    cc->width = vs->width;
    cc->height = vs->height;
    cc->ref = malloc(n * sizeof *cc->ref);
    cc->count = calloc(n, sizeof *cc->count);
    if (!cc->ref || !cc->count) {
        camera_count_free(cc);
        return error_set(err, "out of memory for %dx%d shadow-volume counters", vs->width, vs->height);
    }
    for (int s = 0; s < vs->count; s++) {
        int x = s % vs->width, y = s / vs->width;
        float d = test_depth[s];
        cc->ref[(size_t)(vs->height - 1 - y) * (size_t)vs->width + (size_t)x] =
            d > 0.0f && isfinite(d) ? cam->near_dist / d : 0.0f; /* n / d; 0: at infinity */
    }
    cc->view = (RasterView){.mapping = RASTER_PROJECTIVE,
                            .clip_from_world = camera_clip_from_world(cam, vs->width, vs->height),
                            .depth_near = cam->near_dist,
                            .depth_far = INFINITY};
    cc->db = (DepthBuffer){.width = vs->width, .height = vs->height};
    return true;
}

void camera_count_free(CameraCount *cc)
{
    free(cc->ref);
    free(cc->count);
    raster_scratch_free(cc->db.scratch);
    memset(cc, 0, sizeof *cc);
}

bool camera_count_render(CameraCount *cc, const RasterMesh *meshes, const RasterMeshExtra *extra, int num_meshes,
                         CountTest test, RasterStats *stats, Error *err)
{
    /* z_ndc = n / d grows toward the camera: nearer is greater */
    RasterOptions opt = {.cull = RASTER_CULL_NONE,
                         .test = test == COUNT_NEARER ? RASTER_COUNT_GREATER : RASTER_COUNT_LESS,
                         .depth = RASTER_DEPTH_NDC,
                         .count_ref = cc->ref,
                         .count = cc->count,
                         .extra = extra};
    return raster_depth(meshes, num_meshes, &cc->view, &opt, &cc->db, stats, err);
}
