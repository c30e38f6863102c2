/* view.c -- primary rays from a pinhole camera (see view.h). */
#include "rt/view.h"
#include <math.h>
#include <stdlib.h>

typedef struct CameraFrame { vec3 forward, right, up; float tan_half_y, aspect; } CameraFrame;

static CameraFrame camera_frame(const Camera *c, int grid_w, int grid_h)
{
    CameraFrame f;
    f.forward = v3_normalize_or(v3_sub(c->target, c->position), v3(0, 0, -1));
    f.right = v3_normalize_or(v3_cross(f.forward, c->up), v3(1, 0, 0));
    f.up = v3_cross(f.right, f.forward);
    f.tan_half_y = tanf(0.5f * c->fov_y_rad);
    f.aspect = (float)grid_w / (float)grid_h;
    return f;
}

static vec3 frame_dir(const CameraFrame *f, int grid_w, int grid_h, int x, int y)
{
    float sx = (2.0f * ((float)x + 0.5f) / (float)grid_w - 1.0f) * f->tan_half_y * f->aspect;
    float sy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)grid_h) * f->tan_half_y;
    vec3 d = v3_add(f->forward, v3_add(v3_scale(f->right, sx), v3_scale(f->up, sy)));
    return v3_normalize_or(d, f->forward);
}

void camera_axes(const Camera *cam, int grid_w, int grid_h, vec3 *forward, vec3 *right, vec3 *up, float *tan_x,
                 float *tan_y)
{
    CameraFrame f = camera_frame(cam, grid_w, grid_h);
    *forward = f.forward;
    *right = f.right;
    *up = f.up;
    *tan_x = f.tan_half_y * f.aspect;
    *tan_y = f.tan_half_y;
}

void camera_ray(const Camera *cam, int grid_w, int grid_h, int x, int y, vec3 *org, vec3 *dir)
{
    CameraFrame f = camera_frame(cam, grid_w, grid_h);
    *org = cam->position;
    *dir = frame_dir(&f, grid_w, grid_h, x, y);
}

static bool alloc_samples(ViewSamples *vs, int w, int h, Error *err)
{
    size_t n = (size_t)w * (size_t)h;
    vs->width = w;
    vs->height = h;
    vs->count = (int)n;
    vs->p_world = malloc(n * sizeof(vec3));
    vs->n_geom_world = malloc(n * sizeof(vec3));
    vs->n_shading_world = malloc(n * sizeof(vec3));
    vs->depth_view = malloc(n * sizeof(float));
    vs->object = malloc(n * sizeof(int32_t));
    vs->prim = malloc(n * sizeof(int32_t));
    if (vs->p_world && vs->n_geom_world && vs->n_shading_world && vs->depth_view && vs->object && vs->prim) return true;
    view_samples_free(vs);
    return error_set(err, "out of memory for %dx%d view samples", w, h);
}

/* Barycentric interpolation of vertex normals of triangle prim. */
static vec3 shading_normal(const Mesh *m, unsigned prim, float u, float v, vec3 n_geom)
{
    const uint32_t *t = &m->indices[3 * prim];
    vec3 n = v3_add(v3_scale(m->normals[t[0]], 1.0f - u - v),
                    v3_add(v3_scale(m->normals[t[1]], u), v3_scale(m->normals[t[2]], v)));
    n = v3_normalize_or(n, n_geom);
    return v3_dot(n, n_geom) < 0.0f ? v3_scale(n, -1.0f) : n;
}

static void store_hit(ViewSamples *vs, int s, const Scene *scene, const RtScene *rs, const struct RTCRayHit *rh,
                      vec3 org, vec3 dir, vec3 forward)
{
    int obj = rt_scene_object(rs, rh->hit.geomID);
    vs->object[s] = obj;
    vs->prim[s] = (int32_t)rh->hit.primID;
    vec3 ng = v3_normalize_or(v3(rh->hit.Ng_x, rh->hit.Ng_y, rh->hit.Ng_z), v3_scale(dir, -1.0f));
    if (v3_dot(ng, dir) > 0.0f) ng = v3_scale(ng, -1.0f);
    vs->n_geom_world[s] = ng;
    vs->n_shading_world[s] = shading_normal(&scene->objects[obj].mesh, rh->hit.primID, rh->hit.u, rh->hit.v, ng);
    vs->p_world[s] = v3_madd(org, dir, rh->ray.tfar);
    vs->depth_view[s] = rh->ray.tfar * v3_dot(dir, forward);
}

bool view_samples_trace(const RtScene *rs, const Scene *scene, ViewSamples *vs, Error *err)
{
    const Camera *cam = &scene->camera;
    int w = cam->width * cam->supersample, h = cam->height * cam->supersample;
    if (!alloc_samples(vs, w, h, err)) return false;
    CameraFrame f = camera_frame(cam, w, h);
    RTCScene rtc = rt_scene_handle(rs);
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < h; y++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        for (int x = 0; x < w; x++) {
            int s = y * w + x;
            vec3 dir = frame_dir(&f, w, h, x, y);
            float cos_axis = fmaxf(v3_dot(dir, f.forward), 1e-6f); /* near/far are along the view axis */
            struct RTCRayHit rh = {0};
            rh.ray.org_x = cam->position.x; rh.ray.org_y = cam->position.y; rh.ray.org_z = cam->position.z;
            rh.ray.dir_x = dir.x; rh.ray.dir_y = dir.y; rh.ray.dir_z = dir.z;
            rh.ray.tnear = cam->near_dist / cos_axis;
            rh.ray.tfar = cam->far_dist / cos_axis;
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rt_intersect1(rtc, &ctx, &rh);
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                vs->object[s] = vs->prim[s] = -1;
                vs->p_world[s] = vs->n_geom_world[s] = vs->n_shading_world[s] = v3(0, 0, 0);
                vs->depth_view[s] = INFINITY;
            } else {
                store_hit(vs, s, scene, rs, &rh, cam->position, dir, f.forward);
            }
        }
    }
    return true;
}

void view_samples_free(ViewSamples *vs)
{
    free(vs->p_world);
    free(vs->n_geom_world);
    free(vs->n_shading_world);
    free(vs->depth_view);
    free(vs->object);
    free(vs->prim);
    *vs = (ViewSamples){0};
}

size_t view_samples_bytes(const ViewSamples *vs)
{
    return (size_t)vs->count * (3 * sizeof(vec3) + sizeof(float) + 2 * sizeof(int32_t));
}

void view_samples_classify(const ViewSamples *vs, const Scene *scene, int light_index, uint8_t *cls)
{
    const Light *l = &scene->lights[light_index];
#pragma omp parallel for schedule(static)
    for (int s = 0; s < vs->count; s++) {
        int obj = vs->object[s];
        if (obj < 0) cls[s] = SAMPLE_BACKGROUND;
        else if (!scene->objects[obj].receiver) cls[s] = SAMPLE_NOT_RECEIVER;
        else cls[s] = (uint8_t)light_classify(l, vs->p_world[s], vs->n_geom_world[s]);
    }
}
