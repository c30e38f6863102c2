/* hard.c -- `hard`: one ray-traced occlusion test from each view sample
 * toward the light's centre (course §2: the point-light shadow, Eq. 1.1 with a
 * single light sample). Every soft technique must converge to it as the light
 * shrinks; the stability suite tests that limit. */
#include <math.h>
#include <stdlib.h>
#include "resources/standard.h"
#include "techniques/technique.h"

static const ParamDesc hard_params[] = {
    {"offset_scale", PARAM_FLOAT, 1.0, 0.0, 1e4, "x rt_ray_offset",
     "ray-origin offset along the geometric normal, as a multiple of the engine's scale-aware offset (0 shows self-intersection acne)",
     NULL},
};

static const char *const hard_resources[] = {"embree_bvh", NULL};

typedef struct HardState {
    RTCScene rtc;
    float extent;
} HardState;

static bool hard_prepare(const TechContext *ctx, void **state, Error *err)
{
    const RtScene *bvh = res_bvh(ctx->rm, ctx->scene, RT_CASTERS, err);
    if (!bvh) return false;
    HardState *hs = malloc(sizeof *hs);
    if (!hs) return error_set(err, "out of memory");
    hs->rtc = rt_scene_handle(bvh);
    hs->extent = scene_extent(ctx->scene);
    *state = hs;
    return true;
}

static void hard_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const HardState *hs = state;
    float offset_scale = (float)ctx->params[0];
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    for (int s = begin; s < end; s++) {
        float *o = out + (size_t)(s - begin) * (size_t)ctx->channels;
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        vec3 p = ctx->vs->p_world[s];
        LightSample ls = light_sample_center(ctx->light, p);
        vec3 org = v3_madd(p, ctx->vs->n_geom_world[s], offset_scale * rt_ray_offset(hs->extent, p));
        struct RTCRay ray = {
            .org_x = org.x, .org_y = org.y, .org_z = org.z, .tnear = 0.0f,
            .dir_x = ls.dir_world.x, .dir_y = ls.dir_world.y, .dir_z = ls.dir_world.z,
            .tfar = isinf(ls.dist) ? INFINITY : ls.dist * (1.0f - 1e-5f), .mask = 0xFFFFFFFFu};
        rt_occluded1(hs->rtc, &ictx, &ray);
        float vis = ray.tfar == -INFINITY ? 0.0f : 1.0f;
        for (int c = 0; c < ctx->channels; c++) o[c] = vis;
    }
}

const Technique tech_hard = {
    .name = "hard",
    .family = "ray traced",
    .source = "course §2 (Eq. 1.1, one light sample)",
    .summary = "ray-traced point-light shadow toward the light's centre: the limit every soft technique converges to",
    .params = hard_params,
    .num_params = (int)(sizeof hard_params / sizeof hard_params[0]),
    .resources = hard_resources,
    .rgb = true,
    .lights = LIGHTS_ALL,
    .main_param = NULL,
    .prepare = hard_prepare,
    .evaluate = hard_evaluate,
    .release = free,
};
