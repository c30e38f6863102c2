/* smap.c -- shared shadow-map parameters, biases and lookups (smap.h). */
#include "techniques/smap.h"
#include <float.h>
#include <string.h>

const char *const smap_projection_names[] = {MAP_PROJ_NAMES, NULL};
const char *const smap_fit_names[] = {MAP_FIT_NAMES, NULL};
const char *const smap_depth_names[] = {"linear", "ndc", NULL};
const char *const smap_bits_names[] = {"f32", "u24", "u16", NULL};
const char *const smap_falloff_names[] = {WARP_FALLOFF_NAMES, NULL};
const char *const smap_split_names[] = {SPLIT_SCHEME_NAMES, NULL};
const char *const smap_select_names[] = {CASCADE_SELECT_NAMES, NULL};

/* What each view parameter shapes (resources/maps/shadowmap.c's relevant_params,
 * resources/views/warp.c's warp_n, lightview.c's fit_face): a warp's n and falloff
 * (lispsm, logpsm; tsm's falloff), a free n, TSM's focus, the splits of a
 * partitioned map (cascades, or the frustum's faces), stable extents
 * (unwarped faces: ortho and perspective maps, also per cascade, and the
 * flat near and far faces of a face partition, lightview.c's
 * fit_face_partition). A condition may be wider than where the parameter
 * acts (stabilize with an auto projection that resolves to a cube), never
 * narrower: the configuration key leaves out what it excludes. A technique that takes none of the listed
 * values (adaptive_area: no warps) is not offered the parameter. */
#define SMAP_WARPED "projection=psm|lispsm|tsm|logpsm"
#define SMAP_PARTED "cascades!=1 or split_scheme=faces"
const ParamCondition smap_conditions[] = {
    {"warp_n", "projection=lispsm|logpsm and warp_n_world=0"},
    {"warp_n_world", "projection=lispsm|logpsm"},
    {"warp_falloff", "projection=lispsm|logpsm and warp_n_world=0 or projection=tsm"},
    {"pseudo_near", SMAP_WARPED " or " SMAP_PARTED},
    {"tsm_focus", "projection=tsm"},
    {"stabilize", "projection=auto|perspective|ortho or split_scheme=faces"}, /* faces: near and far are flat */
    {"split_scheme", SMAP_PARTED},
    {"split_lambda", "split_scheme=practical and cascades!=1"},
    {"split_1", "split_scheme=explicit and cascades=2|3|4"},
    {"split_2", "split_scheme=explicit and cascades=3|4"},
    {"split_3", "split_scheme=explicit and cascades=4"},
    {"cascade_select", SMAP_PARTED},
    {"cascade_blend", SMAP_PARTED},
    {NULL, NULL},
};

_Static_assert(SMAP_P_SPLIT_3 - SMAP_P_SPLIT_1 + 1 == LIGHTVIEW_EXPLICIT_SPLITS, "one split_k per explicit distance");

ShadowMapSpec smap_spec(const double *p)
{
    static const int bits[] = {0, 24, 16};
    ShadowMapSpec s = shadowmap_spec_default();
    s.res = (int)p[SMAP_P_MAP_SIZE];
    s.projection = (MapProjection)(int)p[SMAP_P_PROJECTION];
    s.fit = (MapFit)(int)p[SMAP_P_FIT];
    s.depth = (int)p[SMAP_P_DEPTH] == 1 ? RASTER_DEPTH_NDC : RASTER_DEPTH_LINEAR;
    s.depth_bits = bits[(int)p[SMAP_P_DEPTH_BITS]];
    s.view = (LightViewParams){.warp_n = p[SMAP_P_WARP_N], .warp_n_world = p[SMAP_P_WARP_N_WORLD],
                               .falloff = (WarpFalloff)(int)p[SMAP_P_WARP_FALLOFF],
                               .pseudo_near = p[SMAP_P_PSEUDO_NEAR], .tsm_focus = p[SMAP_P_TSM_FOCUS],
                               .stabilize = p[SMAP_P_STABILIZE] != 0.0, .cascades = (int)p[SMAP_P_CASCADES],
                               .split = (SplitScheme)(int)p[SMAP_P_SPLIT_SCHEME], .split_lambda = p[SMAP_P_SPLIT_LAMBDA],
                               .split_at = {p[SMAP_P_SPLIT_1], p[SMAP_P_SPLIT_2], p[SMAP_P_SPLIT_3]},
                               .select = (CascadeSelect)(int)p[SMAP_P_CASCADE_SELECT],
                               .blend = p[SMAP_P_CASCADE_BLEND]};
    return s;
}

bool smap_has_map_params(const Technique *t)
{
    static const ParamDesc shared[] = {SMAP_MAP_PARAMS};
    int n = (int)(sizeof shared / sizeof shared[0]);
    if (t->num_params < n) return false;
    for (int i = 0; i < n; i++)
        if (strcmp(t->params[i].name, shared[i].name) != 0 || t->params[i].type != shared[i].type) return false;
    return true;
}

SmapBias smap_depth_bias(const double *p, const Scene *scene)
{
    return (SmapBias){p[SMAP_P_BIAS], p[SMAP_P_BIAS_STEPS], p[SMAP_P_SLOPE_BIAS], p[SMAP_P_SLOPE_MAX],
                      p[SMAP_P_NORMAL_OFFSET], false, scene_extent(scene), 0.0};
}

SmapBias smap_bias(const double *p, const Scene *scene)
{
    SmapBias b = smap_depth_bias(p, scene);
    b.receiver_plane = p[SMAP_P_RECEIVER_PLANE] != 0.0;
    return b;
}

/* The constant part of the bias (course §2.1.2: world units plus steps of
 * the stored depth) in the stored metric, at a receiver of post-projective
 * depth z_ndc and linear depth depth_linear, on a map storing ndc or linear
 * depth in `bits` (0: float32) over `depth_range` world units (the face's
 * far - near). A step (the r of glPolygonOffset) is a quantisation level, or
 * a float32 ulp at the receiver; on ndc maps it is made world units through
 * dz_ndc/d depth, then the sum made ndc again. */
static inline double constant_bias(const SmapBias *b, bool ndc, int bits, double depth_range, double z_ndc,
                                   double depth_linear, double ndc_per_world)
{
    double levels = (double)((1u << bits) - 1u); /* read only where bits > 0 */
    if (!ndc) return b->constant_world + b->steps * (bits ? depth_range / levels : fabs(depth_linear) * FLT_EPSILON);
    /* nan_max(|z_ndc|, FLT_MIN) FLT_EPSILON, the scaling first: times 2^-23
     * is exact in double down to 2^-999, and one compare with the scaled
     * floor keeps NaN (so the multiply is not moved into a branch) */
    double ulp = fabs(z_ndc) * FLT_EPSILON, ulp_min = (double)FLT_MIN * FLT_EPSILON;
    double step_ndc = bits ? 1.0 / levels : ulp < ulp_min ? ulp_min : ulp;
    return (b->constant_world + b->steps * (step_ndc / ndc_per_world)) * ndc_per_world;
}

/* The same for a receiver of a map's face. */
static inline double face_constant_bias(const ShadowMap *m, const SmapBias *b, int face, double z_ndc,
                                        double depth_linear, double ndc_per_world)
{
    const RasterView *rv = &m->view.face[face].raster;
    return constant_bias(b, m->spec.depth == RASTER_DEPTH_NDC, m->spec.depth_bits, rv->depth_far - rv->depth_near,
                         z_ndc, depth_linear, ndc_per_world);
}

static inline double stored_depth(const ShadowMap *m, double z_ndc, double depth_linear)
{
    return m->spec.depth == RASTER_DEPTH_NDC ? z_ndc : depth_linear;
}

/* The receiver's plane (point q, normal n) seen through texel coordinates
 * (s, t) of the face, in the affine metric g (course §4.1.2 box). */
static bool plane_metric(const ShadowMap *m, const SmapReceiver *r, dvec3 q, dvec3 n, double s, double t, double *g)
{
    dvec3 org, dir;
    lightview_texel_ray(&m->view, r->mc.face, s, t, &org, &dir);
    double dn = d3_dot(dir, n);
    if (!(fabs(dn) > 1e-9)) return false; /* the ray runs along the plane: grazing light */
    dvec3 x = d3_madd(org, dir, d3_dot(d3_sub(q, org), n) / dn);
    MapCoord c = lightview_locate_on(&m->view, r->mc.face, x);
    double v = stored_depth(m, c.z_ndc, c.depth_linear);
    if (r->reciprocal && !(v > 0.0)) return false;
    *g = r->reciprocal ? 1.0 / v : v;
    return isfinite(*g);
}

/* g0, gs, gt of the receiver's plane: exact for projective maps, where
 * planes stay planes (1/depth is affine on screen under perspective). */
static bool receiver_plane(const ShadowMap *m, SmapReceiver *r, dvec3 q, dvec3 n)
{
    const MapFace *f = &m->view.face[r->mc.face];
    r->reciprocal = f->perspective && m->spec.depth == RASTER_DEPTH_LINEAR;
    double g0, g1, g2, s = r->mc.s, t = r->mc.t;
    if (!plane_metric(m, r, q, n, s, t, &g0) || !plane_metric(m, r, q, n, s + 1.0, t, &g1) ||
        !plane_metric(m, r, q, n, s, t + 1.0, &g2))
        return false;
    r->g0 = g0;
    r->gs = g1 - g0;
    r->gt = g2 - g0;
    return true;
}

/* glPolygonOffset's m: the stored depth's largest change across one texel
 * on the receiver's plane, max(|dz/ds|, |dz/dt|). */
static double depth_slope(const SmapReceiver *r)
{
    double k = r->reciprocal ? 1.0 / (r->g0 * r->g0) : 1.0; /* d = 1/g: |dd| = |dg| / g^2 */
    return nan_max(fabs(r->gs), fabs(r->gt)) * k;
}

/* The bias and reference depth of a located receiver (lookup point p, the
 * geometric normal n), whichever path located it. */
static bool receiver_bias(const ShadowMap *m, const SmapBias *b, dvec3 p, dvec3 n, double ndc_per_world,
                          SmapReceiver *r)
{
    r->p_world = p; /* the lookup point, whichever path located it (smrt marches from it) */
    r->plane = false;
    if (!r->mc.inside) return false;
    double to_stored = m->spec.depth == RASTER_DEPTH_NDC ? ndc_per_world : 1.0;
    bool plane = (b->receiver_plane || b->slope > 0.0) && receiver_plane(m, r, p, n);
    /* Slope-scaled bias (course §2.1.2: faces aligned with the light's rays
     * need much more): factor x depth slope, clamped, since the slope
     * diverges at grazing light (where the plane is lost, the clamp). A
     * filter compares taps up to `filter_radius` texels away, so the depth
     * it must tolerate grows with it (catalogue ch.4: ~K texel tan(theta)). */
    double reach = 1.0 + b->filter_radius;
    double slope_max = b->slope_max_texels * r->texel_world * to_stored * reach;
    double slope = plane ? nan_min(b->slope * depth_slope(r) * reach, slope_max) : b->slope > 0.0 ? slope_max : 0.0;
    r->bias = face_constant_bias(m, b, r->mc.face, r->mc.z_ndc, r->mc.depth_linear, ndc_per_world) + slope;
    r->ref = stored_depth(m, r->mc.z_ndc, r->mc.depth_linear) - r->bias;
    r->plane = plane && b->receiver_plane;
    return true;
}

/* Any map in double precision: lift, locate (any face, warp or cascade),
 * normal offset, locate again. */
static bool receiver_any(const ShadowMap *m, const SmapBias *b, vec3 p_world, vec3 n_geom_world, SmapReceiver *r)
{
    const LightView *lv = &m->view;
    dvec3 n = d3_from(n_geom_world);
    dvec3 p = d3_madd(d3_from(p_world), n, rt_ray_offset(b->scene_extent, p_world));
    r->mc = lightview_locate(lv, p);
    r->texel_world = lightview_texel_world(lv, &r->mc);
    if (b->normal_offset_texels > 0.0) {
        p = d3_madd(p, n, b->normal_offset_texels * r->texel_world);
        r->mc = lightview_locate(lv, p);
        r->texel_world = lightview_texel_world(lv, &r->mc);
    }
    double ndc_per_world = r->mc.inside ? lightview_ndc_per_world(lv, &r->mc) : 0.0;
    return receiver_bias(m, b, p, n, ndc_per_world, r);
}

/* ---- the batched float32 set-up of a plain projective map ---------------- */

/* One unwarped ortho or perspective face, as lightview_locate_on,
 * lightview_texel_world and lightview_ndc_per_world (lightview_lookup.c)
 * read it, rounded to float32 once per batch. */
typedef struct FaceF {
    float clip[4][4]; /* clip_from_world */
    float row[4];     /* linear depth = row . (p, 1), world units */
    float res;        /* texels per side */
    float texel;      /* texel width: world units (ortho), or per unit of depth (perspective) */
    float near;       /* depth_near, world units */
    float ndc_k;      /* perspective: f n / (f - n), dz_ndc/dd = ndc_k / d^2; ortho: 1 / (f - n) */
    bool perspective;
} FaceF;

/* Where the batch path serves: one face (no cube, paraboloid, cascades or
 * frustum-face partition), no warp. Other maps take receiver_any. */
static bool face_float(const ShadowMap *m, FaceF *f)
{
    const LightView *lv = &m->view;
    const MapFace *mf = &lv->face[0];
    if (lv->num_faces != 1 || lv->num_cascades > 1 || lv->face_partition || mf->paraboloid ||
        mf->warp != MAP_WARP_NONE)
        return false;
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 4; k++) f->clip[i][k] = (float)mf->raster.clip_from_world.m[i][k];
        f->row[i] = (float)mf->raster.depth_row[i];
    }
    double n = mf->raster.depth_near, far = mf->raster.depth_far;
    f->res = (float)lv->res;
    f->texel = (float)(fmax(mf->r - mf->l, mf->t - mf->b) / lv->res);
    f->near = (float)n;
    f->perspective = mf->perspective;
    f->ndc_k = (float)(mf->perspective ? far * n / (far - n) : 1.0 / (far - n));
    return true;
}

/* A batch's lookup points and what locating them gives, one array per
 * quantity (structure of arrays: the loop over them vectorises). */
typedef struct BatchF {
    float x[SMAP_BATCH], y[SMAP_BATCH], z[SMAP_BATCH];        /* lookup point, world */
    float nx[SMAP_BATCH], ny[SMAP_BATCH], nz[SMAP_BATCH];     /* geometric normal, world */
    float s[SMAP_BATCH], t[SMAP_BATCH];                       /* texel coordinates */
    float z_ndc[SMAP_BATCH], depth[SMAP_BATCH];               /* post-projective and linear depth */
    float texel_world[SMAP_BATCH], ndc_per_world[SMAP_BATCH]; /* texel width (world units), dz_ndc / d depth */
    int inside[SMAP_BATCH];
} BatchF;

/* lightview_locate_on, lightview_texel_world and lightview_ndc_per_world of
 * an unwarped face for points [0, n) of the batch, in float32 lanes: AVX2
 * where the CPU has it, 8 lanes. Without -ftrapping-math's promise that a
 * comparison with NaN may trap (no FP exception is unmasked here) GCC
 * turns the selects into vector blends. */
#if defined(__clang__)
#define NO_TRAPPING_MATH /* clang: no such attribute, nor the need */
#else
#define NO_TRAPPING_MATH __attribute__((optimize("no-trapping-math")))
#endif
NO_TRAPPING_MATH __attribute__((target_clones("avx2", "default")))
static void locate_batch(const FaceF *f, int n, BatchF *b)
{
    const float(*M)[4] = f->clip;
    const float *row = f->row, res = f->res, near = f->near;
    /* perspective: texel width k_t d, slope k_z / d^2; ortho: constants */
    float kt = f->perspective ? f->texel : 0.0f, ct = f->perspective ? 0.0f : f->texel;
    float kz = f->perspective ? f->ndc_k : 0.0f, cz = f->perspective ? 0.0f : f->ndc_k;
    float pn = f->perspective ? 1.0f : 0.0f; /* ortho: the slope's denominator is 1 */
#pragma omp simd
    for (int i = 0; i < n; i++) {
        float x = b->x[i], y = b->y[i], z = b->z[i];
        float cx = M[0][0] * x + M[0][1] * y + M[0][2] * z + M[0][3];
        float cy = M[1][0] * x + M[1][1] * y + M[1][2] * z + M[1][3];
        float cq = M[2][0] * x + M[2][1] * y + M[2][2] * z + M[2][3];
        float cw = M[3][0] * x + M[3][1] * y + M[3][2] * z + M[3][3];
        float d = row[0] * x + row[1] * y + row[2] * z + row[3];
        int front = cw > 0.0f; /* behind a perspective face's eye: outside */
        float q = 1.0f / (front ? cw : 1.0f);
        float s = (cx * q + 1.0f) * 0.5f * res, t = (cy * q + 1.0f) * 0.5f * res, zn = cq * q;
        float dn = d < near ? near : d; /* depth clamped to the near plane (> 0 for perspective); NaN stays NaN */
        b->s[i] = s;
        b->t[i] = t;
        b->z_ndc[i] = zn;
        b->depth[i] = d;
        b->texel_world[i] = kt * d + ct;
        b->ndc_per_world[i] = kz / (pn * dn * dn + (1.0f - pn)) + cz;
        b->inside[i] = front & (s >= 0.0f) & (s < res) & (t >= 0.0f) & (t < res) & (zn >= 0.0f) & (zn <= 1.0f);
    }
}

/* Samples index[0, n) of the arrays on a FaceF map: lift by rt_ray_offset,
 * locate, normal offset, locate again. */
static void batch_locate(const FaceF *f, const SmapBias *b, const vec3 *p_world, const vec3 *n_geom_world,
                         const int *index, int n, BatchF *B)
{
    for (int k = 0; k < n; k++) { /* gathered into lanes, then lifted in them */
        vec3 p = p_world[index[k]], nrm = n_geom_world[index[k]];
        B->x[k] = p.x, B->y[k] = p.y, B->z[k] = p.z;
        B->nx[k] = nrm.x, B->ny[k] = nrm.y, B->nz[k] = nrm.z;
    }
    float extent = b->scene_extent;
#pragma omp simd
    for (int k = 0; k < n; k++) {
        float lift = rt_ray_offset(extent, v3(B->x[k], B->y[k], B->z[k]));
        B->x[k] += B->nx[k] * lift;
        B->y[k] += B->ny[k] * lift;
        B->z[k] += B->nz[k] * lift;
    }
    locate_batch(f, n, B);
    if (b->normal_offset_texels > 0.0) {
        float off = (float)b->normal_offset_texels;
        for (int k = 0; k < n; k++) {
            float step = off * B->texel_world[k];
            B->x[k] += B->nx[k] * step;
            B->y[k] += B->ny[k] * step;
            B->z[k] += B->nz[k] * step;
        }
        locate_batch(f, n, B);
    }
}

/* The same, then the biases per receiver. */
static void receivers_float(const ShadowMap *m, const FaceF *f, const SmapBias *b, const vec3 *p_world,
                            const vec3 *n_geom_world, const int *index, int n, SmapReceiver *r, bool *inside)
{
    BatchF B;
    batch_locate(f, b, p_world, n_geom_world, index, n, &B);
    for (int k = 0; k < n; k++) {
        SmapReceiver *o = &r[index[k]];
        o->mc = (MapCoord){.face = 0, .s = B.s[k], .t = B.t[k], .depth_linear = B.depth[k], .z_ndc = B.z_ndc[k],
                           .inside = B.inside[k] != 0, .warp_w = 1.0};
        o->texel_world = B.texel_world[k];
        inside[index[k]] = receiver_bias(m, b, d3(B.x[k], B.y[k], B.z[k]), d3(B.nx[k], B.ny[k], B.nz[k]),
                                         B.ndc_per_world[k], o);
    }
}

/* The lit candidates among samples [first, min(count, first + SMAP_BATCH))
 * (cls NULL: all), into index; their number. */
static int batch_candidates(const uint8_t *cls, int first, int count, int *index)
{
    int n = 0;
    for (int i = first; i < count && i < first + SMAP_BATCH; i++)
        if (!cls || cls[i] == SAMPLE_LIT_CANDIDATE) index[n++] = i;
    return n;
}

void smap_receivers(const ShadowMap *m, const SmapBias *b, const vec3 *p_world, const vec3 *n_geom_world,
                    const uint8_t *cls, int count, SmapReceiver *r, bool *inside)
{
    FaceF f;
    bool batched = face_float(m, &f);
    for (int i = 0; i < count; i++) inside[i] = false;
    for (int first = 0; first < count; first += SMAP_BATCH) {
        int index[SMAP_BATCH], n = batch_candidates(cls, first, count, index);
        if (batched) {
            receivers_float(m, &f, b, p_world, n_geom_world, index, n, r, inside);
            continue;
        }
        for (int k = 0; k < n; k++)
            inside[index[k]] = receiver_any(m, b, p_world[index[k]], n_geom_world[index[k]], &r[index[k]]);
    }
}

bool smap_receiver(const ShadowMap *m, const SmapBias *b, vec3 p_world, vec3 n_geom_world, SmapReceiver *r)
{
    bool inside;
    smap_receivers(m, b, &p_world, &n_geom_world, NULL, 1, r, &inside);
    return inside;
}

/* receiver_bias without a plane (slope_bias 0): the reference depths of a
 * located batch in double lanes, in receiver_bias's order of operations
 * (its slope term is then 0.0), so every reference is the same double. */
__attribute__((always_inline)) static inline void refs_lanes(const SmapBias *b, bool ndc, int bits,
                                                             double depth_range, const BatchF *B, int n, SmapRefs *o)
{
#pragma omp simd
    for (int k = 0; k < n; k++) {
        double z_ndc = B->z_ndc[k], depth = B->depth[k];
        double bias = constant_bias(b, ndc, bits, depth_range, z_ndc, depth, B->ndc_per_world[k]) + 0.0;
        o->ref_up[k] = smap_ref_up((ndc ? z_ndc : depth) - bias);
        o->s[k] = B->s[k];
        o->t[k] = B->t[k];
        o->face[k] = 0;
        o->inside[k] = B->inside[k] != 0;
    }
}

/* refs_lanes with the float32 formats' choices made before the loop, so
 * their loops run without branches (and in vector lanes where they can). */
static void refs_float(const ShadowMap *m, const SmapBias *b, const BatchF *B, int n, SmapRefs *o)
{
    const RasterView *rv = &m->view.face[0].raster;
    bool ndc = m->spec.depth == RASTER_DEPTH_NDC;
    int bits = m->spec.depth_bits;
    double range = rv->depth_far - rv->depth_near;
    if (bits) refs_lanes(b, ndc, bits, range, B, n, o);
    else if (ndc) refs_lanes(b, true, 0, range, B, n, o);
    else refs_lanes(b, false, 0, range, B, n, o);
}

void smap_refs(const ShadowMap *m, const SmapBias *b, const vec3 *p_world, const vec3 *n_geom_world,
               const uint8_t *cls, int count, SmapRefs *out)
{
    FaceF f;
    out->count = batch_candidates(cls, 0, count, out->sample);
    if (!(b->slope > 0.0) && face_float(m, &f)) {
        BatchF B;
        batch_locate(&f, b, p_world, n_geom_world, out->sample, out->count, &B);
        refs_float(m, b, &B, out->count, out);
        return;
    }
    SmapReceiver r[SMAP_BATCH];
    bool inside[SMAP_BATCH];
    smap_receivers(m, b, p_world, n_geom_world, cls, count, r, inside);
    for (int k = 0; k < out->count; k++) {
        const SmapReceiver *o = &r[out->sample[k]];
        out->inside[k] = inside[out->sample[k]];
        if (!out->inside[k]) continue;
        out->face[k] = o->mc.face;
        out->s[k] = o->mc.s;
        out->t[k] = o->mc.t;
        out->ref_up[k] = smap_ref_up(o->ref);
    }
}
