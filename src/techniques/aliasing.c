/* aliasing.c -- `aliasing`: the sampling-error analysis of course §3.1 as a
 * technique, so every parametrisation of the shared map parameters (warps,
 * fits, cascades) can be measured by the CLI, Lua sweeps and the stability
 * suite alike. Its visibility is the map's nearest-texel test (what `sm`
 * with single layers gives); its auxiliary channels are the instrument's
 * readings per sample (resources/analysis/aliasing.h): m = max(m_s, m_t), m_s and
 * m_t (pixels per texel step along each map axis; > 1 undersampled), the
 * projection factor cos(alpha)/cos(beta) of Eq. 3.1, and the cascade used
 * (1-based; 0 where nothing was measured). `shadowlab aliasing` writes the
 * full report (colour map, histogram, profile along depth, storage). */
#include <stdlib.h>
#include "resources/analysis/aliasing.h"
#include "techniques/smap.h"

static const ParamDesc aliasing_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
};

static const char *const aliasing_resources[] = {"shadow_map", "aliasing", "view_samples", NULL};
static const char *const aliasing_aux[] = {"m", "m_s", "m_t", "proj", "cascade", NULL};

typedef struct AliasingState {
    const ShadowMap *map;
    const AliasingMap *an;
    SmapBias bias;
} AliasingState;

static bool aliasing_prepare(const TechContext *ctx, void **state, Error *err)
{
    AliasingState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(ctx->params);
    st->map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    st->an = st->map ? res_aliasing(ctx->rm, ctx->scene, ctx->light_index, st->map, err) : NULL;
    if (!st->an) {
        free(st);
        return false;
    }
    st->bias = smap_bias(ctx->params, ctx->scene);
    *state = st;
    return true;
}

static void aliasing_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const AliasingState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f;
        if (smap_receiver(st->map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r)) {
            int i, j;
            smap_texel(&r, &i, &j);
            v = smap_lit(st->map, &r, i, j);
        }
        tech_store(ctx, out, begin, s, v);
        if (!ctx->aux) continue;
        float *a = ctx->aux + (size_t)s * 5;
        bool measured = st->an->face[s] >= 0;
        a[0] = measured ? fmaxf(st->an->m_s[s], st->an->m_t[s]) : 0.0f;
        a[1] = measured ? st->an->m_s[s] : 0.0f;
        a[2] = measured ? st->an->m_t[s] : 0.0f;
        a[3] = measured ? st->an->proj[s] : 0.0f;
        a[4] = (float)(st->an->face[s] + 1);
    }
}

const Technique tech_aliasing = {
    .name = "aliasing",
    .family = "analysis",
    .source = "course §3.1 (Eq. 3.1, Stamminger & Drettakis 2002; Eq. 3.2, Lloyd et al. 2008)",
    .summary = "sampling-error analysis of the shadow map in use: per-sample m along both map axes (aux), with the "
               "map's nearest-texel shadow as visibility",
    .params = aliasing_params,
    .num_params = (int)(sizeof aliasing_params / sizeof aliasing_params[0]),
    .resources = aliasing_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "map_size",
    .prepare = aliasing_prepare,
    .evaluate = aliasing_evaluate,
    .release = free,
    .aux = aliasing_aux,
};
