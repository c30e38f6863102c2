/* sm.c -- `sm`: Williams' shadow map with a nearest-texel test (course
 * §2.1) and the remedies of §2.1.2 against acne: constant, slope-scaled,
 * normal-offset and receiver-plane biases (smap.h), and the depth-layer
 * variants that need less bias: second-depth maps (Wang & Molnar 1994),
 * midpoint maps (Woo 1992: z_ref = (z1 + z2) / 2) and dual depth layers
 * (Weiskopf & Ertl 2003: z1 + min(delta_max, (z2 - z1) / 2)). */
#include <stdlib.h>
#include "resources/standard.h"
#include "techniques/smap.h"

enum { LAYERS_SINGLE, LAYERS_SECOND, LAYERS_MIDPOINT, LAYERS_DUAL };
static const char *const layer_names[] = {"single", "second_depth", "midpoint", "dual", NULL};
static const char *const second_names[] = {"backfaces", "peeled", NULL};

enum { P_LAYERS = SMAP_NUM_PARAMS, P_SECOND_LAYER, P_DUAL_MAX };

static const ParamDesc sm_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
    {"layers", PARAM_ENUM, LAYERS_SINGLE, 0, 3, "",
     "depth compared with: the first layer, the second (second_depth), their midpoint, or dual layers", layer_names},
    {"second_layer", PARAM_ENUM, 0, 0, 1, "",
     "how the second layer is made: nearest back faces (closed meshes only) or peeled behind the first (any mesh)",
     second_names},
    {"dual_max", PARAM_FLOAT, 0.1, 0, 1e6, "world units",
     "dual layers: the fixed distance threshold delta_max beyond the first layer", NULL},
};

static const ParamCondition sm_conditions[] = {
    {"second_layer", "layers=second_depth|midpoint|dual"},
    {"dual_max", "layers=dual"},
    {NULL, NULL},
};

static const char *const sm_resources[] = {"shadow_map", "view_samples", NULL};

typedef struct SmState {
    const ShadowMap *first, *second; /* either may be NULL when the mode does not read it */
    SmapBias bias;
    int layers;
    double dual_max_world;
} SmState;

static bool sm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    SmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    st->layers = (int)p[P_LAYERS];
    st->bias = smap_bias(p, ctx->scene);
    st->dual_max_world = p[P_DUAL_MAX];
    if (st->layers != LAYERS_SECOND) st->first = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (st->layers != LAYERS_SINGLE && (st->layers == LAYERS_SECOND || st->first)) {
        spec.layer = (int)p[P_SECOND_LAYER] == 0 ? MAP_LAYER_BACKFACES : MAP_LAYER_PEELED;
        st->second = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    }
    if ((st->layers != LAYERS_SECOND && !st->first) || (st->layers != LAYERS_SINGLE && !st->second)) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* The occluder depth the reference is compared with, from the layer(s). */
static double occluder_depth(const SmState *st, const SmapReceiver *r, int i, int j)
{
    const ShadowMap *m = st->first ? st->first : st->second;
    if (st->layers == LAYERS_SINGLE) return shadowmap_texel(st->first, r->mc.face, i, j);
    double z2 = shadowmap_texel(st->second, r->mc.face, i, j);
    if (st->layers == LAYERS_SECOND) return z2;
    double z1 = shadowmap_texel(st->first, r->mc.face, i, j);
    if (st->layers == LAYERS_MIDPOINT) return 0.5 * (z1 + z2); /* one layer only (z2 = inf): lit, Fig. 2.3's failure */
    double delta = st->dual_max_world; /* no second layer: the gap is unbounded, the threshold applies */
    if (m->spec.depth == RASTER_DEPTH_NDC) delta *= lightview_ndc_per_world(&m->view, &r->mc);
    return z1 + nan_min(delta, 0.5 * (z2 - z1));
}

static void sm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SmState *st = state;
    const ShadowMap *m = st->first ? st->first : st->second;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(m, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r)) {
            int i, j;
            smap_texel(&r, &i, &j);
            v = smap_test(smap_ref_at(&r, i, j), occluder_depth(st, &r, i, j));
        }
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_sm = {
    .name = "sm",
    .family = "shadow map",
    .source = "course §2.1, §2.1.2 (Williams 1978; biases; second-depth, midpoint, dual layers)",
    .summary = "shadow map from the light's centre, nearest-texel depth test, with every bias remedy of §2.1.2",
    .params = sm_params,
    .num_params = (int)(sizeof sm_params / sizeof sm_params[0]),
    .resources = sm_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "map_size",
    .conditions = sm_conditions,
    .prepare = sm_prepare,
    .evaluate = sm_evaluate,
    .release = free,
};
