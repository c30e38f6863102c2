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
/* Fitted maps cover their target with this border (texels) on every side. */
#define LIGHTVIEW_MARGIN_TEXELS 2.0

typedef enum MapProjection {
    MAP_PROJ_AUTO,        /* spot: perspective; directional: ortho; point, sphere: perspective if the
                             target fits in a 150-degree cone, else cube; rect, disk: perspective */
    MAP_PROJ_PERSPECTIVE,
    MAP_PROJ_ORTHO,
    MAP_PROJ_CUBE,
    MAP_PROJ_PARABOLOID,
    /* Warped single maps (course §3.2.2) on a base projection (ortho for a
     * directional light, else the light's perspective): */
    MAP_PROJ_PSM,         /* Stamminger & Drettakis 2002: the map taken in the eye's post-perspective space */
    MAP_PROJ_LISPSM,      /* Wimmer et al. 2004: a perspective warp along the light plane, free n */
    MAP_PROJ_TSM,         /* Martin & Tan 2004: the same warp with n from the 80% focus rule */
    MAP_PROJ_LOGPSM,      /* Lloyd et al. 2008: perspective across, logarithmic along the warp axis (ray cast) */
} MapProjection;
#define MAP_PROJ_NAMES "auto", "perspective", "ortho", "cube", "paraboloid", "psm", "lispsm", "tsm", "logpsm"
#define MAP_PROJ_COUNT 9

typedef enum MapFit {
    MAP_FIT_SCENE, /* the bounds of all geometry */
    MAP_FIT_VIEW,  /* the visible lit-candidate view samples (depth range starts at the casters) */
    MAP_FIT_NONE,  /* the light's own frustum: a spot's cone, the scene's bounding sphere */
    MAP_FIT_BODY,  /* the intersection body B: view frustum inside the scene's bounds (course §3.2.1) */
    MAP_FIT_BODY_VISIBLE, /* B with its far plane at the farthest visible sample (exact on the CPU) */
} MapFit;
#define MAP_FIT_NAMES "scene", "view", "none", "body", "body_visible"
#define MAP_FIT_COUNT 5

/* How a perspective warp's n follows the angle gamma between the view and
 * light directions (course §3.2.2.3); zero is Lloyd's, the cookbook's pick. */
typedef enum WarpFalloff {
    WARP_FALLOFF_LLOYD,     /* Lloyd 2007 thesis §5.2.1: eta(gamma), uniform below theta/3 */
    WARP_FALLOFF_SIN_GAMMA, /* Wimmer 2004: n_opt / sin(gamma) */
    WARP_FALLOFF_NONE,      /* n_opt at every angle */
} WarpFalloff;
#define WARP_FALLOFF_NAMES "lloyd", "sin_gamma", "none"

/* Z-partitioning split positions C_i (course §3.2.3.1). */
typedef enum SplitScheme {
    SPLIT_PRACTICAL, /* Zhang et al. 2006: lambda log + (1 - lambda) uniform */
    SPLIT_LOG,       /* Lloyd et al. 2006: C_i = z_n (z_f / z_n)^(i / m) */
    SPLIT_UNIFORM,   /* C_i = z_n + (z_f - z_n) i / m */
    SPLIT_EXPLICIT,  /* C_1..C_(m-1) given as view depths (LightViewParams.split_at, world units) */
    SPLIT_FACES,     /* frustum-face partitioning (course §3.2.3.2): one map per light-facing frustum face */
} SplitScheme;
#define SPLIT_SCHEME_NAMES "practical", "log", "uniform", "explicit", "faces"
/* Interior split distances a map can be given (SPLIT_EXPLICIT): so at most
 * this many + 1 explicit cascades, the usual 4 of the literature. */
#define LIGHTVIEW_EXPLICIT_SPLITS 3

/* Which cascade a point uses (course §3.2.3.1). */
typedef enum CascadeSelect {
    CASCADE_BY_DEPTH,      /* the slice holding its view depth */
    CASCADE_BY_PROJECTION, /* the nearest cascade whose map contains it (Zhang 2009: light near the view axis) */
} CascadeSelect;
#define CASCADE_SELECT_NAMES "depth", "projection"

#define LIGHTVIEW_MAX_CASCADES 16

/* What shapes a light view beyond its projection, fit and size; all-zero
 * is a valid choice (it means the defaults). Lengths in world units. */
typedef struct LightViewParams {
    double warp_n;        /* perspective warps: n as a multiple of the falloff's n (0: 1, i.e. n_opt) */
    double warp_n_world;  /* lispsm, logpsm: a free n in world units (course Fig. 3.6), no falloff (0: off) */
    WarpFalloff falloff;
    double pseudo_near;   /* Lloyd 2007 §5.1.8-5.1.9: warp and splits computed as if z_n were this (0: off) */
    double tsm_focus;     /* TSM: focus point at this fraction of the body's view depth range (0: 0.5) */
    bool stabilize;       /* uniform maps: world-fixed orientation, texel-snapped (course §3.2.1) */
    int cascades;         /* z-partitions, 1 to LIGHTVIEW_MAX_CASCADES (0: 1) */
    SplitScheme split;
    double split_lambda;  /* practical scheme's weight of the log scheme, [0, 1] */
    /* SPLIT_EXPLICIT: C_1..C_(m-1), view depths in world units inside (z_n, z_f), increasing; 0: not given */
    double split_at[LIGHTVIEW_EXPLICIT_SPLITS];
    CascadeSelect select;
    double blend;         /* fraction of each slice, at its far end, dithered into the next one [0, 0.5] */
} LightViewParams;

LightViewParams lightview_params_default(void);

typedef enum MapWarp { MAP_WARP_NONE, MAP_WARP_HOMOGRAPHY, MAP_WARP_LOG } MapWarp;

/* The logarithmic parametrisation in the warp's frame (x', y') = (q.b, q.a)
 * of base NDC q: with w = y' - y_min + n,
 *   u = ku (x' - x_c) / w + cu,   v = kv ln(1 + (y' - y_min) / n) / ln(1 + D / n) + cv
 * (course §3.2.2.2: s = ln(z / z_n) / ln(z_f / z_n) when the view is
 * perpendicular to the light and n = z_n; linear in y' when n is infinite). */
typedef struct LogWarp {
    double a[2], b[2];   /* warp axis and lateral axis in base NDC (unit) */
    double x_c, y_min, D, n;
    double ku, cu, kv, cv;
} LogWarp;

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
    /* Warped faces (course §3.2.2): map NDC (u, v) is a function of the base
     * projection's NDC (x_b, y_b) -- a homography H for PSM, LiSPSM, TSM and
     * uniform maps fitted in the warp's basis (then folded into
     * clip_from_world, so the rasterizer draws them), or the logarithmic
     * map (ray cast; clip_from_world is then the base projection). Depth
     * stays the base's: linear depth along the light, and z_ndc the base's
     * (the clip z is the base's times w_min / w, w the homography's
     * denominator, w >= w_min > 0 on B, so 0 <= z <= w clips as the base
     * does; maps of ndc depth are rescaled per texel to the base's z_ndc). */
    MapWarp warp;
    mat4 base_clip, base_inv; /* world <-> the base projection's clip space */
    bool base_perspective; /* the base is the light's perspective (else ortho) */
    double base_half;      /* half width of the (square) base: world units, or tangent for perspective */
    double H[3][3], H_inv[3][3], w_min;
    LogWarp log;
    double warp_n;         /* the warp's n in base NDC units (INFINITY: uniform; 0: PSM, centred at the eye) */
    double warp_gamma;     /* angle between the view and light directions (radians) */
    bool warp_fallback;    /* the asked-for warp was singular here and fell back (PSM: to LiSPSM at eta = 1) */
} MapFace;

typedef struct LightView {
    MapProjection projection; /* resolved, never AUTO */
    int res;                  /* texels per side of each face */
    int guard;                /* cube faces: texels beyond the 90-degree frustum on each side */
    int num_faces;
    MapFace face[LIGHTVIEW_MAX_FACES];
    dvec3 origin_world;       /* the light's centre (not used by ortho lookups) */
    dvec3 cube_axes[3];       /* cube/paraboloid: the world axes faces are chosen by */
    /* Z-partitioned views (num_cascades > 1): face i covers view depths
     * [split[i], split[i+1]] (course §3.2.3.1). */
    int num_cascades;
    double split[LIGHTVIEW_MAX_CASCADES + 1];
    dvec3 view_eye, view_fwd;
    CascadeSelect select;
    double blend;
    /* Frustum-face partitions: face i serves the points whose light ray meets
     * the view frustum's light-facing face i first (course §3.2.3.2). */
    bool face_partition;
    int num_face_planes;
    double face_plane[6][4];  /* the frustum's planes, inward normals: n.p + d >= 0 inside */
    int face_of_plane[6];     /* map face of each light-facing plane, -1 for the others */
    bool directional;         /* the light's rays are parallel, along light_dir */
    dvec3 light_dir;          /* directional: travel direction; else unused (rays from origin_world) */
} LightView;

/* Fit the map of `light` to the target given by `fit`. `vs` and `cls` are
 * needed only for MAP_FIT_VIEW (else NULL). */
bool lightview_fit(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                   const ViewSamples *vs, const uint8_t *cls, LightView *lv, Error *err);
/* The same with warps, cascades and stabilisation. The camera is the
 * scene's; `vs` is needed for MAP_FIT_VIEW and MAP_FIT_BODY_VISIBLE. */
bool lightview_fit_with(const Scene *scene, const Light *light, MapProjection projection, MapFit fit, int res,
                        const LightViewParams *params, const ViewSamples *vs, const uint8_t *cls, LightView *lv,
                        Error *err);
/* Whether a fit or projection depends on the camera (for resource keys). */
bool lightview_follows_camera(MapProjection projection, MapFit fit, const LightViewParams *params);
/* Split positions C_0..C_m over view depths [z_n, z_f] (course §3.2.3.1)
 * by params' scheme (not SPLIT_FACES); z_n is kept above 1e-9 z_f so the log
 * scheme stays finite. Explicit distances must have passed
 * lightview_check_splits. */
void lightview_splits(const LightViewParams *params, int m, double z_n, double z_f, double *split);
/* Whether the explicit split distances fit m cascades over view depths
 * (z_n, z_f): given for split_1..split_(m-1) only, inside the range and
 * increasing; the error names the parameter and its valid range. `far_what`
 * says where z_f comes from (for the message). */
bool lightview_check_splits(const LightViewParams *params, int m, double z_n, double z_f, const char *far_what,
                            Error *err);

/* Where a world point falls in the map. */
typedef struct MapCoord {
    int face;
    double s, t;         /* texel coordinates in [0, res) when inside */
    double depth_linear; /* view depth (or radial distance for paraboloid faces), world units */
    double z_ndc;        /* post-projective depth of the same point */
    bool inside;         /* within the face's texels and depth range */
    double warp_w;       /* homography faces: its denominator at the point over the base's w (else 1) */
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
/* The base NDC of a point on a warped face's base projection; false when
 * the point is behind a perspective base's eye. */
bool lightview_base_ndc(const MapFace *f, dvec3 p_world, double *x_b, double *y_b, double *z_ndc);

#endif
