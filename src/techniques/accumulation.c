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
 * technique and the reference always see the same light.
 *
 * The lexel grid follows the light (assumption 1: "setting n proportional to
 * R, the neighborhood in which the light source is visible from r can be
 * covered by the same number of lexels, K x K"). The paper's K x K window
 * reaches every caster only while its lexels are as wide as a K-th of the
 * light's footprint; on a map fitted to the scene that footprint spans
 * hundreds of lexels, the window sees a few casters near q, and the umbra
 * is lit. With grid=footprint the kernel reads the map's min-depth pyramid
 * at the level whose lexels are that wide: a lexel of level L is the
 * closest caster of its 2^L x 2^L texels (assumption 2, one caster per
 * lexel), so K of them span the footprint of the light from the nearest
 * blocker in reach, and n, the plane where the light covers the kernel,
 * lies in front of every caster. grid=map reads the map's own lexels
 * (level 0), the behaviour before. The level read is the aux channel
 * `level` (0 also where nothing in reach can block). */
#include <stdlib.h>
#include "techniques/backproject.h"
#include "techniques/softmap.h"

enum { VARIANT_ADDITIVE, VARIANT_OBITS };
static const char *const variant_names[] = {"additive", "occlusion_bits", NULL};
enum { GRID_FOOTPRINT, GRID_MAP };
static const char *const grid_names[] = {"footprint", "map", NULL};

enum { P_K = SMAP_NUM_PARAMS, P_VARIANT, P_GRID };

#define ACC_MAX_K 64 /* a kernel row is one 64-bit word of occlusion bits */

static const ParamDesc acc_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    {"K", PARAM_INT, 10, 1, ACC_MAX_K, "lexels",
     "kernel size: the K x K lexels visited around the receiver's own (seed 000 §1.1: 5 for speed, 10 \"good for "
     "every light size\"; the default: with grid=footprint a lexel is a K-th of the light's footprint, and 5 "
     "dilates every blocker by up to a fifth of its penumbra)",
     NULL},
    {"variant", PARAM_ENUM, VARIANT_OBITS, 0, 1, "",
     "occlusion_bits (first pseudo-code, Eq. 1: union of the casters' footprints on the lexel grid) or additive "
     "(second pseudo-code, Eqs. 2-3: shadowing factors added; the paper's GPU version, which loses the shadow of "
     "lights smaller than its casters' footprints)",
     variant_names},
    {"grid", PARAM_ENUM, GRID_FOOTPRINT, 0, 1, "",
     "the kernel's lexels (assumption 1: K x K lexels cover the light): footprint (a level of the map's min-depth "
     "pyramid, each lexel the closest caster of its texels, chosen per receiver so K lexels span the light's "
     "footprint from the nearest blocker in reach; aux `level`) or map (the map's own texels: on a large map the "
     "window misses most casters and the umbra is lit)",
     grid_names},
};

static const char *const acc_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};
static const char *const acc_aux[] = {"level", NULL};

typedef struct AccState {
    SoftMap sm;
    SmapBias bias;
    int K, variant, grid;
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
    st->grid = (int)p[P_GRID];
    *state = st;
    return true;
}

/* One receiver's frame: the pyramid level read and its lexels (2^level
 * texels a side, dx x dy tangent units), the receiver's map coordinates in
 * those lexels, its depth, the plane n (assumption 1), the scale from
 * plane-n tangent units to world units on the light's plane (the similarity
 * centred at r: n r_z / (r_z - n)), and the kernel's first lexel. */
typedef struct Frame {
    const SoftFace *f;
    int level, scale;
    double dx, dy, s, t;
    double r_z, n, to_light;
    int i0, j0;
} Frame;

/* The first level whose K lexels span the footprint from blockers at z_b
 * along both axes (K 2^L dx / 2 >= footprint), the pyramid's top at most. */
static int footprint_level(const AccState *st, const SoftFace *f, double r_z, double z_b)
{
    double texels = 2.0 / st->K * fmax(backproject_footprint(f->light.half_x, r_z, z_b) / f->dx,
                                       backproject_footprint(f->light.half_y, r_z, z_b) / f->dy);
    int level = 0;
    while (level + 1 < st->sm.pyramid->levels && (double)(1 << level) < texels) level++; /* NaN: level 0 */
    return level;
}

static bool frame(const AccState *st, const SmapReceiver *r, int level, Frame *fr)
{
    fr->f = &st->sm.face[r->mc.face];
    const SoftFace *f = fr->f;
    fr->level = level;
    fr->scale = 1 << level;
    fr->dx = f->dx * fr->scale;
    fr->dy = f->dy * fr->scale;
    fr->s = r->mc.s / fr->scale;
    fr->t = r->mc.t / fr->scale;
    fr->r_z = r->mc.depth_linear;
    double nx = backproject_plane(f->light.half_x, fr->r_z, 0.5 * st->K * fr->dx);
    double ny = backproject_plane(f->light.half_y, fr->r_z, 0.5 * st->K * fr->dy);
    fr->n = fmax(nx, ny); /* the light fits the kernel along both axes */
    if (!(fr->n > 0.0) || !(fr->n < fr->r_z)) return false; /* an edge-on light */
    fr->to_light = fr->n * fr->r_z / (fr->r_z - fr->n);
    fr->i0 = softmap_window_start(fr->s, st->K);
    fr->j0 = softmap_window_start(fr->t, st->K);
    return true;
}

/* The receiver's offset to lexel (i, j)'s centre, in lexels of the frame's level. */
static double lexel_di(const Frame *fr, int i) { return i + 0.5 - fr->s; }
static double lexel_dj(const Frame *fr, int j) { return j + 0.5 - fr->t; }

/* Is a point (di, dj) lexels from q, on the plane, in the light's footprint D? */
static bool on_light(const Frame *fr, double di, double dj)
{
    return softlight_contains(&fr->f->light, di * fr->dx * fr->to_light, dj * fr->dy * fr->to_light);
}

/* The elementary caster of lexel (i, j) of the frame's level: its closest
 * texel (assumption 2, one caster per lexel), tested as that texel alone
 * would be (course §2.1's test at its own reference, with the biases), so a
 * planar receiver does not shadow itself at any level. Its depth in *c_z. */
static bool caster_depth(const AccState *st, const SmapReceiver *r, const Frame *fr, int i, int j, double *c_z)
{
    int ti = i, tj = j;
    float stored = minmax_node_min(st->sm.pyramid, r->mc.face, fr->level, &ti, &tj);
    if (!(smap_ref_at(r, ti, tj) > stored)) return false; /* NaN: not a caster */
    *c_z = smap_linear_depth(st->sm.map, r->mc.face, stored);
    return true;
}

/* The same caster projected back from r (backproject.h), if it is in front of r. */
static bool caster(const AccState *st, const SmapReceiver *r, const Frame *fr, int i, int j, Backprojected *c)
{
    double c_z;
    return caster_depth(st, r, fr, i, j, &c_z) && backproject(fr->r_z, c_z, fr->n, lexel_di(fr, i), lexel_dj(fr, j), c);
}

/* The nearest caster depth of the frame's kernel; false: none. */
static bool nearest_caster(const AccState *st, const SmapReceiver *r, const Frame *fr, double *z_b)
{
    *z_b = INFINITY;
    for (int j = fr->j0; j < fr->j0 + st->K; j++)
        for (int i = fr->i0; i < fr->i0 + st->K; i++) {
            double c_z;
            if (caster_depth(st, r, fr, i, j, &c_z) && c_z < *z_b) *z_b = c_z;
        }
    return *z_b < INFINITY;
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
    double area = fr->f->light.area_world / (fr->to_light * fr->to_light * fr->dx * fr->dy);
    return fmin(1.0, sum / area);
}

/* Bits lo..hi (0 <= lo <= hi < 64). */
static uint64_t bit_range(int lo, int hi) { return (~0ull >> (63 - hi)) & (~0ull << lo); }

/* The kernel lexels k (0..K-1) whose centres lie in the open interval
 * (lo, hi) lexels from q; base = offset of lexel 0. */
static bool cover(double lo, double hi, double base, int K, int *k0, int *k1)
{
    double a = fmax(ceil(lo - base), 0.0), b = fmin(floor(hi - base), K - 1.0);
    if (!(a <= b)) return false;
    *k0 = (int)a;
    *k1 = (int)b;
    return true;
}

/* One axis of a caster's footprint on the plane (lexels from q): its lexel's
 * edges e_lo = d - 1/2 and e_hi = d + 1/2 scaled by its size (l_r - q =
 * size (l - q), backproject.h), each edge reaching the farther of its own
 * and its neighbour's projection of it (0: no caster there): gap filling,
 * course §5.2.3.3 ("gaps leak light. Fix by extending patches to the ...
 * neighbours", Guennebaud 2006; here all four, which "knowingly accepts
 * overocclusion"). Neighbouring lexels of one surface at different depths
 * project with different sizes, so elementary casters alone leave unmarked
 * slits of D between them, lit through a closed surface. */
static void footprint_axis(double d, double size, double size_lo, double size_hi, double *lo, double *hi)
{
    double e_lo = d - 0.5, e_hi = d + 0.5;
    *lo = fmin(size * e_lo, size_lo > 0.0 ? size_lo * e_lo : INFINITY);
    *hi = fmax(size * e_hi, size_hi > 0.0 ? size_hi * e_hi : -INFINITY);
}

/* First pseudo-code: D = kernel lexels on the light; every caster marks the
 * lexels of D its footprint (size x size lexels about l_r, joined to its
 * neighbours') covers; s = |marked ∩ D| / |D|.
 * Its casters are those of the whole K x K square, as in the additive sum
 * (the pseudo-code loops over the lexels of D; the square's corners add the
 * casters nearer the light than n, which project inwards), so the two
 * variants differ only in Eq. 1 against Eqs. 2 and 3. */
static double shadow_obits(const AccState *st, const SmapReceiver *r, const Frame *fr, bool *empty)
{
    uint64_t light[ACC_MAX_K], hit[ACC_MAX_K] = {0};
    float size[ACC_MAX_K + 2][ACC_MAX_K + 2] = {{0}}; /* the kernel's casters' sizes, a border of 0 */
    int K = st->K;
    double base_i = lexel_di(fr, fr->i0), base_j = lexel_dj(fr, fr->j0);
    int lexels = 0;
    for (int b = 0; b < K; b++) {
        light[b] = 0;
        for (int a = 0; a < K; a++)
            if (on_light(fr, base_i + a, base_j + b)) light[b] |= 1ull << a;
        lexels += __builtin_popcountll(light[b]);
    }
    *empty = lexels == 0;
    if (*empty) return 0.0;
    for (int b = 0; b < K; b++)
        for (int a = 0; a < K; a++) {
            Backprojected c;
            if (caster(st, r, fr, fr->i0 + a, fr->j0 + b, &c)) size[b + 1][a + 1] = (float)c.size;
        }
    for (int b = 0; b < K; b++)
        for (int a = 0; a < K; a++) {
            double sz = size[b + 1][a + 1], x0, x1, y0, y1;
            int a0, a1, b0, b1;
            if (!(sz > 0.0)) continue;
            footprint_axis(base_i + a, sz, size[b + 1][a], size[b + 1][a + 2], &x0, &x1);
            footprint_axis(base_j + b, sz, size[b][a + 1], size[b + 2][a + 1], &y0, &y1);
            if (!cover(x0, x1, base_i, K, &a0, &a1) || !cover(y0, y1, base_j, K, &b0, &b1)) continue;
            for (int k = b0; k <= b1; k++) hit[k] |= bit_range(a0, a1);
        }
    int marked = 0;
    for (int b = 0; b < K; b++) marked += __builtin_popcountll(hit[b] & light[b]);
    return (double)marked / lexels;
}

/* grid=footprint: the level whose K lexels span the light's footprint from
 * the nearest blocker in reach (a lower bound of every depth there, so the
 * kernel reaches every caster), then finer while the nearest caster the
 * kernel itself sees allows (the bound also counts receivers). Fills *fr;
 * false: nothing in reach can block r, or an edge-on light (fr->n unset). */
static bool footprint_frame(const AccState *st, const SmapReceiver *r, Frame *fr)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    double z_b;
    if (!backproject_search(&st->sm, r, &z_b)) return false;
    int level = footprint_level(st, f, r->mc.depth_linear, z_b);
    for (int pass = 0; pass < 2; pass++) {
        if (!frame(st, r, level, fr) || !nearest_caster(st, r, fr, &z_b)) return true;
        int finer = footprint_level(st, f, r->mc.depth_linear, z_b);
        if (finer >= level) return true;
        level = finer;
    }
    return frame(st, r, level, fr), true;
}

/* Visibility 1 - s; the level read in *level. An edge-on light, or a
 * footprint that holds no lexel centre (K = 1), falls back to the hard test
 * of the receiver's texel. */
static float visibility(const AccState *st, const SmapReceiver *r, int *level)
{
    Frame fr = {.n = NAN};
    *level = 0;
    if (st->grid == GRID_FOOTPRINT) {
        if (!footprint_frame(st, r, &fr)) return 1.0f;
    } else if (!frame(st, r, 0, &fr)) {
        fr.n = NAN;
    }
    if (fr.n > 0.0) {
        *level = fr.level;
        int s = fr.scale, i1 = (fr.i0 + st->K) * s - 1, j1 = (fr.j0 + st->K) * s - 1;
        double z_min;
        if (!softmap_may_block(&st->sm, r, fr.i0 * s, fr.j0 * s, i1, j1, &z_min)) return 1.0f;
        if (isnan(z_min)) return NAN; /* a NaN depth in the kernel (the pyramid keeps it): unknown, issue 13 §1 */
        if (st->variant == VARIANT_ADDITIVE) return (float)(1.0 - shadow_additive(st, r, &fr));
        bool empty;
        double v = 1.0 - shadow_obits(st, r, &fr, &empty);
        if (!empty) return (float)v;
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
        int level = 0;
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r, &level);
        tech_store(ctx, out, begin, s, v);
        if (ctx->aux) ctx->aux[s] = (float)level;
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
    .aux = acc_aux,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "K",
    .prepare = acc_prepare,
    .evaluate = acc_evaluate,
    .release = free,
};
