/* scene.h -- the scene model: objects (world-space triangle meshes with
 * caster/receiver flags and albedo), a pinhole camera and lights. Built by
 * scene_load() from a sandboxed Lua scene file (scene_lua.c); immutable after.
 * Units: world units for lengths, degrees in scene files, radians here. */
#ifndef SL_SCENE_H
#define SL_SCENE_H
#include <stdint.h>
#include "core/error.h"
#include "core/image.h"
#include "core/vec.h"
#include "scene/mesh.h"

#define SCENE_NAME_MAX 128
#define SCENE_PATH_MAX 1024

typedef struct Object {
    char name[SCENE_NAME_MAX];
    char source[SCENE_PATH_MAX]; /* model file used, or "procedural:<shape>" */
    Mesh mesh;                   /* world space */
    vec3 albedo;                 /* diffuse reflectance, [0,1]^3 */
    bool caster, receiver;
    /* The analytic sphere the mesh tessellates, for techniques that treat
     * spheres exactly (seed 002's appendix): set for a procedural sphere under
     * a uniform scale; the mesh stays the geometry everyone else traces. */
    bool is_sphere;
    vec3 sphere_center_world;
    float sphere_radius_world;
} Object;

typedef struct Camera {
    vec3 position, target, up; /* world */
    float fov_y_rad;           /* vertical field of view */
    float near_dist, far_dist; /* view-space distances along the view axis */
    int width, height;         /* pixels */
    int supersample;           /* view samples per pixel side (n x n) */
} Camera;

/* Typed light kinds (the string names are in scene_lua.c's table). */
typedef enum LightKind {
    LIGHT_POINT,
    LIGHT_SPOT,
    LIGHT_DIRECTIONAL,
    LIGHT_SPHERE,
    LIGHT_RECT,
    LIGHT_DISK,
    LIGHT_TEXTURED_RECT,
} LightKind;

typedef struct Light {
    LightKind kind;
    vec3 position;      /* point, spot, sphere: centre; rect, disk: centre (world) */
    vec3 direction;     /* spot: cone axis; directional: direction light travels;
                           rect, disk: emitting normal (unit) */
    vec3 up;            /* rect: in-plane "up" (height axis), orthonormalised */
    float radius;       /* sphere, disk (world units) */
    float width, height;/* rect (world units) */
    float cone_half_rad;/* spot: half-angle of the cone */
    vec3 color;         /* linear RGB */
    float intensity;    /* radiance scale (area lights) or W/sr (point, spot), irradiance (directional) */
    char image_path[SCENE_PATH_MAX]; /* textured rect */
    Image emission;     /* textured rect: RGB image over the rectangle, row 0 at +up edge */
} Light;

typedef struct Scene {
    char name[SCENE_NAME_MAX];
    char path[SCENE_PATH_MAX];
    Object *objects;
    int num_objects;
    Light *lights;
    int num_lights;
    Camera camera;
    vec3 bounds_min, bounds_max; /* world AABB of all geometry */
    uint64_t hash_geometry;      /* every object's triangles and flags */
    uint64_t hash_casters;       /* caster triangles only */
    uint64_t hash_camera;
    uint64_t *hash_lights;       /* one per light */
    uint64_t hash;               /* everything */
    int num_triangles;
} Scene;

/* Load and validate a scene file; `overrides` are "key.path=value" strings
 * (e.g. "lights[1].radius=0.3") applied before validation. */
bool scene_load(const char *path, const char *const *overrides, int num_overrides, Scene *scene, Error *err);
void scene_free(Scene *scene);

/* Diagonal of the scene's bounding box (world units), >= 1e-30. */
float scene_extent(const Scene *scene);
bool scene_all_cast(const Scene *scene);
const char *light_kind_name(LightKind kind);

/* Procedural primitives (primitives.c), in object space before transforms. */
bool prim_plane(Mesh *m, float size_x, float size_z, Error *err);
bool prim_box(Mesh *m, vec3 size, Error *err);
bool prim_sphere(Mesh *m, float radius, int segments, Error *err);
bool prim_cylinder(Mesh *m, float radius, float height, int segments, Error *err);
bool prim_cone(Mesh *m, float radius, float height, int segments, Error *err);
bool prim_torus(Mesh *m, float major, float minor, int segments, Error *err);
bool prim_disk(Mesh *m, float radius, int segments, Error *err);
/* A grid of (nx+1) x (nz+1) vertices over size_x x size_z, heights given. */
bool prim_heightfield(Mesh *m, float size_x, float size_z, int nx, int nz, const float *heights, Error *err);

#endif
