/* shadowwidth.c -- building the shadow-width map (shadowwidth.h; seed 003 §4,
 * "Generating Shadow Widths"). */
#include "resources/maps/shadowwidth.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/bufpool.h"
#include "core/hash.h"

static void sw_destroy(void *r)
{
    ShadowWidthMap *w = r;
    bufpool_free(w->width);
    free(w);
}

static size_t sw_bytes(const void *r)
{
    const ShadowWidthMap *w = r;
    return sizeof *w + sizeof(float) * (size_t)w->num_faces * (size_t)w->res * (size_t)w->res;
}

static const ResourceKind kind_shadow_width = {"shadow_width_map", sw_bytes, sw_destroy, RES_FRAME};

/* The minimum as a plain select (no NaN rules: widths are finite), which
 * compilers vectorise where fminf may stay a call. */
static inline float min_f(float a, float b) { return b < a ? b : a; }

typedef struct SwArgs {
    const ShadowMap *peeled;
    ShadowWidthSpec spec;
    uint64_t key;
} SwArgs;

/* The inverted occlusion map: 1 where a surface lies behind the first one. */
static long occlusion(const ShadowMap *peeled, float *w)
{
    long n = (long)peeled->num_faces * peeled->res * peeled->res, blockers = 0;
#pragma omp parallel for reduction(+ : blockers)
    for (long i = 0; i < n; i++) {
        w[i] = isfinite(peeled->depth[i]) ? 1.0f : 0.0f;
        blockers += w[i] > 0.0f;
    }
    return blockers;
}

/* Software version: one in-place pass per direction (left to right, right to
 * left, bottom to top, top to bottom). Raster order carries each update on
 * to the next texel, so the four passes give min(1, d x city-block distance)
 * (a two-pass distance transform in the manner of Rosenfeld & Pfaltz). */
#define SW_STRIP 64

static int propagate_software(float *w, int res, float d)
{
#pragma omp parallel for
    for (int j = 0; j < res; j++) {
        float *row = w + (size_t)j * res;
        for (int i = 1; i < res; i++) row[i] = min_f(row[i], row[i - 1] + d);
        for (int i = res - 2; i >= 0; i--) row[i] = min_f(row[i], row[i + 1] + d);
    }
    /* Columns in strips of SW_STRIP, each strip swept row by row (cache-friendly). */
#pragma omp parallel for
    for (int i0 = 0; i0 < res; i0 += SW_STRIP) {
        int i1 = i0 + SW_STRIP < res ? i0 + SW_STRIP : res;
        for (int j = 1; j < res; j++)
            for (int i = i0; i < i1; i++) w[(size_t)j * res + i] = min_f(w[(size_t)j * res + i], w[(size_t)(j - 1) * res + i] + d);
        for (int j = res - 2; j >= 0; j--)
            for (int i = i0; i < i1; i++) w[(size_t)j * res + i] = min_f(w[(size_t)j * res + i], w[(size_t)(j + 1) * res + i] + d);
    }
    return 4;
}

/* One compositing pass: each texel takes the minimum of itself and its
 * neighbours at the offsets plus the difference d (textures clamp to the
 * edge). Row by row and offset by offset, so the inner loop is a plain
 * vectorisable minimum over the columns whose neighbour lies inside. */
static void doubling_pass(const float *src, float *dst, int res, const int (*off)[2], int n_off, float d)
{
#pragma omp parallel for
    for (int j = 0; j < res; j++) {
        float *out = dst + (size_t)j * res;
        memcpy(out, src + (size_t)j * res, sizeof(float) * (size_t)res);
        for (int k = 0; k < n_off; k++) {
            int dx = off[k][0], y = j + off[k][1];
            const float *row = src + (size_t)(y < 0 ? 0 : y >= res ? res - 1 : y) * res;
            int lo = dx < 0 ? (-dx < res ? -dx : res) : 0, hi = dx > 0 ? (res - dx > 0 ? res - dx : 0) : res;
            for (int i = 0; i < lo; i++) out[i] = min_f(out[i], row[0] + d);
            for (int i = lo; i < hi; i++) out[i] = min_f(out[i], row[i + dx] + d);
            for (int i = hi > lo ? hi : lo; i < res; i++) out[i] = min_f(out[i], row[res - 1] + d);
        }
    }
}

/* Texture-compositing version (§4, Fig. 4): neighbours at 2^k texels in 3
 * directions 120 degrees apart (the GeForce3's four texture units: the map
 * itself and three shifted copies) or 6 directions 60 degrees apart, the
 * difference doubling with the distance, until it exceeds 1. Shifts are
 * rounded to whole texels (nearest-texel sampling). */
static int propagate_doubling(float *w, float *scratch, int res, int directions, double d)
{
    int passes = 0;
    float *src = w, *dst = scratch;
    for (double dist = 1.0; d <= 1.0; d *= 2.0, dist *= 2.0, passes++) {
        int off[6][2];
        for (int k = 0; k < directions; k++) {
            double a = (directions == 3 ? M_PI / 2 : 0.0) + 2.0 * M_PI * k / directions;
            off[k][0] = (int)lround(dist * cos(a));
            off[k][1] = (int)lround(dist * sin(a));
        }
        doubling_pass(src, dst, res, (const int(*)[2])off, directions, (float)d);
        float *t = src;
        src = dst;
        dst = t;
    }
    if (src != w) memcpy(w, src, sizeof(float) * (size_t)res * (size_t)res);
    return passes;
}

static void *build_sw(const void *args, Error *err)
{
    const SwArgs *a = args;
    int res = a->peeled->res;
    size_t texels = (size_t)res * (size_t)res, faces = (size_t)a->peeled->num_faces;
    ShadowWidthMap *w = calloc(1, sizeof *w);
    float *scratch = a->spec.propagation == SW_SOFTWARE4 ? NULL : bufpool_alloc(sizeof(float) * texels);
    if (w) w->width = bufpool_alloc(sizeof(float) * texels * faces); /* kept between builds (core/bufpool.h) */
    if (!w || !w->width || (a->spec.propagation != SW_SOFTWARE4 && !scratch)) {
        if (w) sw_destroy(w);
        bufpool_free(scratch);
        error_set(err, "out of memory for a %d^2 shadow-width map", res);
        return NULL;
    }
    w->key = a->key;
    w->res = res;
    w->num_faces = (int)faces;
    w->start_difference = a->spec.start_difference;
    w->blockers = occlusion(a->peeled, w->width);
    for (size_t f = 0; f < faces; f++) {
        float *face = w->width + f * texels;
        if (a->spec.propagation == SW_SOFTWARE4)
            w->passes = propagate_software(face, res, (float)a->spec.start_difference);
        else
            w->passes = propagate_doubling(face, scratch, res, a->spec.propagation == SW_DOUBLING3 ? 3 : 6,
                                           a->spec.start_difference);
    }
    bufpool_free(scratch);
    return w;
}

const ShadowWidthMap *res_shadow_width_map(ResourceManager *rm, const Scene *scene, int light_index,
                                           const ShadowMapSpec *depth_spec, const ShadowWidthSpec *spec, Error *err)
{
    if (!(spec->start_difference > 0.0 && spec->start_difference <= 1.0)) {
        error_set(err, "start_difference %g outside (0, 1]", spec->start_difference);
        return NULL;
    }
    ShadowMapSpec ps = *depth_spec;
    ps.layer = MAP_LAYER_PEELED;
    ps.cull = RASTER_CULL_NONE;
    ps.triangle_ids = false;
    ps.depth = RASTER_DEPTH_LINEAR; /* only whether a second layer exists matters */
    ps.depth_bits = 0;
    const ShadowMap *peeled = res_shadow_map(rm, scene, light_index, &ps, err);
    if (!peeled) return NULL;
    Hasher h;
    hash_init(&h);
    hash_str(&h, "shadow width map 1");
    hash_u64(&h, peeled->key);
    hash_u64(&h, (uint64_t)spec->propagation);
    hash_f64(&h, spec->start_difference);
    SwArgs a = {peeled, *spec, hash_final(&h)};
    static const char *const names[] = {SW_PROPAGATION_NAMES};
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %d x %d^2, %s, start difference %g", light_index + 1, peeled->num_faces,
             peeled->res, names[spec->propagation], spec->start_difference);
    return rm_acquire(rm, &kind_shadow_width, a.key, desc, build_sw, &a, err);
}
