/* lightview.h -- how a light sees the scene for a shadow map: the projection
 * of each map face (spot: perspective; directional: orthographic; point:
 * six-face cube or dual paraboloid, course §2.1.1) fitted to a target
 * (the scene's bounds, or the receivers the camera sees, read exactly from
 * the view samples as sample-distribution shadow maps do), and the lookup
 * of a world point in the map: face, texel coordinates, reference depth.
 *
 * Spaces: world; light view (right-handed, looking down -z, one per face);
 * clip/NDC (0 <= z_ndc <= 1); map texel coordinates (s, t) in [0, res) with
 * texel i's centre at s = i + 0.5 and row 0 at y_ndc = -1. "Linear depth"
 * is the view depth -z_view of the face (world units), or for paraboloid
 * faces the distance to the light's centre. */
#ifndef SL_LIGHTVIEW_H
#define SL_LIGHTVIEW_H
#include "raster/raster.h"
#include "rt/view.h"

#define LIGHTVIEW_MAX_FACES 16

typedef enum MapProjection {
    MAP_PROJ_AUTO,        /* spot: perspective; directional: ortho; point, sphere: perspective if the
                             target fits in a 150-degree cone, else cube; rect, disk: perspective */
    MAP_PROJ_PERSPECTIVE,
    MAP_PROJ_ORTHO,
    MAP_PROJ_CUBE,
    MAP_PROJ_PARABOLOID,
} MapProjection;
#define MAP_PROJ_NAMES "auto", "perspective", "ortho", "cube", "paraboloid"

typedef enum MapFit {
    MAP_FIT_SCENE, /* the bounds of all geometry */
    MAP_FIT_VIEW,  /* the visible lit-candidate view samples (depth range starts at the casters) */
    MAP_FIT_NONE,  /* the light's own frustum: a spot's cone, the scene's bounding sphere */
} MapFit;
#define MAP_FIT_NAMES "scene", "view", "none"

typedef struct MapFace {
    RasterView raster;     /* clip_from_world (or view for paraboloid), depth_row, depth range */
    mat4 view_from_world;  /* the face's light view space */
    mat4 world_from_clip;  /* unprojection (projective faces) */
    bool perspective;      /* w = view depth */
    bool paraboloid;
    /* Extents on the plane at unit view depth (perspective: tangents; ortho:
     * world units at any depth): x in [l, r], y in [b, t]. */
    double l, r, b, t;
    dvec3 axis_world;      /* the direction the face looks (unit) */
} MapFace;

typedef struct LightView {
    MapProjection projection; /* resolved, never AUTO */
    int res;                  /* texels per side of each face */
    int guard;                /* cube faces: texels beyond the 90-degree frustum on each side */
    int num_faces;
    MapFace face[LIGHTVIEW_MAX_FACES];
    dvec3 origin_world;       /* the light's centre (not used by ortho lookups) */
    dvec3 cube_axes[3];       /* cube/paraboloid: the world axes faces are chosen by */
} LightView;

/* Fit the map of `light` to the target given by `fit`. `vs` and `cls` are
 * needed only for MAP_FIT_VIEW (else NULL). */
bool lightview_fit(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                   const ViewSamples *vs, const uint8_t *cls, LightView *lv, Error *err);

/* Where a world point falls in the map. */
typedef struct MapCoord {
    int face;
    double s, t;         /* texel coordinates in [0, res) when inside */
    double depth_linear; /* view depth (or radial distance for paraboloid faces), world units */
    double z_ndc;        /* post-projective depth of the same point */
    bool inside;         /* within the face's texels and depth range */
} MapCoord;

MapCoord lightview_locate(const LightView *lv, dvec3 p_world);
/* Map texel coordinates of a world point on a given face (no face choice). */
MapCoord lightview_locate_on(const LightView *lv, int face, dvec3 p_world);
/* The world-space ray through map texel coordinates (s, t) of a face:
 * origin (on the near plane, or the centre for paraboloids) and unit direction. */
void lightview_texel_ray(const LightView *lv, int face, double s, double t, dvec3 *org, dvec3 *dir);
/* World size of one texel at the point (perpendicular to the light's rays). */
double lightview_texel_world(const LightView *lv, const MapCoord *mc);
/* d z_ndc / d depth_linear at the point: converts world-unit biases to NDC. */
double lightview_ndc_per_world(const LightView *lv, const MapCoord *mc);

const char *map_projection_name(MapProjection p);
const char *map_fit_name(MapFit f);

#endif
