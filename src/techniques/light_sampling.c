/* light_sampling.c -- `light_sampling`: multiple shadow maps (course §5.2.4,
 * its first paragraph: "the rasterised reference"). N points on the light,
 * one hard shadow map from each (a point light there), and the visibility of
 * a receiver the average of the N depth tests (course Eq. 1.4 by N-sample
 * quadrature: V = 1/N sum_k V(p, l_k)). Like the Embree reference it counts
 * only the samples above the receiver's tangent plane (docs/architecture.md,
 * *Sample classes*): V is the lit fraction of those. Each map is the shared
 * resource every shadow-map technique reads (same parameters, same biases,
 * same nearest-texel test as `sm`), so the error is the maps' aliasing plus
 * the quadrature's, which shrinks as N grows.
 *
 * The points are the reference's own for rect and disk lights: light_sample
 * at the (u, v) of a 2D pattern (R2 or independent), uniform over the area.
 * A sphere light is sampled on its central cross-section facing the scene's
 * centre (seed 000's assumption 1, as the single-map soft techniques read
 * it), so its limit differs from the reference's cone sampling where the
 * sphere looks oblique. */
#include <stdlib.h>
#include "core/hash.h"
#include "scene/light.h"
#include "techniques/multimap.h"

const char *const ls_pattern_names[] = {"r2", "random", NULL};
enum { P_SAMPLES = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PATTERN };

/* Each map is tested at one texel per sample: the receiver plane, a depth
 * per texel of a kernel, cannot act (SMAP_DEPTH_BIAS_PARAMS, as filtered.h). */
static const ParamDesc ls_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_DEPTH_BIAS_PARAMS,
    LS_SAMPLE_PARAMS,
};

static const char *const ls_resources[] = {"shadow_map", "view_samples", NULL};

typedef struct LsState {
    SmapBias bias;
    int n;
    vec3 point[LS_MAX_SAMPLES];           /* the light samples, world */
    const ShadowMap *map[LS_MAX_SAMPLES]; /* the hard map from each */
} LsState;

/* The light the samples are drawn on: the light itself, or a sphere's
 * cross-section, a disk of its radius facing the scene's centre. */
static Light sampled_light(const Scene *scene, const Light *light)
{
    Light l = *light;
    if (light->kind != LIGHT_SPHERE) return l;
    vec3 centre = v3_scale(v3_add(scene->bounds_min, scene->bounds_max), 0.5f);
    l.kind = LIGHT_DISK;
    l.direction = v3_normalize_or(v3_sub(centre, light->position), v3(0, -1, 0));
    return l;
}

/* Sample k of n on the light (world units). light_sample returns a direction
 * and distance from a viewpoint; any viewpoint off the light gives the same
 * area-uniform point, here the scene's centre moved off the light's plane. */
static vec3 light_point(const Scene *scene, const Light *l, SamplingPattern pattern, int k, int n)
{
    float u, v;
    sample_2d(pattern, sampling_stream(0x6c535f31u, 0), k, n, &u, &v);
    vec3 view = v3_add(v3_scale(v3_add(scene->bounds_min, scene->bounds_max), 0.5f), l->direction);
    LightSample s = light_sample(l, view, u, v);
    return v3_madd(view, s.dir_world, s.dist);
}

const ShadowMap *ls_point_map(const TechContext *ctx, const ShadowMapSpec *spec, vec3 point, Error *err)
{
    Scene s = *ctx->scene;
    Light l = {.kind = LIGHT_POINT, .position = point, .direction = ctx->light->direction,
               .color = ctx->light->color, .intensity = ctx->light->intensity};
    Hasher h;
    hash_init(&h);
    hash_u64(&h, ctx->scene->hash_lights[ctx->light_index]);
    hash_f32(&h, point.x);
    hash_f32(&h, point.y);
    hash_f32(&h, point.z);
    uint64_t hl = hash_final(&h); /* fit=view keys the map by the whole light */
    s.lights = &l;
    s.num_lights = 1;
    s.hash_lights = &hl;
    return res_shadow_map(ctx->rm, &s, 0, spec, err);
}

bool ls_sample_maps(const TechContext *ctx, const ShadowMapSpec *spec, int n, int pattern,
                    vec3 *point, const ShadowMap **map, Error *err)
{
    Light sampled = sampled_light(ctx->scene, ctx->light);
    SamplingPattern sp = pattern == LS_PAT_R2 ? SAMPLING_R2 : SAMPLING_RANDOM;
    Light probe = {.kind = LIGHT_POINT, .position = ctx->light->position};
    double total = (double)shadowmap_bytes_for(&probe, spec) * n;
    if (total > (double)SHADOWMAP_MAX_BYTES)
        return error_set(err, "samples = %d maps of map_size = %d take %.2f GiB, above the %.0f GiB "
                              "limit: lower samples or map_size",
                         n, spec->res, total / (1u << 30), (double)SHADOWMAP_MAX_BYTES / (1u << 30));
    for (int k = 0; k < n; k++) {
        point[k] = light_point(ctx->scene, &sampled, sp, k, n);
        map[k] = ls_point_map(ctx, spec, point[k], err);
        if (!map[k]) return false;
    }
    return true;
}

static bool ls_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    LsState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->n = (int)p[P_SAMPLES];
    st->bias = smap_depth_bias(p, ctx->scene);
    ShadowMapSpec spec = smap_spec(p);
    if (!ls_sample_maps(ctx, &spec, st->n, (int)p[P_PATTERN], st->point, st->map, err)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* The lit fraction of the samples above the tangent plane (all of them
 * when none is: a terminator sliver the N points miss). A depth test that
 * reads a NaN (smap_lit: neither lit nor shadowed) in the fraction makes it
 * NaN: the sums carry it (issue 13 §1; `lit > 0.5` read it as shadowed). */
static float visibility(const LsState *st, vec3 p, vec3 n)
{
    int above = 0;
    float lit_above = 0.0f, lit_all = 0.0f;
    for (int k = 0; k < st->n; k++) {
        SmapReceiver r;
        int i, j;
        float lit = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->map[k], &st->bias, p, n, &r)) {
            smap_texel(&r, &i, &j);
            lit = smap_lit(st->map[k], &r, i, j); /* 0, 1 or NaN */
        }
        bool up = v3_dot(n, v3_sub(st->point[k], p)) > 0.0f;
        above += up;
        lit_above += up ? lit : 0.0f;
        lit_all += lit;
    }
    return above ? lit_above / above : lit_all / st->n;
}

static void ls_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const LsState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        tech_store(ctx, out, begin, s, visibility(st, ctx->vs->p_world[s], ctx->vs->n_geom_world[s]));
    }
}

const Technique tech_light_sampling = {
    .name = "light_sampling",
    .family = "soft",
    .source = "course §5.2.4 (multiple shadow maps: the rasterised reference)",
    .summary = "N hard shadow maps from N points on the light, the receiver's lit fraction of those above its "
               "tangent plane; converges to the reference as N grows",
    .params = ls_params,
    .num_params = (int)(sizeof ls_params / sizeof ls_params[0]),
    .resources = ls_resources,
    .aux = NULL,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "samples",
    .prepare = ls_prepare,
    .evaluate = ls_evaluate,
    .release = free,
};
