/* smrt.c -- `smrt`: shadow-map ray tracing as engines ship it (Unreal
 * Engine 5's virtual shadow maps, "SMRT"; Blender's EEVEE Next: "EEVEE
 * uses a technique called Virtual Shadow Mapping along with Shadow Map
 * Raytracing", Blender manual 4.2, Light Settings). One depth map from the light's
 * centre is read as a height field: for a receiver p (the lifted lookup
 * point of smap_receiver) and `rays` points L on the light,
 *  1. the segment p -> L is cut where it reaches the map's near plane
 *     (nothing is stored before it), and `spread` of that part is marched:
 *     t in (0, t_max], t_max = spread (z_p - n) / (z_p - z_L) in depths along
 *     the receiver's face (t = 1: the light point);
 *  2. `steps` samples t_k = t_max u_k^2, u_k = (N - k - xi) / N, k = 0 ..
 *     N - 1, jittered per ray by xi in [0, 1) (UE5's per-pixel step dither),
 *     are visited from the light end toward the receiver. [OWN] the square
 *     packs them toward the receiver: the stretch of a ray that lies in
 *     front of a caster's visible face yet inside its silhouette shrinks
 *     with the caster's distance from the receiver (similar triangles), so
 *     contacts need the finest steps; measured against uniform t_k (7 x 8,
 *     160 x 120, 64 samples), umbra leak contact 0.056 -> 0.034, bunny 0.063
 *     -> 0.017, ball-and-disk 0.061 -> 0.008, overlap 0.0125 -> 0.0112,
 *     sphere-on-plane 0.0047 -> 0.0064 (penumbra RMSE within 0.01 but for
 *     overlap, 0.090 -> 0.101). Each sample is located in the map (its own
 *     face), with ray depth z_k and stored depth d_k (linear, world units
 *     along that face's axis; +INFINITY where nothing was drawn or the
 *     sample is off the map);
 *  3. a sample with z_k <= d_k + tol is in front of the stored surface: it
 *     is "valid" and updates the history (d_v, z_v) and the surface's slope
 *     s = (d_v - d_v') / (z_v - z_v') between the last two valid samples
 *     of the same face, clamped to [-slope_limit, slope_limit];
 *  4. a sample behind the stored surface (z_k > d_k + tol) is one the map
 *     cannot see through: the occluder depth there is extrapolated from the
 *     last valid sample, e = d_v + s (z_k - z_v) (UE5's cvar help: "Maximum
 *     depth slope when extrapolating behind occluders"), and the ray is occluded
 *     when it lies behind that by more than tol: z_k > e + tol. Without a
 *     valid sample before it (the first sample already behind) e = d_k;
 *  5. V = the fraction of the rays above the receiver's tangent plane (the
 *     reference's horizon rule, architecture.md) that no sample occluded.
 * [OWN] step 4's reading: the surface the ray was seen in front of
 * continues behind the nearer one; if the ray passes in front of that
 * continuation it passed *under* the nearer occluder (its thickness is
 * unknown, so it is taken as thin): light leaks behind second occluders,
 * the trade-off Epic's cvar help states for the slope ("Higher values allow
 * softer penumbra edges but can introduce light leaks behind second
 * occluders", r.Shadow.Virtual.SMRT.ExtrapolateMaxSlopeLocal; here the
 * slope moves the measured errors by 0.003 at most, docs/backprojection.md). The march runs from the light end because
 * the extrapolation needs the occluder's own surface in the history; from
 * the receiver end the history would hold the receiver's surface, which a
 * ray rising toward the light never falls behind. Thin casters whose
 * footprint in the map lies between two samples are stepped over: with few
 * steps thin walls leak (test_smrt measures it). tol is the shared depth
 * bias at the receiver (smap.h's block; `bias` is the constant thickness in
 * world units). Sources for the counts (UE 5.4's cvar help and defaults):
 * r.Shadow.Virtual.SMRT.RayCountLocal (7) and SamplesPerRayLocal (8);
 * Blender's Python API, SceneEEVEE.shadow_ray_count (1 to 4) and
 * shadow_step_count (1 to 16);
 * UE5's RayLengthScale help ("Shorter rays limit the screen space size of
 * shadow penumbra, while longer rays require more samples to avoid
 * shadows disconnecting from contact points") for `spread`. No screen-space
 * ray (UE5's ScreenRayLength, the contact trace before the lookup) here. */
#include <stdlib.h>
#include "core/sampling.h"
#include "scene/light.h"
#include "techniques/smap.h"

enum { P_RAYS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_STEPS, P_SLOPE_LIMIT, P_SPREAD, P_SEED };

#define SMRT_MAX_RAYS 8
#define SMRT_MAX_STEPS 16

static const ParamDesc smrt_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_DEPTH_BIAS_PARAMS,
    {"rays", PARAM_INT, 7, 1, SMRT_MAX_RAYS, "rays",
     "rays per receiver toward points of the light (an R2 set rotated per pixel); 7 is UE5's "
     "r.Shadow.Virtual.SMRT.RayCountLocal, Blender's shadow_ray_count is 1 to 4",
     NULL},
    {"steps", PARAM_INT, 8, 1, SMRT_MAX_STEPS, "samples",
     "depth-map samples per ray, from the light end toward the receiver; 8 is UE5's SamplesPerRayLocal, "
     "Blender's shadow_step_count is 1 to 16 (default 6)",
     NULL},
    {"slope_limit", PARAM_FLOAT, 0.05, 0, 1000, "depth / ray depth",
     "clamp of the occluder's depth slope (stored depth change per unit of the ray's depth, both linear) "
     "extrapolated behind a surface: larger softens penumbrae and leaks behind second occluders (UE5's "
     "ExtrapolateMaxSlopeLocal, default 0.05); 0: the occluder is extrapolated at constant depth",
     NULL},
    {"spread", PARAM_FLOAT, 1, 0.01, 1, "fraction",
     "the marched part of each ray, as a fraction of its path from the receiver to the map's near plane "
     "(shorter rays bound the penumbra's size, UE5's RayLengthScale)",
     NULL},
    {"seed", PARAM_INT, 0, 0, 2147483647, "",
     "seed of the per-pixel rotation of the light points and of the step jitter (deterministic)", NULL},
};

/* The slope is read between two valid samples before a third one behind
 * the surface: with fewer steps there is never one to extrapolate. */
static const ParamCondition smrt_conditions[] = {
    {"slope_limit", "steps!=1|2"},
    {NULL, NULL},
};

static const char *const smrt_resources[] = {"shadow_map", "view_samples", NULL};

typedef struct SmrtState {
    const ShadowMap *map;
    SmapBias bias;
    int rays, steps;
    double slope_limit, spread;
    uint32_t seed;
} SmrtState;

static bool smrt_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    SmrtState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    st->map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!st->map) {
        free(st);
        return false;
    }
    st->bias = smap_depth_bias(p, ctx->scene);
    st->rays = (int)p[P_RAYS];
    st->steps = (int)p[P_STEPS];
    st->slope_limit = p[P_SLOPE_LIMIT];
    st->spread = p[P_SPREAD];
    st->seed = (uint32_t)p[P_SEED];
    *state = st;
    return true;
}

/* A hash as a number in [0, 1). */
static double unit(uint32_t h) { return (h >> 8) * (1.0 / 16777216.0); }

/* Light point i of n for sample s: Roberts' R2 set (2018, the plastic
 * number g: alpha = (1/g, 1/g^2)), Cranley-Patterson rotated per pixel by a
 * hash of (seed, s), so neighbouring pixels see different points and the
 * n points of one pixel stay stratified. */
static void light_point_2d(uint32_t pixel_hash, int i, float *u, float *v)
{
    const double g = 1.32471795724474602596, a1 = 1.0 / g, a2 = 1.0 / (g * g);
    double x = 0.5 + a1 * (i + 1) + unit(pixel_hash), y = 0.5 + a2 * (i + 1) + unit(sampling_stream(pixel_hash, 1u));
    *u = (float)(x - floor(x));
    *v = (float)(y - floor(y));
    if (*u >= 1.0f) *u = nextafterf(1.0f, 0.0f); /* rounding to float may reach 1 */
    if (*v >= 1.0f) *v = nextafterf(1.0f, 0.0f);
}

/* The stored depth under a world point and the point's own depth, both
 * linear along the point's face; +INFINITY stored off the map. */
typedef struct MarchSample { int face; double z, d; } MarchSample;

static MarchSample march_sample(const ShadowMap *m, dvec3 x)
{
    MapCoord mc = lightview_locate(&m->view, x);
    MarchSample ms = {mc.face, mc.depth_linear, INFINITY};
    if (mc.inside)
        ms.d = smap_linear_depth(m, mc.face, shadowmap_texel(m, mc.face, (int)floor(mc.s), (int)floor(mc.t)));
    return ms;
}

/* The marched fraction of p -> L: spread of the part before the near plane
 * of the receiver's face (all of it when L lies beyond that plane). */
static double march_length(const SmrtState *st, const SmapReceiver *r, dvec3 l)
{
    const RasterView *rv = &st->map->view.face[r->mc.face].raster;
    double z_p = r->mc.depth_linear, z_l = lightview_locate_on(&st->map->view, r->mc.face, l).depth_linear;
    double n = rv->depth_near, t_near = 1.0;
    if (z_l < n && n < z_p) t_near = (z_p - n) / (z_p - z_l); /* z_p - z_l > z_p - n > 0: in (0, 1) */
    return st->spread * t_near;
}

/* The surface history of one ray (steps 3 and 4). */
typedef struct History { bool valid, sloped; int face; double d, z, slope; } History;

static void history_add(const SmrtState *st, History *h, const MarchSample *ms)
{
    if (!isfinite(ms->d) || (h->valid && h->face != ms->face)) { /* no surface, or another face's metric */
        *h = (History){.valid = isfinite(ms->d), .face = ms->face, .d = ms->d, .z = ms->z};
        return;
    }
    if (h->valid && ms->z != h->z) {
        h->slope = nan_clamp((ms->d - h->d) / (ms->z - h->z), -st->slope_limit, st->slope_limit);
        h->sloped = true;
    }
    h->valid = true;
    h->face = ms->face;
    h->d = ms->d;
    h->z = ms->z;
}

/* 1 lit, 0 occluded, NaN when a sample read a NaN depth before any hit. */
static double ray_visibility(const SmrtState *st, dvec3 p, dvec3 l, double t_max, double xi, double tol)
{
    History h = {.valid = false};
    int n = st->steps;
    for (int k = 0; k < n; k++) {
        double u = (n - k - xi) / n, t = t_max * u * u;
        MarchSample ms = march_sample(st->map, d3_madd(p, d3_sub(l, p), t));
        if (isnan(ms.d) || isnan(ms.z)) return NAN;
        if (ms.z <= ms.d + tol) { /* in front of the stored surface */
            history_add(st, &h, &ms);
            continue;
        }
        double e = ms.d; /* behind it: the occluder's depth here, extrapolated when the history allows */
        if (h.valid && h.face == ms.face) e = h.d + (h.sloped ? h.slope * (ms.z - h.z) : 0.0);
        if (ms.z > e + tol) return 0.0;
    }
    return 1.0;
}

/* The comparison tolerance in linear depth (world units): the receiver's
 * bias, converted from NDC where the map stores that. */
static double tolerance_world(const SmrtState *st, const SmapReceiver *r)
{
    if (st->map->spec.depth != RASTER_DEPTH_NDC) return r->bias;
    double k = lightview_ndc_per_world(&st->map->view, &r->mc);
    return k > 0.0 ? r->bias / k : INFINITY; /* a flat NDC slope: no depth can be told apart */
}

static float visibility(const SmrtState *st, const TechContext *ctx, const SmapReceiver *r, int s)
{
    vec3 n_geom = ctx->vs->n_geom_world[s];
    vec3 p_f = d3_to_f(r->p_world);
    dvec3 n = d3_from(n_geom);
    double tol = tolerance_world(st, r), lit = 0.0;
    uint32_t hash = sampling_stream(st->seed, (uint32_t)s);
    int kept = 0;
    for (int i = 0; i < st->rays; i++) {
        float u, v;
        light_point_2d(hash, i, &u, &v);
        LightSample ls = light_sample(ctx->light, p_f, u, v);
        if (!(d3_dot(d3_from(ls.dir_world), n) > 0.0)) continue; /* below the horizon: shading, not shadow */
        dvec3 l = d3_madd(r->p_world, d3_from(ls.dir_world), ls.dist);
        double xi = unit(sampling_stream(hash, 2u + (uint32_t)i));
        lit += ray_visibility(st, r->p_world, l, march_length(st, r, l), xi, tol);
        kept++;
    }
    if (kept == 0) { /* the light is above the plane only in a sliver none of the points reached */
        LightSample ls = light_sample_highest(ctx->light, p_f, n_geom);
        dvec3 l = d3_madd(r->p_world, d3_from(ls.dir_world), ls.dist);
        return (float)ray_visibility(st, r->p_world, l, march_length(st, r, l), unit(hash), tol);
    }
    return (float)(lit / kept);
}

static void smrt_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SmrtState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, ctx, &r, s);
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_smrt = {
    .name = "smrt",
    .family = "soft",
    .source = "Unreal Engine 5 virtual shadow maps' shadow-map ray tracing (SMRT); Blender EEVEE Next",
    .summary = "per receiver a few rays toward points on the light, each marched through the depth map from the "
               "light end in a few steps; behind a surface the occluder's depth is extrapolated from the last "
               "sample in front of it; V the fraction of rays not occluded",
    .params = smrt_params,
    .num_params = (int)(sizeof smrt_params / sizeof smrt_params[0]),
    .resources = smrt_resources,
    .aux = NULL,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "rays",
    .conditions = smrt_conditions,
    .prepare = smrt_prepare,
    .evaluate = smrt_evaluate,
    .release = free,
};
