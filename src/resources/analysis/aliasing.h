/* aliasing.h -- the lab's measuring instrument for shadow-map sampling error
 * (course §3.1). For a surface point seen by the camera, the Jacobian J of
 * (screen pixel -> map texel) is measured through the map's actual mapping
 * (any projection, warp or cascade: the face the point uses), by central
 * differences of lightview_locate_on over the pixel's footprint on the
 * point's tangent plane. The columns of J^-1 are the projected extents of
 * one texel step along the map's axes s and t, in pixels: Lloyd's aliasing
 * error m per axis (Eq. 3.2), undersampling where m > 1. The projection
 * factor of Eq. 3.1, cos(alpha) / cos(beta) (alpha: normal to the eye,
 * beta: normal to the light), is reported beside it; m divided by it is the
 * perspective factor. The per-sample analysis is a resource (built only
 * when asked for, keyed by the map and the view), with its summary:
 * undersampled share, max and mean, histogram, profile along view depth,
 * and the storage the maps need for m <= 1 (Lloyd's storage factor over the
 * frustum, the total-aliasing storage over the samples). */
#ifndef SL_ALIASING_H
#define SL_ALIASING_H
#include "resources/views/lightbody.h"
#include "resources/maps/shadowmap.h"

#define ALIASING_M_CAP 1e9       /* m where J is singular (a texel seen edge-on): finite, undersampled */
#define ALIASING_HIST_BINS 40    /* log10 m over [-2, 2] in 0.1 steps, first and last bins open */
#define ALIASING_DEPTH_BINS 32   /* log view depth over [near, far] */

/* The camera as the instrument needs it: frame and pixel size. */
typedef struct AliasingView {
    ViewFrustum frustum;
    double pixel;                /* image-plane units per screen pixel at unit depth: 2 tan(fov_y / 2) / height */
    int width, height;           /* screen pixels (the camera's, not supersampled) */
} AliasingView;

AliasingView aliasing_view(const Camera *cam);

/* One measurement. */
typedef struct AliasingPoint {
    double m_s, m_t; /* pixels per texel step along s and along t */
    double proj;     /* cos(alpha) / cos(beta) */
    int face;
    double depth;    /* view depth, world units */
} AliasingPoint;

/* Measure at surface point p (unit normal n); `to_light` is the unit
 * direction from p toward the light. False where the point is outside the
 * map, seen edge-on, or behind the eye. */
bool aliasing_at(const LightView *lv, const AliasingView *av, dvec3 p, dvec3 n, dvec3 to_light, AliasingPoint *out);
/* The unit direction from p toward a light (directional: -direction). */
dvec3 aliasing_to_light(const Light *light, dvec3 p);
/* The setting of course §3.1.2 and Fig. 3.7: a surface element on the view
 * axis at view depth z whose normal bisects the directions to the eye and
 * to the light (cos alpha = cos beta: perspective aliasing only). */
bool aliasing_on_axis(const LightView *lv, const AliasingView *av, const Light *light, double z, AliasingPoint *out);
/* m as the catalogue's normalised dp/ds (course §3.1.2): e_y in image-plane
 * units at unit depth per map height, e_x in viewport widths per map width
 * (so a uniform map fitted to z_n..z_f has e_y = (z_f - z_n)/z, e_x = z_f/z). */
void aliasing_normalised(const AliasingView *av, int res, const AliasingPoint *pt, double *e_x, double *e_y);

typedef struct AliasingSummary {
    long measured, undersampled;          /* samples measured; of them with max(m_s, m_t) > 1 */
    long singular;                        /* of them seen edge-on by the light (m = ALIASING_M_CAP): counted as
                                             undersampled, left out of every statistic below */
    double m_max, m_mean;                 /* of max(m_s, m_t) */
    double m_s_max, m_t_max, m_s_mean, m_t_mean;
    /* Texels the maps would need for m <= 1 at every measured point, over
     * the screen's pixels, both axes: sum over faces of res^2 max(m_s)
     * max(m_t) / (width height). Over the frustum (perspective_only) it is
     * Lloyd et al. 2006's storage factor; over the view samples m includes
     * projection aliasing (cos(alpha) / cos(beta), unbounded near grazing
     * light), so it is the total-aliasing storage, another and far larger
     * quantity (aliasing_storage_name). */
    double storage;
    bool perspective_only;                /* each point's normal bisects the eye and light directions */
    long hist[ALIASING_HIST_BINS];
    double depth_lo, depth_hi;            /* the profile's range (the camera's near and far) */
    long depth_count[ALIASING_DEPTH_BINS];
    double depth_m_s[ALIASING_DEPTH_BINS], depth_m_t[ALIASING_DEPTH_BINS];       /* means */
    double depth_m_s_max[ALIASING_DEPTH_BINS], depth_m_t_max[ALIASING_DEPTH_BINS];
    double depth_persp_s[ALIASING_DEPTH_BINS], depth_persp_t[ALIASING_DEPTH_BINS]; /* means of m / proj */
    int num_faces;
    long face_count[LIGHTVIEW_MAX_FACES];
    double face_m_s_max[LIGHTVIEW_MAX_FACES], face_m_t_max[LIGHTVIEW_MAX_FACES];
} AliasingSummary;

/* Accumulate measurements into a summary (res: texels per side of each face). */
void aliasing_summary_init(AliasingSummary *s, int num_faces, double depth_lo, double depth_hi, bool perspective_only);
void aliasing_summary_add(AliasingSummary *s, const AliasingPoint *pt);
void aliasing_summary_finish(AliasingSummary *s, int res, int width, int height);
/* The name of s->storage in records, Lua and printouts: "storage_factor"
 * (perspective only) or "total_aliasing_storage" (projection included). */
const char *aliasing_storage_name(const AliasingSummary *s);
/* Lower edge of histogram bin b as m (bin 0 also takes everything below). */
double aliasing_hist_edge(int b);

/* The per-sample analysis of a map over the view samples (lit candidates). */
typedef struct AliasingMap {
    int width, height;         /* the view-sample grid */
    float *m_s, *m_t, *proj;   /* per sample; NAN where not measured */
    int8_t *face;              /* -1 where not measured */
    AliasingSummary sum;
} AliasingMap;

const AliasingMap *res_aliasing(ResourceManager *rm, const Scene *scene, int light_index, const ShadowMap *map,
                                Error *err);

/* Lloyd et al. 2006's measure over the intersection body B (the view
 * frustum inside the scene's bounds), not the samples: perspective
 * aliasing only (each point's normal bisects the directions to the eye and
 * to the light, so cos(alpha) = cos(beta)). Each map's maximum lies on the
 * boundary of its region, so the probes include it: nx x ny rays at image
 * positions -1..1 (edges and corners included), nz view depths along each,
 * log spaced from its entry into B to its exit (both included), each map
 * change along a ray bisected; then a climb from each map's highest m_s
 * and m_t raises the maxima (s->storage converges from below in the
 * points; counts and means are the probes'). */
void aliasing_frustum(const LightView *lv, const Scene *scene, const Light *light, int nx, int ny, int nz,
                      AliasingSummary *out);

#endif
