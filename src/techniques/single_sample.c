/* single_sample.c -- `single_sample_rt`: seed 002 (Parker, Shirley & Smits,
 * "Single Sample Soft Shadows", 1998; course §5.3.1). One shadow ray toward
 * the light's centre. A caster on it (the opaque inner object: the casters'
 * BVH, exactly as `hard` traces it) gives s = 0; otherwise the soft-edged
 * outer objects it grazes (rt/outer.h) give s. Outer penumbra only: the umbra
 * is the hard shadow's, and the penumbra is added outside it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/hash.h"
#include "resources/standard.h"
#include "rt/outer.h"
#include "techniques/technique.h"

static const char *const combine_choices[] = {"min", "product", "sum", NULL};
static const char *const falloff_choices[] = {"polynomial", "sinusoid", NULL};

enum { P_COMBINE, P_FALLOFF, P_ANALYTIC_SPHERES, P_OFFSET_SCALE };
static const ParamDesc ss_params[] = {
    {"combine", PARAM_ENUM, OUTER_MIN, 0, 2, "",
     "how the attenuations s_i of several grazed occluders combine (seed 002 §3): min (the paper's), product, or sum",
     combine_choices},
    {"falloff", PARAM_ENUM, OUTER_POLYNOMIAL, 0, 1, "",
     "s(tau) across the outer shell: polynomial 3t^2 - 2t^3 (the paper's) or the sinusoid (1 + sin(pi t - pi/2))/2",
     falloff_choices},
    {"analytic_spheres", PARAM_BOOL, 1, 0, 1, "",
     "procedural spheres as exact spheres (the paper's appendix); false: by their tessellation's outer triangles",
     NULL},
    {"offset_scale", PARAM_FLOAT, 1.0, 0.0, 1e4, "x rt_ray_offset",
     "ray-origin offset along the geometric normal, as a multiple of the engine's scale-aware offset", NULL},
};

static const char *const ss_resources[] = {"embree_bvh", "outer_objects", NULL};

/* ---- the outer objects as a resource -------------------------------------- */

typedef struct OuterArgs {
    const Scene *scene;
    bool analytic;
} OuterArgs;

static void *build_outer(const void *args, Error *err)
{
    const OuterArgs *a = args;
    return outer_scene_create(a->scene, a->analytic, err);
}
static size_t outer_bytes(const void *r) { return outer_scene_bytes(r); }
static void outer_destroy(void *r) { outer_scene_release(r); }
static const ResourceKind kind_outer = {"outer_objects", outer_bytes, outer_destroy, RES_FRAME};

/* Keyed by exactly its inputs: the caster triangles and, when used, the
 * analytic spheres. Not the light: b is formed per ray, so a sweep of the
 * light's size reuses it. */
static uint64_t outer_key(const Scene *scene, bool analytic)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, scene->hash_casters);
    hash_u64(&h, analytic);
    for (int i = 0; analytic && i < scene->num_objects; i++) {
        const Object *o = &scene->objects[i];
        if (!o->caster || !o->is_sphere) continue;
        hash_u64(&h, (uint64_t)i);
        const float f[4] = {o->sphere_center_world.x, o->sphere_center_world.y, o->sphere_center_world.z,
                            o->sphere_radius_world};
        for (int k = 0; k < 4; k++) hash_f32(&h, f[k]);
    }
    return hash_final(&h);
}

static const OuterScene *res_outer(ResourceManager *rm, const Scene *scene, bool analytic, Error *err)
{
    OuterArgs a = {scene, analytic};
    char desc[160];
    snprintf(desc, sizeof desc, "casters, %s spheres", analytic ? "analytic" : "tessellated");
    return rm_acquire(rm, &kind_outer, outer_key(scene, analytic), desc, build_outer, &a, err);
}

/* ---- prepare and evaluate ------------------------------------------------- */

typedef struct SingleSampleState {
    RTCScene casters;
    const OuterScene *outer;
    float extent, diameter;
} SingleSampleState;

static bool ss_prepare(const TechContext *ctx, void **state, Error *err)
{
    float diameter = outer_light_diameter(ctx->light);
    const RtScene *casters = res_bvh(ctx->rm, ctx->scene, RT_CASTERS, err);
    const OuterScene *outer = casters ? res_outer(ctx->rm, ctx->scene, ctx->params[P_ANALYTIC_SPHERES] != 0.0, err) : NULL;
    if (!outer) return false;
    SingleSampleState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    *st = (SingleSampleState){rt_scene_handle(casters), outer, scene_extent(ctx->scene), diameter};
    *state = st;
    return true;
}

/* The inner objects: is the segment from org to the light's centre blocked?
 * (the same ray as `hard`'s, so the two agree as D -> 0). */
static bool inner_blocked(RTCScene casters, vec3 org, const LightSample *ls)
{
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    struct RTCRay ray = {
        .org_x = org.x, .org_y = org.y, .org_z = org.z, .tnear = 0.0f,
        .dir_x = ls->dir_world.x, .dir_y = ls->dir_world.y, .dir_z = ls->dir_world.z,
        .tfar = ls->dist * (1.0f - 1e-5f), .mask = 0xFFFFFFFFu};
    rt_occluded1(casters, &ictx, &ray);
    return ray.tfar == -INFINITY;
}

static void ss_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SingleSampleState *st = state;
    float offset_scale = (float)ctx->params[P_OFFSET_SCALE];
    OuterRay ray = {.light_diameter = st->diameter,
                    .combine = (OuterCombine)ctx->params[P_COMBINE],
                    .falloff = (OuterFalloff)ctx->params[P_FALLOFF]};
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        vec3 p = ctx->vs->p_world[s];
        LightSample ls = light_sample_center(ctx->light, p);
        ray.org_world = v3_madd(p, ctx->vs->n_geom_world[s], offset_scale * rt_ray_offset(st->extent, p));
        ray.dir_world = ls.dir_world;
        ray.light_dist = ls.dist;
        out[s - begin] = inner_blocked(st->casters, ray.org_world, &ls) ? 0.0f : outer_scene_attenuation(st->outer, &ray);
    }
}

const Technique tech_single_sample_rt = {
    .name = "single_sample_rt",
    .family = "ray traced",
    .source = "seed 002 (Parker, Shirley & Smits 1998, §3 and appendix); course §5.3.1",
    .summary = "one shadow ray toward the light's centre; soft-edged outer objects (b = D t0 / ||l - o||) add an "
               "outer penumbra to the hard shadow",
    .params = ss_params,
    .num_params = (int)(sizeof ss_params / sizeof ss_params[0]),
    .resources = ss_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = NULL,
    .prepare = ss_prepare,
    .evaluate = ss_evaluate,
    .release = free,
};
