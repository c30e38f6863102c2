/* pcf.c -- `pcf`: percentage-closer filtering (Reeves 1987; course §4.1.2,
 * Eq. 4.1): the depth test is done first, then filtered,
 * pcf(p) = sum_q w(p - q) S(p_z, z_q). Kernels: a K x K box; the same box
 * over hardware-style 2x2 bilinear taps (a (K+1)^2 footprint with tent
 * weights at its rim); a Poisson disk of diameter K texels, rotated per
 * pixel; and adaptive PCF (Uralsky 2005, course §4.2): the first taps of
 * the disk, and all of them only where those disagree (the penumbra). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "resources/standard.h"
#include "techniques/smap.h"

enum { KERNEL_BOX, KERNEL_BILINEAR, KERNEL_POISSON, KERNEL_ADAPTIVE };
static const char *const kernel_names[] = {"box", "bilinear", "poisson", "adaptive", NULL};

enum { P_K = SMAP_NUM_PARAMS, P_KERNEL, P_SAMPLES, P_INITIAL, P_ROTATE };

#define PCF_MAX_K 63
#define PCF_MAX_SAMPLES 256

static const ParamDesc pcf_params[] = {
    SMAP_MAP_PARAMS,
    SMAP_BIAS_PARAMS,
    {"K", PARAM_INT, 5, 1, PCF_MAX_K, "texels", "kernel width: the filter covers K x K texels (the disk's diameter)", NULL},
    {"kernel", PARAM_ENUM, KERNEL_BOX, 0, 3, "",
     "box (K^2 taps), bilinear (K^2 hardware 2x2 taps), poisson (disk, rotated per pixel) or adaptive", kernel_names},
    {"samples", PARAM_INT, 16, 1, PCF_MAX_SAMPLES, "taps", "poisson and adaptive: taps in the disk", NULL},
    {"initial", PARAM_INT, 4, 1, PCF_MAX_SAMPLES, "taps",
     "adaptive: taps tried first; the rest only where they disagree", NULL},
    {"rotate", PARAM_BOOL, 1, 0, 1, "", "poisson and adaptive: rotate the disk per pixel (banding becomes noise)", NULL},
};

/* The disk's taps and rotation; the first taps only in adaptive PCF. */
static const ParamCondition pcf_conditions[] = {
    {"samples", "kernel=poisson|adaptive"},
    {"initial", "kernel=adaptive"},
    {"rotate", "kernel=poisson|adaptive"},
    {NULL, NULL},
};

static const char *const pcf_resources[] = {"shadow_map", "view_samples", "point_table", NULL};

typedef struct PcfState {
    const ShadowMap *map;
    SmapBias bias;
    int K, kernel, samples, initial;
    bool rotate;
    const PointTable *disk; /* unit disk, progressive: every prefix is well spread (a set-up table) */
} PcfState;

/* Mitchell's best-candidate points in the unit disk: each new point is the
 * farthest of 32 i candidates from those placed, so prefixes stay uniform. */
static void poisson_disk(float (*pts)[2], int n)
{
    uint32_t state = 0x9e3779b9u;
    for (int i = 0; i < n; i++) {
        double best = -1.0;
        for (int c = 0; c < 32 * (i + 1); c++) {
            state = hash_u32(state + (uint32_t)c);
            double a = 2.0 * M_PI * (state >> 8) / 16777216.0;
            state = hash_u32(state);
            double r = sqrt((state >> 8) / 16777216.0), x = r * cos(a), y = r * sin(a), d = INFINITY;
            for (int k = 0; k < i; k++) d = fmin(d, (x - pts[k][0]) * (x - pts[k][0]) + (y - pts[k][1]) * (y - pts[k][1]));
            if (d > best) {
                best = d;
                pts[i][0] = (float)x;
                pts[i][1] = (float)y;
            }
        }
    }
}

static bool pcf_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    PcfState *st = malloc(sizeof *st);
    if (!st) return error_set(err, "out of memory");
    ShadowMapSpec spec = smap_spec(p);
    st->map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!st->map) {
        free(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->K = (int)p[P_K];
    st->bias.filter_radius = 0.5 * (st->K - 1);
    st->kernel = (int)p[P_KERNEL];
    st->samples = (int)p[P_SAMPLES];
    st->initial = (int)p[P_INITIAL] < st->samples ? (int)p[P_INITIAL] : st->samples;
    st->rotate = p[P_ROTATE] != 0.0;
    st->disk = NULL;
    if (st->kernel >= KERNEL_POISSON) {
        st->disk = res_point_table(ctx->rm, "pcf best-candidate disk", poisson_disk, st->samples, err);
        if (!st->disk) {
            free(st);
            return false;
        }
    }
    *state = st;
    return true;
}

/* Four float32 and four int32 lanes (GCC's and clang's vector extension:
 * SSE2 on x86-64, NEON on arm64); a compare gives -1 (true) or 0 per lane. */
typedef float f32x4 __attribute__((vector_size(16)));
typedef int32_t i32x4 __attribute__((vector_size(16)));

/* (int)floor(x) for x well inside int's range (texel coordinates): the
 * truncation, one less where it rounded a negative x up. */
static inline int floor_int(double x)
{
    int i = (int)x;
    return i - (x < i);
}

/* The K x K window of a face from texel (i0, j0), rows `width` >= K taps
 * wide, where it reaches past the map's edges: clamped to them, as
 * shadowmap_texel reads (row j of the window at window + j * width). */
static void edge_window(const ShadowMap *m, int face, int i0, int j0, int K, int width, float *window)
{
    int res = m->res;
    for (int j = 0; j < K; j++) {
        const float *row = shadowmap_row(m, face, j0 + j, K); /* clamps the row; counts its K taps */
        for (int i = 0; i < width; i++) window[j * width + i] = row[i0 + i < 0 ? 0 : i0 + i >= res ? res - 1 : i0 + i];
    }
}

/* A box's taps counted in int32 lanes: -1 per lit tap, and -1 wherever a
 * depth was NaN (neither lit nor shadowed). */
typedef struct BoxCount {
    i32x4 lit, nan;
} BoxCount;

/* The K rows of a box, `stride` floats apart, against the reference in
 * every lane: 4 taps to a vector, `width` (K rounded up to vectors) read
 * per row, the lanes of the last vector past K masked off (`last`). Inlined
 * with a constant width, each row's loop unrolls. */
__attribute__((always_inline)) static inline BoxCount box_rows(const float *row, ptrdiff_t stride, int K, int width,
                                                               f32x4 ref, i32x4 last)
{
    BoxCount c = {{0, 0, 0, 0}, {0, 0, 0, 0}};
    for (int j = 0; j < K; j++, row += stride) {
        f32x4 z;
        int i = 0;
#pragma GCC unroll 4
        for (; i < width - 4; i += 4) {
            memcpy(&z, row + i, sizeof z);
            c.lit += ref <= z;
            c.nan |= z != z;
        }
        memcpy(&z, row + i, sizeof z);
        c.lit += (ref <= z) & last;
        c.nan |= (z != z) & last;
    }
    return c;
}

/* Lit taps of the K x K box from texel (i0, j0) of a face against one
 * reference depth, rounded up to float32 (smap_ref_up: every outcome that
 * of smap_test's double compare); NaN if a tap (or the reference) is NaN,
 * which is neither lit nor shadowed. A box past the map's edges reads a
 * clamped copy (edge_window) in the same loop; boxes up to 16 wide take
 * their width's unrolled loop. */
static float box_lit(const ShadowMap *m, int face, int i0, int j0, int K, float ref)
{
    int res = m->res, width = (K + 3) & ~3; /* taps read per row: K rounded up to vectors */
    float window[PCF_MAX_K * (PCF_MAX_K + 3)];
    const float *row = window;
    ptrdiff_t stride = width;
    if (i0 >= 0 && i0 + width <= res && j0 >= 0 && j0 + K <= res) {
        row = shadowmap_row(m, face, j0, K * K) + i0; /* counts the K^2 taps (core/counters.h) */
        stride = res;
    } else {
        edge_window(m, face, i0, j0, K, width, window);
    }
    f32x4 r = {ref, ref, ref, ref};
    i32x4 lane = {0, 1, 2, 3}, last = lane < K - (width - 4); /* the lanes of a row's last vector inside K */
    BoxCount c = width == 4    ? box_rows(row, stride, K, 4, r, last)
                 : width == 8  ? box_rows(row, stride, K, 8, r, last)
                 : width == 16 ? box_rows(row, stride, K, 16, r, last)
                               : box_rows(row, stride, K, width, r, last);
    /* one sum for both: -(lit taps) <= 0 plus 2^20 > K^2 per lane that saw a NaN */
    i32x4 sum = c.lit + (c.nan & (1 << 20));
    int total = sum[0] + sum[1] + sum[2] + sum[3];
    return ref != ref || total > 0 ? NAN : (float)-total;
}

/* Box: K x K texel centres around (s, t); the first is at floor(s - K/2 + 1/2). */
static int box_first(double s, int K) { return floor_int(s - 0.5 * K + 0.5); }

/* The box with the receiver plane: a reference per texel. */
static float filter_box_plane(const PcfState *st, const SmapReceiver *r)
{
    int i0 = box_first(r->mc.s, st->K), j0 = box_first(r->mc.t, st->K);
    float lit = 0.0f;
    for (int j = j0; j < j0 + st->K; j++)
        for (int i = i0; i < i0 + st->K; i++) lit += smap_lit(st->map, r, i, j);
    return lit / (float)(st->K * st->K);
}

/* K bilinear taps per axis at s - (K-1)/2 ... s + (K-1)/2 add up to weights
 * 1 - f, 1, ..., 1, f over K + 1 texels (f: the taps' fractional position). */
static float filter_bilinear(const PcfState *st, const SmapReceiver *r)
{
    double fs = r->mc.s - 0.5 * (st->K - 1) - 0.5, ft = r->mc.t - 0.5 * (st->K - 1) - 0.5;
    int i0 = (int)floor(fs), j0 = (int)floor(ft);
    double ax = fs - i0, ay = ft - j0, lit = 0.0;
    for (int j = 0; j <= st->K; j++) {
        double wy = j == 0 ? 1.0 - ay : j == st->K ? ay : 1.0;
        for (int i = 0; i <= st->K; i++) {
            double wx = i == 0 ? 1.0 - ax : i == st->K ? ax : 1.0;
            lit += wx * wy * smap_lit(st->map, r, i0 + i, j0 + j);
        }
    }
    return (float)(lit / ((double)st->K * st->K));
}

/* Lit taps [first, last) of the disk of diameter K texels, rotated by
 * angle; NaN if a tap reads a NaN depth. */
static float disk_lit(const PcfState *st, const SmapReceiver *r, int first, int last, double cs, double sn)
{
    double radius = 0.5 * st->K;
    float lit = 0.0f;
    for (int k = first; k < last; k++) {
        double x = st->disk->pts[k][0], y = st->disk->pts[k][1];
        double s = r->mc.s + radius * (cs * x - sn * y), t = r->mc.t + radius * (sn * x + cs * y);
        lit += smap_lit(st->map, r, (int)floor(s), (int)floor(t));
    }
    return lit;
}

static float filter_disk(const PcfState *st, const SmapReceiver *r, uint32_t sample)
{
    double a = st->rotate ? 2.0 * M_PI * (hash_u32(sample) >> 8) / 16777216.0 : 0.0;
    double cs = cos(a), sn = sin(a);
    int n0 = st->kernel == KERNEL_ADAPTIVE ? st->initial : st->samples;
    float lit = disk_lit(st, r, 0, n0, cs, sn);
    if (n0 == st->samples || lit == 0.0f || lit == (float)n0) return lit / (float)n0; /* NaN: the full disk */
    lit += disk_lit(st, r, n0, st->samples, cs, sn);
    return lit / (float)st->samples;
}

static float pcf_filter(const PcfState *st, const SmapReceiver *r, int sample)
{
    switch (st->kernel) {
    case KERNEL_BOX: return filter_box_plane(st, r);
    case KERNEL_BILINEAR: return filter_bilinear(st, r);
    default: return filter_disk(st, r, (uint32_t)sample);
    }
}

/* The box without the receiver plane: one reference per sample, read from
 * the batch's arrays (smap_refs). */
static void evaluate_box(const PcfState *st, const TechContext *ctx, int first, int n, int begin, float *out)
{
    SmapRefs r;
    smap_refs(st->map, &st->bias, ctx->vs->p_world + first, ctx->vs->n_geom_world + first, ctx->cls + first, n, &r);
    float area = (float)(st->K * st->K);
    for (int k = 0; k < r.count; k++) {
        float v = 1.0f;
        if (r.inside[k])
            v = box_lit(st->map, r.face[k], box_first(r.s[k], st->K), box_first(r.t[k], st->K), st->K, r.ref_up[k]) /
                area;
        tech_store(ctx, out, begin, first + r.sample[k], v);
    }
}

/* Receivers are set up SMAP_BATCH samples at a time (smap_refs for the box
 * without the receiver plane, else smap_receivers), then filtered one by one. */
static void pcf_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const PcfState *st = state;
    for (int first = begin; first < end; first += SMAP_BATCH) {
        int n = end - first < SMAP_BATCH ? end - first : SMAP_BATCH;
        if (st->kernel == KERNEL_BOX && !st->bias.receiver_plane) {
            evaluate_box(st, ctx, first, n, begin, out);
            continue;
        }
        SmapReceiver r[SMAP_BATCH];
        bool inside[SMAP_BATCH];
        smap_receivers(st->map, &st->bias, ctx->vs->p_world + first, ctx->vs->n_geom_world + first, ctx->cls + first,
                       n, r, inside);
        for (int k = 0; k < n; k++) {
            int s = first + k;
            if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
            tech_store(ctx, out, begin, s, inside[k] ? pcf_filter(st, &r[k], s) : 1.0f);
        }
    }
}

const Technique tech_pcf = {
    .name = "pcf",
    .family = "filtered",
    .source = "course §4.1.2 (Eq. 4.1, Reeves 1987), §4.2 (adaptive PCF, Uralsky 2005)",
    .summary = "percentage-closer filtering over K x K texels: box, bilinear, rotated Poisson disk or adaptive",
    .params = pcf_params,
    .num_params = (int)(sizeof pcf_params / sizeof pcf_params[0]),
    .resources = pcf_resources,
    .rgb = false,
    .lights = LIGHTS_ALL,
    .main_param = "K",
    .conditions = pcf_conditions,
    .prepare = pcf_prepare,
    .evaluate = pcf_evaluate,
    .release = free,
};
