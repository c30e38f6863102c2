/* smap.h -- what every shadow-map technique shares: the map's parameters and
 * the depth-bias remedies of course §2.1.2, declared once here and expanded
 * into each technique's parameter table (so `list`, the CLI and Lua see the
 * same names, ranges and docs everywhere), and the lookup of a view sample
 * in the map: texel coordinates and the biased reference depth, per texel
 * when the receiver-plane bias is on.
 *
 * A technique's table starts with SMAP_MAP_PARAMS then SMAP_BIAS_PARAMS;
 * its own parameters follow at index SMAP_NUM_PARAMS (SMAP_DEPTH_BIAS_PARAMS:
 * at SMAP_NUM_DEPTH_BIAS_PARAMS). */
#ifndef SL_SMAP_H
#define SL_SMAP_H
#include <string.h>
#include "core/nanmath.h"
#include "resources/maps/shadowmap.h"
#include "techniques/technique.h"

extern const char *const smap_projection_names[];
extern const char *const smap_fit_names[];
extern const char *const smap_depth_names[];
extern const char *const smap_bits_names[];
extern const char *const smap_falloff_names[];
extern const char *const smap_split_names[];
extern const char *const smap_select_names[];

/* An explicit split distance C_k (LIGHTVIEW_EXPLICIT_SPLITS of them). */
#define SMAP_SPLIT_PARAM(name, k, next)                                                                             \
    {name, PARAM_FLOAT, 0, 0, 1e9, "world units",                                                                   \
     "split_scheme=explicit: the view depth where cascade " k " ends and cascade " next " begins, inside the "    \
     "view's (z_n, z_f) and beyond the split before it; cascades=m takes split_1..split_(m-1), each given, the "   \
     "others 0 (0: not given); pseudo_near does not move it",                                                      \
     NULL}

#define SMAP_MAP_PARAMS SMAP_MAP_PARAMS_UPTO(MAP_PROJ_COUNT - 1, LIGHTVIEW_MAX_CASCADES, SPLIT_FACES)
/* The same for a technique that accepts only the projections up to
 * `proj_max`, at most `cascades_max` maps and the split schemes up to
 * `split_max`: its declared ranges are then what it accepts, so every
 * front end and the stability suite see the limit (adaptive_area: plain
 * perspective maps). */
#define SMAP_MAP_PARAMS_UPTO(proj_max, cascades_max, split_max)                                                    \
    {"map_size", PARAM_INT, 1024, 1, RASTER_MAX_SIZE, "texels",                                                     \
     "shadow-map resolution per side (per face for cube and paraboloid maps)", NULL},                              \
    {"projection", PARAM_ENUM, 0, 0, proj_max, "",                                                                  \
     "light projection (course §2.1.1): auto = perspective for spot, rect and disk lights, ortho for directional, " \
     "perspective or a cube map for point and sphere lights (cube when the scene spans more than 150 degrees); "   \
     "or a warp (course §3.2.2) on the ortho or perspective base: psm (Stamminger & Drettakis), lispsm (Wimmer), " \
     "tsm (Martin & Tan, 80% rule), logpsm (Lloyd, logarithmic along the view, ray cast per texel)",             \
     smap_projection_names},                                                                                       \
    {"fit", PARAM_ENUM, 0, 0, MAP_FIT_COUNT - 1, "",                                                                 \
     "what the frustum is fitted to (course §3.2.1): the scene's bounds, the receivers the camera sees (read "     \
     "exactly from the view samples), none (a spot's cone, the scene's bounding sphere), the intersection body B " \
     "(view frustum inside the scene's bounds), or B with its far plane at the farthest visible sample",           \
     smap_fit_names},                                                                                              \
    {"depth", PARAM_ENUM, 0, 0, 1, "",                                                                               \
     "stored depth: linear (world units along the light's axis) or ndc (post-projective z in [0, 1])",             \
     smap_depth_names},                                                                                            \
    {"depth_bits", PARAM_ENUM, 0, 0, 2, "",                                                                          \
     "depth storage: f32, or u24/u16 quantised over the light's depth range (course §2.1.2 on precision)",         \
     smap_bits_names},                                                                                             \
    {"warp_n", PARAM_FLOAT, 1, 0.01, 1e6, "x n_opt",                                                                  \
     "lispsm and logpsm: the warp's n as a multiple of the falloff's n (lispsm: n_opt = z_n + sqrt(z_f z_n) for "  \
     "a view perpendicular to the light, course §3.2.2.3; with warp_falloff=none exactly warp_n x n_opt); small n " \
     "warps toward PSM, large toward uniform",                                                                     \
     NULL},                                                                                                        \
    {"warp_n_world", PARAM_FLOAT, 0, 0, 1e9, "world units",                                                          \
     "lispsm and logpsm: a free n (course Fig. 3.6), the warp centre's distance before the body's near end along " \
     "the view's image, used as given (warp_n and warp_falloff then do nothing); measured in the light's plane, "   \
     "for lights with a position at the light depth of the body's near end; 0: off",                             \
     NULL},                                                                                                        \
    {"warp_falloff", PARAM_ENUM, 0, 0, 2, "",                                                                        \
     "how the warp relaxes as the view turns toward the light's direction (angle gamma): Lloyd's (thesis "         \
     "§5.2.1, uniform within theta/3), n_opt / sin(gamma) (Wimmer 2004), or none",                                 \
     smap_falloff_names},                                                                                          \
    {"pseudo_near", PARAM_FLOAT, 0, 0, 1e9, "world units",                                                           \
     "pseudo-near plane (Lloyd 2007 §5.1.8-5.1.9): warps and splits are computed as if the view's near plane "     \
     "were here (0: off)",                                                                                         \
     NULL},                                                                                                        \
    {"tsm_focus", PARAM_FLOAT, 0.5, 0.01, 1, "fraction",                                                              \
     "tsm: the focus point, as a fraction of the body's view-depth range from its near end; it maps to the 80% "   \
     "line of the map (Martin & Tan 2004)",                                                                        \
     NULL},                                                                                                        \
    {"stabilize", PARAM_BOOL, 0, 0, 1, "",                                                                           \
     "unwarped single-face maps (ortho, perspective; also per cascade): world-fixed orientation (a spot, rect or "  \
     "disk light's own axis, a point or sphere light aimed at the scene's centre) and texel-snapped extents on a "  \
     "ladder of sizes, so texels stay still as the camera moves (course §3.2.1); cube and paraboloid maps are "     \
     "world-fixed already; no effect on warped maps (psm, lispsm, tsm, logpsm, warped frustum faces)",           \
     NULL},                                                                                                        \
    {"cascades", PARAM_INT, 1, 1, cascades_max, "maps",                                                             \
     "z-partitioning (cascaded / parallel-split shadow maps, course §3.2.3.1): this many maps of map_size^2, "      \
     "each fitted to its slice of the intersection body (its visible samples with fit=view); 1: a single map",     \
     NULL},                                                                                                        \
    {"split_scheme", PARAM_ENUM, 0, 0, split_max, "",                                                               \
     "split positions: practical (lambda log + (1 - lambda) uniform, Zhang 2006), log (C_i = z_n (z_f/z_n)^(i/m), " \
     "Lloyd 2006), uniform, explicit (the view depths split_1..split_3: up to 4 cascades), or faces (one warped "   \
     "map per light-facing face of the view frustum, course §3.2.3.2)",                                            \
     smap_split_names},                                                                                            \
    {"split_lambda", PARAM_FLOAT, 0.5, 0, 1, "",                                                                     \
     "practical split scheme: weight of the logarithmic positions (0: uniform, 1: log)", NULL},                    \
    SMAP_SPLIT_PARAM("split_1", "1", "2"), SMAP_SPLIT_PARAM("split_2", "2", "3"),                                  \
    SMAP_SPLIT_PARAM("split_3", "3", "4"),                                                                         \
    {"cascade_select", PARAM_ENUM, 0, 0, 1, "",                                                                      \
     "which cascade a point uses: the slice of its view depth, or the nearest cascade whose map contains it "      \
     "(better with the light near the view axis, Zhang 2009)",                                                     \
     smap_select_names},                                                                                           \
    {"cascade_blend", PARAM_FLOAT, 0, 0, 0.5, "fraction",                                                            \
     "fraction of each slice, at its far end, over which points are dithered into the next cascade (0: hard "      \
     "borders)",                                                                                                   \
     NULL}

#define SMAP_BIAS_PARAMS SMAP_BIAS_PARAMS_PLANE(0)
/* The same with the receiver-plane bias on (1) or off (0) by default: wide
 * kernels (blocker searches, soft-shadow filters) need it on, or every planar
 * receiver tilted to the light shadows itself (course §5.2.2.1, its third issue). */
#define SMAP_BIAS_PARAMS_PLANE(receiver_plane_default) \
    SMAP_DEPTH_BIAS_PARAMS, SMAP_RECEIVER_PLANE_PARAM(receiver_plane_default)
/* The biases of the one reference depth a sample is compared with. A
 * technique that compares a whole prefiltered window with that one depth
 * (filtered.h: vsm, lvsm, evsm, msm, csm) takes only these: the receiver
 * plane, a depth per texel, cannot act there. */
#define SMAP_DEPTH_BIAS_PARAMS                                                                                     \
    {"bias", PARAM_FLOAT, 0, 0, 1e6, "world units", "constant depth bias along the light's depth axis", NULL},      \
    {"bias_steps", PARAM_FLOAT, 0, 0, 1e9, "depth steps",                                                            \
     "constant bias in steps of the stored depth format at the receiver (glPolygonOffset's units)", NULL},          \
    {"slope_bias", PARAM_FLOAT, 1, 0, 1000, "x depth slope",                                                         \
     "slope-scaled bias (glPolygonOffset's factor): this times the receiver's depth change across one texel, "     \
     "texel width x tan(angle to the light); filters multiply it by 1 + their radius in texels",                  \
     NULL},                                                                                                        \
    {"slope_max", PARAM_FLOAT, 8, 0, 1e6, "texels",                                                                  \
     "clamp of the slope-scaled bias in texel widths at the receiver (tan diverges at grazing light), also "       \
     "times 1 + a filter's radius",                                                                                \
     NULL},                                                                                                        \
    {"normal_offset", PARAM_FLOAT, 0, 0, 100, "texels",                                                              \
     "normal-offset bias: the lookup point moves along the geometric normal by this many texel widths", NULL}
#define SMAP_RECEIVER_PLANE_PARAM(receiver_plane_default)                                                          \
    {"receiver_plane", PARAM_BOOL, receiver_plane_default, 0, 1, "",                                                 \
     "receiver-plane depth bias (Schueler 2006, course §4.1.2 box): each texel is compared with the receiver's "   \
     "plane at that texel's centre, not with the sample's own depth",                                              \
     NULL}

enum {
    SMAP_P_MAP_SIZE, SMAP_P_PROJECTION, SMAP_P_FIT, SMAP_P_DEPTH, SMAP_P_DEPTH_BITS,
    SMAP_P_WARP_N, SMAP_P_WARP_N_WORLD, SMAP_P_WARP_FALLOFF, SMAP_P_PSEUDO_NEAR, SMAP_P_TSM_FOCUS, SMAP_P_STABILIZE,
    SMAP_P_CASCADES, SMAP_P_SPLIT_SCHEME, SMAP_P_SPLIT_LAMBDA, SMAP_P_SPLIT_1, SMAP_P_SPLIT_2, SMAP_P_SPLIT_3,
    SMAP_P_CASCADE_SELECT, SMAP_P_CASCADE_BLEND,
    SMAP_P_BIAS, SMAP_P_BIAS_STEPS, SMAP_P_SLOPE_BIAS, SMAP_P_SLOPE_MAX, SMAP_P_NORMAL_OFFSET, SMAP_P_RECEIVER_PLANE,
    SMAP_NUM_PARAMS
};
/* Tables with SMAP_DEPTH_BIAS_PARAMS only: their own parameters start here. */
#define SMAP_NUM_DEPTH_BIAS_PARAMS SMAP_P_RECEIVER_PLANE

/* When the shared map parameters act (technique.h's ParamCondition), for
 * every technique whose table starts with SMAP_MAP_PARAMS; ended by {NULL}. */
extern const ParamCondition smap_conditions[];

/* The map resource the parameters ask for (first layer, no culling). */
ShadowMapSpec smap_spec(const double *params);
/* Whether a technique's table starts with SMAP_MAP_PARAMS (so smap_spec
 * reads its values): the map a technique renders with, for the analyses
 * that measure it (`shadowlab aliasing -t TECH`). */
bool smap_has_map_params(const Technique *t);

typedef struct SmapBias {
    double constant_world, steps, slope, slope_max_texels, normal_offset_texels;
    bool receiver_plane;
    float scene_extent;   /* for the engine's own offset, rt_ray_offset */
    double filter_radius; /* texels from the sample to a filter's farthest tap (0: one texel) */
} SmapBias;
/* The biases of a table with SMAP_BIAS_PARAMS (receiver plane included). */
SmapBias smap_bias(const double *params, const Scene *scene);
/* The same for a table with SMAP_DEPTH_BIAS_PARAMS: no receiver plane. */
SmapBias smap_depth_bias(const double *params, const Scene *scene);

/* A view sample as the map sees it. */
typedef struct SmapReceiver {
    MapCoord mc;            /* of the (normal-offset) lookup point */
    dvec3 p_world;          /* that lookup point, world units (rays marched through the map start here) */
    double texel_world;     /* texel width at the receiver, world units */
    double ref;             /* the biased reference depth, in the map's stored metric */
    double bias;            /* the bias subtracted, stored metric */
    /* Receiver plane (course §4.1.2 box): the stored metric, made affine in
     * the texel coordinates (1/depth for linear perspective maps), is
     * g(s, t) = g0 + gs (s - s0) + gt (t - t0) on the receiver's plane. */
    bool plane, reciprocal;
    double g0, gs, gt;
} SmapReceiver;

/* The lookup point is first lifted off the surface along the geometric
 * normal by rt_ray_offset, exactly as the reference and `hard` lift their
 * shadow rays: view samples carry float error, and with zero bias a map
 * should agree with `hard` wherever the surface faces the light squarely.
 * false when the sample falls outside the map (the technique decides: lit). */
bool smap_receiver(const ShadowMap *m, const SmapBias *b, vec3 p_world, vec3 n_geom_world, SmapReceiver *r);
/* The same set-up for samples [0, count) of the arrays at once, those whose
 * class is SAMPLE_LIT_CANDIDATE (cls NULL: all); inside[i] is what
 * smap_receiver returns (false for the others, whose r[i] is not written).
 * smap_receiver is a batch of one. On a plain projective map (one ortho or
 * perspective face, no warp, cascades or cube) lifting, locating, the texel
 * size and the depth slope run over SMAP_BATCH samples at a time in float32
 * arrays, as a GPU's shader does; the biases then per receiver, in double.
 * Other maps are located per sample in double (lightview_locate). */
#define SMAP_BATCH 64
void smap_receivers(const ShadowMap *m, const SmapBias *b, const vec3 *p_world, const vec3 *n_geom_world,
                    const uint8_t *cls, int count, SmapReceiver *r, bool *inside);

/* A batch's receivers as a filter that compares every tap with its
 * sample's one reference depth reads them (no receiver plane): one array per
 * quantity, written once per batch. */
typedef struct SmapRefs {
    int count;                            /* lit candidates of the batch, in sample order */
    int sample[SMAP_BATCH];               /* each one's index in the batch */
    bool inside[SMAP_BATCH];              /* smap_receiver's answer; the rest is unset where false */
    int face[SMAP_BATCH];                 /* the map face it falls on */
    double s[SMAP_BATCH], t[SMAP_BATCH];  /* texel coordinates of the lookup point on that face */
    float ref_up[SMAP_BATCH];             /* smap_ref_up of the biased reference depth */
} SmapRefs;
/* smap_receivers' set-up of samples [0, count <= SMAP_BATCH) for a bias
 * without the receiver plane (b->receiver_plane false), the same reference
 * depths to the bit. Where the batch path serves and no slope-scaled bias
 * asks for the receiver's plane, the biases too run in lanes (double, in
 * receiver_bias's order of operations); else through SmapReceiver records. */
void smap_refs(const ShadowMap *m, const SmapBias *b, const vec3 *p_world, const vec3 *n_geom_world,
               const uint8_t *cls, int count, SmapRefs *out);

/* Reference depth at map point (s, t) of the receiver's face (texel units:
 * texel i covers [i, i + 1]): the receiver plane's there, else r->ref. */
static inline double smap_ref_at_point(const SmapReceiver *r, double s, double t)
{
    if (!r->plane) return r->ref;
    double g = r->g0 + r->gs * (s - r->mc.s) + r->gt * (t - r->mc.t);
    double d = r->reciprocal ? (g > 0.0 ? 1.0 / g : INFINITY) : g;
    return d - r->bias;
}

/* Reference depth to compare with texel (i, j) of the receiver's face. */
static inline double smap_ref_at(const SmapReceiver *r, int i, int j)
{
    return smap_ref_at_point(r, i + 0.5, j + 0.5);
}

/* The shadow test of course §2.1: lit (1) unless the reference lies behind
 * the stored depth; ties are lit; NaN when either depth is NaN (unknown,
 * neither lit nor shadowed: it reaches the output, issue 13 §1). */
static inline float smap_test(double ref, double stored)
{
    return ref > stored ? 0.0f : ref <= stored ? 1.0f : NAN;
}

/* The smallest float32 at or above a reference depth: against any stored
 * float32 z, ref <= z exactly when smap_ref_up(ref) <= z (and ref > z when
 * it is > z; NaN stays NaN), so a filter may compare its taps in float
 * lanes with smap_test's results unchanged. */
static inline float smap_ref_up(double ref)
{
    float f = (float)ref;
    /* the next float32 up, as nextafterf(f, INFINITY) but inline (it runs in
     * lanes): f < ref is finite or -inf, never -0 (a ref that rounds to -0
     * is <= -0), and IEEE 754 orders floats as sign-magnitude integers, so
     * one step up is magnitude + 1 from +0 up, magnitude - 1 below 0. */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    u = f >= 0.0f ? u + 1u : u - 1u;
    float up;
    memcpy(&up, &u, sizeof up);
    return (double)f < ref ? up : f;
}

static inline float smap_lit(const ShadowMap *m, const SmapReceiver *r, int i, int j)
{
    return smap_test(smap_ref_at(r, i, j), shadowmap_texel(m, r->mc.face, i, j));
}

/* A stored depth of a face as linear depth (world units along the face's
 * axis), for techniques whose formulas need distances (blocker depths, shadow
 * depths): the inverse of z_ndc = f/(f-n) (1 - n/d) for perspective faces and
 * of z_ndc = (d - n)/(f - n) for orthographic ones; +INFINITY (no caster)
 * stays infinite. */
static inline double smap_linear_depth(const ShadowMap *m, int face, double stored)
{
    const MapFace *f = &m->view.face[face];
    if (m->spec.depth == RASTER_DEPTH_LINEAR || !isfinite(stored)) return stored;
    double n = f->raster.depth_near, far = f->raster.depth_far;
    if (!f->perspective && !f->base_perspective) return n + stored * (far - n); /* warps keep the base's z */
    double den = 1.0 - stored * (far - n) / far; /* n/d: reaches 0 only beyond the far plane */
    return den > 0.0 ? n / den : INFINITY;
}

/* Texel of the nearest-sample lookup. */
static inline void smap_texel(const SmapReceiver *r, int *i, int *j)
{
    *i = (int)floor(r->mc.s);
    *j = (int)floor(r->mc.t);
}

#endif
