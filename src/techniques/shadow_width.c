/* shadow_width.c -- `shadow_width`: Kirsch & Döllner's single-sample soft
 * shadows (seed 003). A depth map and a shadow-width map (resources/
 * shadowwidth.h) from the light's centre; per receiver the shadow depth
 * sd = z' - z(x', y') (§3, world units along the light's axis) and the
 * shadow width sw (the distance to the nearest unblocked texel, in world
 * units at the receiver) give the attenuation I(sd, sw) = 1 + c_bias -
 * c_scale sw / sd clamped to [0, 1], and 1 where sd = 0 (§3). Only points
 * inside the hard shadow are darkened: the penumbra is the inner half only
 * (§2, "our shadows are smaller than their physically correct counterparts").
 * §5's self-shadowing treatment renders the depth map from the farthest back
 * faces instead (a z-greater test). */
#include <stdlib.h>
#include "resources/maps/shadowwidth.h"
#include "techniques/smap.h"

enum { P_C_SCALE = SMAP_NUM_PARAMS, P_C_BIAS, P_NEIGHBOURS, P_START_DIFFERENCE, P_SELF_SHADOW, P_FILTER };
enum { SELF_BLOCKERS, SELF_BACKFACES };
enum { FILTER_NEAREST, FILTER_BILINEAR };

static const char *const neighbour_names[] = {SW_PROPAGATION_NAMES, NULL};
static const char *const self_names[] = {"blockers", "backfaces", NULL};
static const char *const filter_names[] = {"nearest", "bilinear", NULL};

static const ParamDesc sw_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
    {"c_scale", PARAM_FLOAT, 8, 0, 1e6, "",
     "softness of I = 1 + c_bias - c_scale sw/sd (§3), sw and sd in world units at the receiver: larger is harder; "
     "2 D / W matches the inner half-penumbra of a light W wide at distance D from the blocker; 0 lights everything",
     NULL},
    {"c_bias", PARAM_FLOAT, 0, 0, 1, "", "offset of I (§3: 0, or slightly more against artefacts at the shadow's "
                                         "outer border)", NULL},
    {"neighbours", PARAM_ENUM, SW_SOFTWARE4, 0, 2, "",
     "shadow-width propagation (§4): software4 (in-place sweeps over the 4 axis neighbours), doubling3 or doubling6 "
     "(texture-compositing passes over 3 or 6 neighbours, distance and difference doubling)",
     neighbour_names},
    {"start_difference", PARAM_FLOAT, 1.0 / 256.0, 1e-6, 1, "per texel",
     "d: the width one texel step adds (doubling: in the first pass); widths saturate at 1/d texels", NULL},
    {"self_shadow", PARAM_ENUM, SELF_BLOCKERS, 0, 1, "",
     "§5: blockers (the depth map holds the nearest surfaces, self-shadowing shapes act as blockers) or backfaces "
     "(the farthest back faces, a z-greater test: no self-shadowing, harder edges)",
     self_names},
    {"filter", PARAM_ENUM, FILTER_NEAREST, 0, 1, "",
     "depth and width lookups: nearest texel, or bilinear (§5 Filtering, Fig. 7: smooth at low resolutions, with "
     "discontinuities at the shadow's outer border)",
     filter_names},
};

/* c_bias offsets 1 - c_scale sw / sd, which c_scale = 0 makes 1 everywhere. */
static const ParamCondition sw_conditions[] = {{"c_bias", "c_scale!=0"}, {NULL, NULL}};

static const char *const sw_resources[] = {"shadow_map", "shadow_width_map", "view_samples", NULL};
static const char *const sw_aux[] = {"shadow_width", "shadow_depth", NULL};

typedef struct SwState {
    const ShadowMap *depth;     /* nearest surfaces, or farthest back faces */
    const ShadowWidthMap *width;
    SmapBias bias;
    double c_scale, c_bias;
    bool bilinear;
} SwState;

static bool sw_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    SwState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    ShadowWidthSpec ws = {(SwPropagation)(int)p[P_NEIGHBOURS], p[P_START_DIFFERENCE]};
    st->width = res_shadow_width_map(ctx->rm, ctx->scene, ctx->light_index, &spec, &ws, err);
    if ((int)p[P_SELF_SHADOW] == SELF_BACKFACES) spec.layer = MAP_LAYER_FARTHEST_BACKFACES;
    st->depth = st->width ? res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err) : NULL;
    if (!st->depth) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->c_scale = p[P_C_SCALE];
    st->c_bias = p[P_C_BIAS];
    st->bilinear = (int)p[P_FILTER] == FILTER_BILINEAR;
    *state = st;
    return true;
}

/* Seed 003 §3: I = 1 where sd <= 0 (nothing nearer the light), else
 * clamp(1 + c_bias - c_scale sw / sd). The stiff case sd -> 0+ is taken as
 * the comparison c_scale sw >= (1 + c_bias) sd (umbra), so no quotient
 * overflows and c_scale = 0 (I = 1) needs no special case. */
static double attenuation(double sd, double sw, double c_scale, double c_bias)
{
    if (isnan(sd) || isnan(sw)) return NAN; /* a NaN depth or width: unknown, not lit */
    if (!(sd > 0.0)) return 1.0;
    double x = c_scale * sw;
    if (x >= (1.0 + c_bias) * sd) return 0.0;
    return nan_min(1.0, 1.0 + c_bias - x / sd);
}

/* Shadow depth (world units) and width (texels) at the receiver. */
static void lookup(const SwState *st, const SmapReceiver *r, double *sd, double *sw_texels)
{
    const ShadowMap *m = st->depth;
    int i, j;
    smap_texel(r, &i, &j);
    double ref = smap_linear_depth(m, r->mc.face, smap_ref_at(r, i, j));
    double z = smap_linear_depth(m, r->mc.face, shadowmap_texel(m, r->mc.face, i, j));
    *sw_texels = shadow_width_texels(st->width, r->mc.face, i, j);
    if (st->bilinear) { /* hardware bilinear filtering of both textures (Fig. 7) */
        double fs = r->mc.s - 0.5, ft = r->mc.t - 0.5, zb = 0.0, wb = 0.0;
        int i0 = (int)floor(fs), j0 = (int)floor(ft);
        double ax = fs - i0, ay = ft - j0;
        for (int k = 0; k < 4; k++) {
            int di = k & 1, dj = k >> 1;
            double wt = (di ? ax : 1.0 - ax) * (dj ? ay : 1.0 - ay);
            zb += wt * smap_linear_depth(m, r->mc.face, shadowmap_texel(m, r->mc.face, i0 + di, j0 + dj));
            wb += wt * shadow_width_texels(st->width, r->mc.face, i0 + di, j0 + dj);
        }
        if (isfinite(zb)) z = zb; /* an empty texel (no caster) keeps the nearest lookup */
        *sw_texels = wb;
    }
    *sd = ref - z;
}

static void sw_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SwState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0, sd = 0.0, sw_texels = 0.0; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->depth, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r)) {
            lookup(st, &r, &sd, &sw_texels);
            v = attenuation(sd, sw_texels * r.texel_world, st->c_scale, st->c_bias);
        }
        tech_store(ctx, out, begin, s, (float)v);
        if (ctx->aux) {
            bool shadowed = sd > 0.0 && isfinite(sd);
            ctx->aux[2 * (size_t)s] = shadowed ? (float)sw_texels : 0.0f;
            ctx->aux[2 * (size_t)s + 1] = shadowed ? (float)sd : 0.0f;
        }
    }
}

const Technique tech_shadow_width = {
    .name = "shadow_width",
    .family = "soft",
    .source = "seed 003 §3-5 (Kirsch & Döllner 2003: shadow-width map, attenuation I(sd, sw))",
    .summary = "one light sample: depth map plus shadow-width map, attenuation 1 + c_bias - c_scale sw/sd inside the "
               "hard shadow",
    .params = sw_params,
    .num_params = (int)(sizeof sw_params / sizeof sw_params[0]),
    .resources = sw_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "c_scale",
    .conditions = sw_conditions,
    .prepare = sw_prepare,
    .evaluate = sw_evaluate,
    .release = free,
    .aux = sw_aux,
};
