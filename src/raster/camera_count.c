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

/* Clip from world for the near caps: the camera's rows 0, 1 and 3 after
 * Blinn's shadow matrix S = (pi.L) I - L pi^T, which takes x along the line
 * from L onto the near plane pi (pi.x = f.x - f.e - n); row 2 is
 * C n (pi.x). Then w = n (pi.L - pi.x) for a point light, and 0 <= z <= w
 * keeps the slab 0 <= pi.x <= pi.L / (1 + C): the parts between the centre
 * and the near plane (with C = 1e-9, all but a 1e-9 sliver at the centre).
 * The rows are negated when pi.L < 0, so the slab is [pi.L, 0] and w > 0. */
#define NEAR_CAP_SLAB 1e-9
static mat4 near_cap_clip_from_world(const CameraCount *cc, const Camera *cam, const double L[4], double *pi_L)
{
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, cc->width, cc->height, &f, &r, &u, &tx, &ty);
    double pi[4] = {f.x, f.y, f.z,
                    -(f.x * (double)cam->position.x + f.y * (double)cam->position.y + f.z * (double)cam->position.z) -
                        cam->near_dist};
    *pi_L = pi[0] * L[0] + pi[1] * L[1] + pi[2] * L[2] + pi[3] * L[3];
    mat4 S;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) S.m[i][j] = (i == j ? *pi_L : 0.0) - L[i] * pi[j];
    mat4 M = m4_mul(&cc->view.clip_from_world, &S);
    double sign = *pi_L < 0.0 ? -1.0 : 1.0;
    for (int j = 0; j < 4; j++) M.m[2][j] = NEAR_CAP_SLAB * cam->near_dist * pi[j];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) M.m[i][j] *= sign;
    return M;
}

bool camera_count_near_caps(CameraCount *cc, const Camera *cam, const RasterMesh *caps, const RasterMeshExtra *extra,
                            const double L[4], RasterStats *stats, Error *err)
{
    double pi_L;
    RasterView view = cc->view;
    view.clip_from_world = near_cap_clip_from_world(cc, cam, L, &pi_L);
    if (stats) memset(stats, 0, sizeof *stats);
    if (pi_L == 0.0) return true;
    size_t n = (size_t)cc->width * (size_t)cc->height;
    float *all = malloc(n * sizeof *all);
    int32_t *count = calloc(n, sizeof *count);
    if (!all || !count) {
        free(all);
        free(count);
        return error_set(err, "out of memory for %dx%d near-cap counters", cc->width, cc->height);
    }
    for (size_t i = 0; i < n; i++) all[i] = -1.0f; /* below every z_ndc >= 0: each fragment counts */
    RasterOptions opt = {.cull = RASTER_CULL_NONE, .test = RASTER_COUNT_GREATER, .depth = RASTER_DEPTH_NDC,
                         .count_ref = all, .count = count, .extra = extra};
    bool ok = raster_depth(caps, 1, &view, &opt, &cc->db, stats, err);
    /* A cap turned toward L, projected from L, keeps its orientation seen
     * from L's side of the plane: counter-clockwise from the camera when L
     * is on the camera's side (pi.L < 0), clockwise otherwise. */
    int32_t sign = pi_L < 0.0 ? 1 : -1;
    for (size_t i = 0; ok && i < n; i++) {
        int64_t c = (int64_t)cc->count[i] + (int64_t)sign * count[i];
        if (c > INT32_MAX || c < INT32_MIN) ok = error_set(err, "ZP+: a near-plane count leaves int32");
        else cc->count[i] = (int32_t)c;
    }
    free(all);
    free(count);
    return ok;
}
