/* accumulation.c -- `accumulation`: shadow accumulation (Aszódi &
 * Szirmay-Kalos, seed 000). One shadow map from the light's centre; each
 * lexel of the K x K neighbourhood of the receiver's own lexel q is an
 * elementary caster, projected back from the receiver onto the map's plane
 * (backproject.h), and the shadowing factor s = |D_c ∩ D| / |D| is
 * accumulated over them, D being the light's footprint on that plane:
 *   additive        the paper's second pseudo-code (assumptions 1-3, Eqs. 2
 *                   and 3): s = sum of size^2 over casters whose centre l_r
 *                   falls on the light, over the light's area in lexels;
 *   occlusion_bits  its first pseudo-code (Eq. 1): the lexels of D each
 *                   caster covers are marked, s = marked / |D| (set union).
 * The default is the occlusion bits, the paper's definition: the additive
 * sum point-samples each footprint by its centre, so once footprints outgrow
 * the light (small lights) the hard shadow vanishes (docs/soft-maps.md).
 * Both keep one caster per lexel, the map's first layer (assumption 2; the
 * first pseudo-code's layered depth image would need every layer, and a
 * peeled second layer of a closed mesh is only its own back face).
 * R is the scene's light (sphere, disk: radius; rect: its rectangle), so the
 * technique and the reference always see the same light. */
#include <stdlib.h>
#include "techniques/backproject.h"
#include "techniques/softmap.h"

enum { VARIANT_ADDITIVE, VARIANT_OBITS };
static const char *const variant_names[] = {"additive", "occlusion_bits", NULL};

enum { P_K = SMAP_NUM_PARAMS, P_VARIANT };

#define ACC_MAX_K 64 /* a kernel row is one 64-bit word of occlusion bits */

static const ParamDesc acc_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_BIAS_PARAMS_PLANE(1),
    {"K", PARAM_INT, 5, 1, ACC_MAX_K, "lexels",
     "kernel size: the K x K lexels visited around the receiver's own (seed 000: 5 for speed, 10 for quality)",
     NULL},
    {"variant", PARAM_ENUM, VARIANT_OBITS, 0, 1, "",
     "occlusion_bits (first pseudo-code, Eq. 1: union of the casters' footprints on the lexel grid) or additive "
     "(second pseudo-code, Eqs. 2-3: shadowing factors added; the paper's GPU version, which loses the shadow of "
     "lights smaller than its casters' footprints)",
     variant_names},
};

static const char *const acc_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};

typedef struct AccState {
    SoftMap sm;
    SmapBias bias;
    int K, variant;
} AccState;

static bool acc_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    AccState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&st->sm, ctx->rm, map, ctx->light, "accumulation", err)) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->K = (int)p[P_K];
    st->variant = (int)p[P_VARIANT];
    *state = st;
    return true;
}

/* One receiver's frame: its depth, the plane n (assumption 1), the scale
 * from plane-n tangent units to world units on the light's plane
 * (the similarity centred at r: n r_z / (r_z - n)), and the kernel's first lexel. */
typedef struct Frame {
    const SoftFace *f;
    double r_z, n, to_light;
    int i0, j0;
} Frame;

static bool frame(const AccState *st, const SmapReceiver *r, Frame *fr)
{
    fr->f = &st->sm.face[r->mc.face];
    const SoftFace *f = fr->f;
    fr->r_z = r->mc.depth_linear;
    double nx = backproject_plane(f->light.half_x, fr->r_z, 0.5 * st->K * f->dx);
    double ny = backproject_plane(f->light.half_y, fr->r_z, 0.5 * st->K * f->dy);
    fr->n = fmax(nx, ny); /* the light fits the kernel along both axes */
    if (!(fr->n > 0.0) || !(fr->n < fr->r_z)) return false; /* an edge-on light */
    fr->to_light = fr->n * fr->r_z / (fr->r_z - fr->n);
    fr->i0 = softmap_window_start(r->mc.s, st->K);
    fr->j0 = softmap_window_start(r->mc.t, st->K);
    return true;
}

/* Is a point (di, dj) lexels from q, on the plane, in the light's footprint D? */
static bool on_light(const Frame *fr, double di, double dj)
{
    return softlight_contains(&fr->f->light, di * fr->f->dx * fr->to_light, dj * fr->f->dy * fr->to_light);
}

/* The elementary caster of lexel (i, j), if it is in front of r. */
static bool caster(const AccState *st, const SmapReceiver *r, const Frame *fr, int i, int j, Backprojected *c)
{
    float stored = shadowmap_texel(st->sm.map, r->mc.face, i, j);
    if (!(smap_ref_at(r, i, j) > stored)) return false; /* course §2.1's test, with the biases */
    double c_z = smap_linear_depth(st->sm.map, r->mc.face, stored);
    return backproject(fr->r_z, c_z, fr->n, softmap_di(r, i), softmap_dj(r, j), c);
}

/* Second pseudo-code: s = sum size^2 [l_r on the light] / (light area in lexels). */
static double shadow_additive(const AccState *st, const SmapReceiver *r, const Frame *fr)
{
    double sum = 0.0;
    for (int j = fr->j0; j < fr->j0 + st->K; j++)
        for (int i = fr->i0; i < fr->i0 + st->K; i++) {
            Backprojected c;
            if (caster(st, r, fr, i, j, &c) && on_light(fr, c.di, c.dj)) sum += c.size * c.size;
        }
    double area = fr->f->light.area_world / (fr->to_light * fr->to_light * fr->f->dx * fr->f->dy);
    return fmin(1.0, sum / area);
}

/* Bits lo..hi (0 <= lo <= hi < 64). */
static uint64_t bit_range(int lo, int hi) { return (~0ull >> (63 - hi)) & (~0ull << lo); }

/* The kernel lexels k (0..K-1) whose centres lie in the open interval
 * (centre - half, centre + half) lexels from q; base = offset of lexel 0. */
static bool cover(double centre, double half, double base, int K, int *lo, int *hi)
{
    double a = fmax(ceil(centre - half - base), 0.0), b = fmin(floor(centre + half - base), K - 1.0);
    if (!(a <= b)) return false;
    *lo = (int)a;
    *hi = (int)b;
    return true;
}

static void mark(const Backprojected *c, double base_i, double base_j, int K, uint64_t *rows)
{
    int a0, a1, b0, b1;
    if (!cover(c->di, 0.5 * c->size, base_i, K, &a0, &a1) || !cover(c->dj, 0.5 * c->size, base_j, K, &b0, &b1)) return;
    uint64_t m = bit_range(a0, a1);
    for (int b = b0; b <= b1; b++) rows[b] |= m;
}

/* First pseudo-code: D = kernel lexels on the light; every caster marks the
 * lexels of D its footprint (size x size lexels about l_r) covers; s = |marked ∩ D| / |D|.
 * Its casters are those of the whole K x K square, as in the additive sum
 * (the pseudo-code loops over the lexels of D; the square's corners add the
 * casters nearer the light than n, which project inwards), so the two
 * variants differ only in Eq. 1 against Eqs. 2 and 3. */
static double shadow_obits(const AccState *st, const SmapReceiver *r, const Frame *fr, bool *empty)
{
    uint64_t light[ACC_MAX_K], hit[ACC_MAX_K] = {0};
    double base_i = softmap_di(r, fr->i0), base_j = softmap_dj(r, fr->j0);
    int lexels = 0;
    for (int b = 0; b < st->K; b++) {
        light[b] = 0;
        for (int a = 0; a < st->K; a++)
            if (on_light(fr, base_i + a, base_j + b)) light[b] |= 1ull << a;
        lexels += __builtin_popcountll(light[b]);
    }
    *empty = lexels == 0;
    if (*empty) return 0.0;
    for (int j = fr->j0; j < fr->j0 + st->K; j++)
        for (int i = fr->i0; i < fr->i0 + st->K; i++) {
            Backprojected c;
            if (caster(st, r, fr, i, j, &c)) mark(&c, base_i, base_j, st->K, hit);
        }
    int marked = 0;
    for (int b = 0; b < st->K; b++) marked += __builtin_popcountll(hit[b] & light[b]);
    return (double)marked / lexels;
}

/* Visibility 1 - s; an edge-on light, or a footprint that holds no lexel
 * centre (K = 1), falls back to the hard test of the receiver's lexel. */
static float visibility(const AccState *st, const SmapReceiver *r)
{
    Frame fr;
    if (frame(st, r, &fr)) {
        if (!softmap_may_block(&st->sm, r, fr.i0, fr.j0, fr.i0 + st->K - 1, fr.j0 + st->K - 1, NULL)) return 1.0f;
        if (st->variant == VARIANT_ADDITIVE) return (float)(1.0 - shadow_additive(st, r, &fr));
        bool empty;
        double s = shadow_obits(st, r, &fr, &empty);
        if (!empty) return (float)(1.0 - s);
    }
    int i, j;
    smap_texel(r, &i, &j);
    return smap_lit(st->sm.map, r, i, j);
}

static void acc_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const AccState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f; /* outside the map nothing is known to block: lit */
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r);
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_accumulation = {
    .name = "accumulation",
    .family = "soft",
    .source = "seed 000 (Aszódi & Szirmay-Kalos, shadow accumulation) §1.1, Eqs. 1-4 and both pseudo-codes",
    .summary = "each lexel of a K x K neighbourhood is an elementary caster projected back from the receiver; "
               "shadowing factors added (Eqs. 2-3) or united on the lexel grid (Eq. 1); R is the scene "
               "light's own size",
    .params = acc_params,
    .num_params = (int)(sizeof acc_params / sizeof acc_params[0]),
    .resources = acc_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "K",
    .prepare = acc_prepare,
    .evaluate = acc_evaluate,
    .release = free,
};
