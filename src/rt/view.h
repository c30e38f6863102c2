/* view.h -- view samples: one Embree primary ray per sample (n x n per pixel
 * with supersampling) giving each sample's world position, geometric and
 * shading normals (both turned to face the camera), object id and view depth.
 * Arrays are indexed by sample s = y * width + x, row 0 at the top. */
#ifndef SL_VIEW_H
#define SL_VIEW_H
#include <stdint.h>
#include "rt/rt.h"
#include "scene/light.h"

typedef struct ViewSamples {
    int width, height;     /* sample grid: camera size x supersample */
    int count;             /* width * height */
    vec3 *p_world;         /* hit position (world) */
    vec3 *n_geom_world;    /* unit geometric normal, facing the camera */
    vec3 *n_shading_world; /* unit interpolated vertex normal, same hemisphere */
    float *depth_view;     /* distance along the camera's view axis (world units) */
    int32_t *object;       /* object index, -1 for background */
    int32_t *prim;         /* triangle index within the object's mesh */
} ViewSamples;

bool view_samples_trace(const RtScene *all, const Scene *scene, ViewSamples *vs, Error *err);
void view_samples_free(ViewSamples *vs);
size_t view_samples_bytes(const ViewSamples *vs);

/* Class of every sample with respect to light `light_index` (see light.h). */
void view_samples_classify(const ViewSamples *vs, const Scene *scene, int light_index, uint8_t *cls);

/* The camera's frame (world, unit, right-handed: right x up = -forward) and
 * the grid's image-plane half extents: sample (x, y) looks along forward +
 * right x_ndc tan_x + up y_ndc tan_y, x_ndc = 2 (x + 1/2) / grid_w - 1,
 * y_ndc = 1 - 2 (y + 1/2) / grid_h. */
void camera_axes(const Camera *cam, int grid_w, int grid_h, vec3 *forward, vec3 *right, vec3 *up, float *tan_x,
                 float *tan_y);

/* World-space ray through sample (x, y) of the grid: origin and unit direction. */
void camera_ray(const Camera *cam, int grid_w, int grid_h, int x, int y, vec3 *org, vec3 *dir);

#endif
