/* prefilter.c -- moment maps, box blurs, summed-area tables and min-max
 * pyramids derived from a depth map (prefilter.h; course ch.4 and its box
 * "Fast-box Filter Approximations"). */
#include "resources/maps/prefilter.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/bufpool.h"
#include "core/counters.h"
#include "core/hash.h"
#include "core/nanmath.h"

/* ---- element storage ---- */

/* The prefiltered maps and min-max levels, like the depth maps they are made
 * from, come from core/bufpool.h: rebuilt at the same size (a scope's
 * repeated builds, a sweep, the next frame) they reuse their pages. */
static bool store_alloc(PfStore *s, size_t n, bool f64)
{
    s->d = f64 ? bufpool_alloc(n * sizeof *s->d) : NULL;
    s->f = f64 ? NULL : bufpool_alloc(n * sizeof *s->f);
    return s->d || s->f;
}

static void store_free(PfStore *s)
{
    bufpool_free(s->d);
    bufpool_free(s->f);
}

static inline void pf_put(PfStore *s, size_t i, double v)
{
    if (s->d) s->d[i] = v;
    else s->f[i] = (float)v;
}

/* v rounded to the element type. A float operation is the double operation
 * of the same floats rounded once, so this is f32 arithmetic exactly. */
static inline double pf_round(const PfStore *s, double v) { return s->d ? v : (double)(float)v; }

static size_t elem_bytes(bool f64) { return f64 ? sizeof(double) : sizeof(float); }

/* Bytes of one entry (all channels) of a prefiltered map, for the counters. */
static uint64_t entry_bytes(const Prefiltered *pf, int channels)
{
    return (uint64_t)channels * elem_bytes(pf->data.d != NULL);
}

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

/* The refusal suggests precision=f32 only where it would fit: in f64 at no
 * more than twice the cap (f32 halves the bytes). */
static bool check_bytes(const char *what, int res, int faces, int channels, bool f64, size_t bytes, Error *err)
{
    if (bytes <= PREFILTER_MAX_BYTES) return true;
    bool f32_fits = f64 && bytes / 2 <= PREFILTER_MAX_BYTES;
    return error_set(err,
                     "%s of a %d^2 %d-face map with %d channels in %s needs %.2f GiB, above the %.0f GiB cap "
                     "(use %sfewer channels or a smaller map_size)",
                     what, res, faces, channels, f64 ? "f64" : "f32", (double)bytes / (1 << 30),
                     (double)PREFILTER_MAX_BYTES / (1 << 30), f32_fits ? "precision=f32, " : "");
}

/* ---- moment maps ---- */

int moment_channels(const MomentSpec *sp)
{
    switch (sp->warp) {
    case WARP_POWERS: return sp->order;
    case WARP_LAYERS: return 2 * sp->order;
    case WARP_EXP: return sp->order;
    case WARP_FOURIER: return 2 * sp->order;
    case WARP_LOG_EXP: return 1;
    case WARP_FOURIER_DEPTH: return 4 * sp->order + 1;
    }
    return 0;
}

double prefilter_depth_unit(const ShadowMap *m, int face, double z)
{
    if (isnan(z)) return z;          /* an unknown depth stays unknown */
    if (z == INFINITY) return 1.0; /* no caster: the far plane */
    double u = z;
    if (m->spec.depth == RASTER_DEPTH_LINEAR) {
        const RasterView *rv = &m->view.face[face].raster;
        double span = rv->depth_far - rv->depth_near;
        u = span > 0.0 ? (z - rv->depth_near) / span : 0.0;
    }
    return u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
}

/* The smaller one-sided difference of u along a row or column: the surface's
 * slope per texel, without jumping across a depth discontinuity. */
static double slope_per_texel(double prev, double u, double next, bool has_prev, bool has_next)
{
    double a = has_prev ? u - prev : INFINITY, b = has_next ? next - u : INFINITY;
    double d = fabs(a) < fabs(b) ? a : b;
    return isfinite(d) ? d : 0.0;
}

void fourier_basis(double u, int terms, double *out)
{
    /* The angle c_k u grows by 2 pi u per term: rotate instead of calling sin, cos 2M times. */
    double s = sin(M_PI * u), c = cos(M_PI * u), ss = sin(2.0 * M_PI * u), cs = cos(2.0 * M_PI * u);
    for (int k = 0; k < terms; k++) {
        out[2 * k] = s;
        out[2 * k + 1] = c;
        double s2 = s * cs + c * ss;
        c = c * cs - s * ss;
        s = s2;
    }
}

/* The warped channels of one texel at normalised depth u. */
static void warp_texel(const MomentSpec *sp, double u, double dx, double dy, double *out)
{
    switch (sp->warp) {
    case WARP_POWERS: {
        double z = sp->signed_depth ? 2.0 * u - 1.0 : u, p = z;
        for (int k = 0; k < sp->order; k++, p *= z) out[k] = p;
        /* Lauritzen 2007 (course §4.2.1 box): a plane over the texel with
         * E(u^2) = E(v^2) = 1/4 adds (ddx^2 + ddy^2) / 4 to M2. */
        if (sp->slope_moment && sp->order >= 2) out[1] += 0.25 * (dx * dx + dy * dy);
        break;
    }
    case WARP_LAYERS:
        /* course §4.2.2: phi_i(x) = 0 below d_i, (x - d_i) / (d_{i+1} - d_i) inside, 1 above; d_i = i / L. */
        for (int i = 0; i < sp->order; i++) {
            double phi = (u - (double)i / sp->order) * sp->order;
            phi = phi < 0.0 ? 0.0 : phi > 1.0 ? 1.0 : phi;
            out[2 * i] = phi;
            out[2 * i + 1] = phi * phi;
        }
        break;
    case WARP_EXP: {
        /* EVSM (course §4.2.4, erratum: the pair is +exp(cz), -exp(-cz)). The
         * positive warp is scaled by e^-c+ (Chebyshev's bound is invariant
         * under scaling), so its largest value is 1 and nothing overflows;
         * the second moments hold e^(2c...) as the catalogue notes. */
        double a = exp(sp->c_pos * (u - 1.0));
        out[0] = a;
        out[1] = a * a;
        if (sp->order == 4) {
            double b = exp(-sp->c_neg * u);
            out[2] = -b;
            out[3] = b * b;
        }
        break;
    }
    case WARP_FOURIER: fourier_basis(u, sp->order, out); break;
    case WARP_LOG_EXP: out[0] = sp->c_pos * u; break; /* ln e^(c u) */
    case WARP_FOURIER_DEPTH: {
        int n = 2 * sp->order;
        fourier_basis(0.5 * u, sp->order, out);
        out[n] = u;
        for (int k = 0; k < n; k++) out[n + 1 + k] = u * out[k];
        break;
    }
    }
}

static void moments_destroy(void *r)
{
    MomentMap *mm = r;
    store_free(&mm->data);
    free(mm);
}

static size_t moments_bytes(const void *r)
{
    const MomentMap *mm = r;
    return sizeof *mm + (size_t)mm->num_faces * mm->res * mm->res * mm->channels * elem_bytes(mm->spec.f64);
}

static const ResourceKind kind_moments = {"moments", moments_bytes, moments_destroy, RES_FRAME};

typedef struct MomentArgs { const ShadowMap *map; MomentSpec spec; uint64_t key; } MomentArgs;

static void warp_row(const ShadowMap *m, const MomentSpec *sp, MomentMap *mm, int f, int j)
{
    int res = m->res, C = mm->channels;
    double out[PREFILTER_MAX_CHANNELS];
#define U(i_, j_) prefilter_depth_unit(m, f, shadowmap_texel(m, f, (i_), (j_)))
    for (int i = 0; i < res; i++) {
        double u = U(i, j), dx = 0.0, dy = 0.0;
        if (sp->slope_moment) {
            dx = slope_per_texel(i > 0 ? U(i - 1, j) : 0, u, i + 1 < res ? U(i + 1, j) : 0, i > 0, i + 1 < res);
            dy = slope_per_texel(j > 0 ? U(i, j - 1) : 0, u, j + 1 < res ? U(i, j + 1) : 0, j > 0, j + 1 < res);
        }
        warp_texel(sp, u, dx, dy, out);
        size_t base = (((size_t)f * res + j) * res + i) * C;
        for (int c = 0; c < C; c++) pf_put(&mm->data, base + c, out[c]);
    }
#undef U
}

static void *build_moments(const void *args, Error *err)
{
    const MomentArgs *a = args;
    MomentMap *mm = calloc(1, sizeof *mm);
    if (!mm) { error_set(err, "out of memory"); return NULL; }
    *mm = (MomentMap){a->key, a->map, a->spec, a->map->res, a->map->num_faces, moment_channels(&a->spec),
                      a->spec.warp == WARP_LOG_EXP, {NULL, NULL}};
    size_t n = (size_t)mm->num_faces * mm->res * mm->res * mm->channels;
    if (!store_alloc(&mm->data, n, a->spec.f64)) {
        error_set(err, "out of memory for a %d-channel %d^2 moment map", mm->channels, mm->res);
        free(mm);
        return NULL;
    }
    int rows = mm->num_faces * mm->res;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < rows; r++) warp_row(a->map, &a->spec, mm, r / mm->res, r % mm->res);
    return mm;
}

static const char *warp_name(MomentWarp w)
{
    static const char *const names[] = {"powers", "layers", "exp", "fourier", "log-exp", "fourier-depth"};
    return names[w];
}

/* Only the fields the warp reads, so unrelated parameters share one map. */
static MomentSpec normalised_spec(const MomentSpec *in)
{
    MomentSpec s = {.warp = in->warp, .order = in->order, .f64 = in->f64};
    if (in->warp == WARP_EXP || in->warp == WARP_LOG_EXP) s.c_pos = in->c_pos;
    if (in->warp == WARP_EXP && in->order == 4) s.c_neg = in->c_neg;
    if (in->warp == WARP_POWERS) {
        s.signed_depth = in->signed_depth;
        s.slope_moment = in->slope_moment && in->order >= 2;
    }
    if (in->warp == WARP_LOG_EXP) s.order = 1;
    return s;
}

const MomentMap *res_moment_map(ResourceManager *rm, const ShadowMap *map, const MomentSpec *spec_in, Error *err)
{
    MomentSpec spec = normalised_spec(spec_in);
    int C = moment_channels(&spec);
    if (C < 1 || C > PREFILTER_MAX_CHANNELS)
        return error_set(err, "a moment map needs 1 to %d channels, not %d", PREFILTER_MAX_CHANNELS, C), NULL;
    size_t bytes = (size_t)map->num_faces * map->res * map->res * C * elem_bytes(spec.f64);
    if (!check_bytes("the moment map", map->res, map->num_faces, C, spec.f64, bytes, err)) return NULL;
    Hasher h;
    hash_init(&h);
    hash_u64(&h, map->key);
    hash_str(&h, "moments");
    const int64_t fields[] = {spec.warp, spec.order, spec.signed_depth, spec.slope_moment, spec.f64};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) hash_u64(&h, (uint64_t)fields[i]);
    hash_f64(&h, spec.c_pos);
    hash_f64(&h, spec.c_neg);
    MomentArgs a = {map, spec, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(map->key, mk);
    snprintf(desc, sizeof desc, "%s x%d (%d ch, %s%s) c %g/%g of map %s", warp_name(spec.warp), spec.order, C,
             spec.f64 ? "f64" : "f32", spec.slope_moment ? ", slope moment" : "", spec.c_pos, spec.c_neg, mk);
    return rm_acquire(rm, &kind_moments, a.key, desc, build_moments, &a, err);
}

/* ---- box blurs and summed-area tables ---- */

static void prefiltered_destroy(void *r)
{
    Prefiltered *pf = r;
    store_free(&pf->data);
    free(pf->offset);
    free(pf);
}

static size_t prefiltered_entries(const Prefiltered *pf)
{
    size_t side = (size_t)pf->stride + (pf->kind == PREFILTER_SAT);
    return (size_t)pf->num_faces * side * side * pf->channels;
}

static size_t prefiltered_bytes(const void *r)
{
    const Prefiltered *pf = r;
    return sizeof *pf + prefiltered_entries(pf) * elem_bytes(pf->f64) +
           (size_t)pf->num_faces * pf->channels * sizeof(double);
}

static const ResourceKind kind_box = {"box_blur", prefiltered_bytes, prefiltered_destroy, RES_FRAME};
static const ResourceKind kind_sat = {"sat", prefiltered_bytes, prefiltered_destroy, RES_FRAME};

typedef struct PrefilterArgs { const MomentMap *mm; PrefilterKind kind; int K; uint64_t key; } PrefilterArgs;

/* For each of nc interleaved channels, out[o] = mean of in[clamp(o - shift
 * + k)], k = 0..K-1 (edge replicated); for log values, the log of the mean
 * of their exponentials, shifted by the window's max so no exponential
 * overflows (catalogue §4.2.4 [LIT]: ln sum w e^x = x0 + ln sum w e^(x - x0)). */
static void box_line(const double *in, int n_in, double *out, int n_out, int nc, int K, int shift, bool log_values)
{
#define IN(k_) in[(size_t)clampi((k_), 0, n_in - 1) * nc + c]
    for (int c = 0; c < nc; c++) {
        if (log_values) {
            for (int o = 0; o < n_out; o++) {
                double m = -INFINITY, sum = 0.0;
                for (int k = 0; k < K; k++) m = fmax(m, IN(o - shift + k));
                for (int k = 0; k < K; k++) sum += exp(IN(o - shift + k) - m);
                out[(size_t)o * nc + c] = m + log(sum / K);
            }
            continue;
        }
        /* A running sum, recomputed whenever the value leaving the window
         * was 256 times larger than what remains: subtracting it would leave
         * its rounding error in every later window (exponential warps span
         * e^-c, and a residual 1e-16 of a far texel's 1 swamps e^-40). */
        double sum = 0.0;
        for (int k = 0; k < K; k++) sum += IN(k - shift);
        for (int o = 0; o < n_out; o++) {
            out[(size_t)o * nc + c] = sum / K;
            double leaving = IN(o - shift);
            sum += IN(o - shift + K) - leaving;
            if (fabs(leaving) > 256.0 * fabs(sum)) {
                sum = 0.0;
                for (int k = 1; k <= K; k++) sum += IN(o - shift + k);
            }
        }
    }
#undef IN
}

/* Separable K x K box of every channel of one face, with no intermediate
 * beyond the output: the moment map's rows, blurred, into the output's rows
 * pad .. pad + res - 1, then each output column, read back from those rows
 * and blurred, into the whole padded column (a column is one thread's, so
 * reading and writing it in place is safe). false when a thread's line
 * buffers cannot be allocated. */
static bool box_face(Prefiltered *pf, int f)
{
    const MomentMap *mm = pf->moments;
    int res = pf->res, S = pf->stride, C = pf->channels, pad = pf->pad, shift = pf->pad + pf->K / 2;
    bool ok = true;
#define OUT(J_, I_, c_) ((((size_t)f * S + (J_)) * S + (I_)) * C + (c_))
#pragma omp parallel
    {
        double *in = malloc(sizeof *in * (size_t)S * C), *out = malloc(sizeof *out * (size_t)S * C);
        if (!in || !out) {
#pragma omp atomic write
            ok = false;
        }
#pragma omp for schedule(static)
        for (int j = 0; j < res; j++) {
            if (!in || !out) continue;
            for (size_t k = 0; k < (size_t)res * C; k++) in[k] = pf_get(&mm->data, ((size_t)f * res + j) * res * C + k);
            box_line(in, res, out, S, C, pf->K, shift, pf->log);
            for (size_t k = 0; k < (size_t)S * C; k++) pf_put(&pf->data, OUT(j + pad, 0, 0) + k, out[k]);
        }
#pragma omp for schedule(static)
        for (int I = 0; I < S; I++) {
            if (!in || !out) continue;
            for (int j = 0; j < res; j++)
                for (int c = 0; c < C; c++) in[(size_t)j * C + c] = pf_get(&pf->data, OUT(j + pad, I, c));
            box_line(in, res, out, S, C, pf->K, shift, pf->log);
            for (int J = 0; J < S; J++)
                for (int c = 0; c < C; c++) pf_put(&pf->data, OUT(J, I, c), out[(size_t)J * C + c]);
        }
        free(in);
        free(out);
    }
#undef OUT
    return ok;
}

/* What a SAT subtracts from each channel before summing: its mean over
 * the face (catalogue [OWN]: keeps the sums small), or for log channels
 * the largest value (the sum is then of e^(x - x_max) <= 1). */
static void sat_offsets(const MomentMap *mm, int f, double *off)
{
    size_t n = (size_t)mm->res * mm->res, C = (size_t)mm->channels, base = (size_t)f * n * C;
    for (size_t c = 0; c < C; c++) off[c] = mm->log ? -INFINITY : 0.0;
    for (size_t k = 0; k < n; k++)
        for (size_t c = 0; c < C; c++) {
            double v = pf_get(&mm->data, base + k * C + c);
            off[c] = mm->log ? fmax(off[c], v) : off[c] + v;
        }
    if (!mm->log)
        for (size_t c = 0; c < C; c++) off[c] /= (double)n;
}

/* SAT entry (I, J) = sum over padded texels [0, I) x [0, J), every channel,
 * in the element type's arithmetic: row prefix sums, then the columns. */
static void sat_face(Prefiltered *pf, int f)
{
    const MomentMap *mm = pf->moments;
    int res = pf->res, E = pf->stride + 1, C = pf->channels, pad = pf->pad;
    const double *off = pf->offset + (size_t)f * C;
    size_t face0 = (size_t)f * E * E * C, row = (size_t)E * C;
    for (size_t x = 0; x < row; x++) pf_put(&pf->data, face0 + x, 0.0);
#pragma omp parallel for schedule(static)
    for (int J = 1; J < E; J++) {
        int j = clampi(J - 1 - pad, 0, res - 1);
        double r[PREFILTER_MAX_CHANNELS] = {0};
        size_t at = face0 + (size_t)J * row;
        for (int c = 0; c < C; c++) pf_put(&pf->data, at + c, 0.0);
        for (int I = 1; I < E; I++) {
            size_t src = (((size_t)f * res + j) * res + clampi(I - 1 - pad, 0, res - 1)) * C;
            for (int c = 0; c < C; c++) {
                double v = pf_get(&mm->data, src + c);
                r[c] = pf_round(&pf->data, r[c] + (pf->log ? exp(v - off[c]) : pf_round(&pf->data, v - off[c])));
                pf_put(&pf->data, at + (size_t)I * C + c, r[c]);
            }
        }
    }
    const size_t block = 512;
#pragma omp parallel for schedule(static)
    for (size_t b = 0; b < row; b += block)
        for (int J = 2; J < E; J++) {
            size_t at = face0 + (size_t)J * row;
            for (size_t x = b; x < b + block && x < row; x++)
                pf_put(&pf->data, at + x, pf_get(&pf->data, at - row + x) + pf_get(&pf->data, at + x));
        }
}

static void *build_prefiltered(const void *args, Error *err)
{
    const PrefilterArgs *a = args;
    const MomentMap *mm = a->mm;
    Prefiltered *pf = calloc(1, sizeof *pf);
    if (!pf) { error_set(err, "out of memory"); return NULL; }
    *pf = (Prefiltered){.key = a->key, .moments = mm, .kind = a->kind, .K = a->kind == PREFILTER_BOX ? a->K : 0,
                        .res = mm->res, .pad = PREFILTER_PAD, .stride = mm->res + 2 * PREFILTER_PAD,
                        .num_faces = mm->num_faces, .channels = mm->channels, .log = mm->log, .f64 = mm->spec.f64};
    /* A log SAT's corners sum at most stride^2 positive terms through 2
     * stride roundings each; the window's four corners then err by at most
     * 8 stride eps times the largest (first-order bound, Higham §4.2). */
    pf->sat_rel_error = 8.0 * pf->stride * (pf->f64 ? DBL_EPSILON : FLT_EPSILON) / 2.0;
    pf->offset = calloc((size_t)pf->num_faces * pf->channels, sizeof *pf->offset);
    if (!pf->offset || !store_alloc(&pf->data, prefiltered_entries(pf), pf->f64)) {
        error_set(err, "out of memory for a %d-channel %d^2 %s", pf->channels, pf->res,
                  a->kind == PREFILTER_BOX ? "box blur" : "summed-area table");
        prefiltered_destroy(pf);
        return NULL;
    }
    bool ok = true;
    for (int f = 0; ok && f < pf->num_faces; f++) {
        if (a->kind == PREFILTER_SAT) {
            sat_offsets(mm, f, pf->offset + (size_t)f * pf->channels);
            sat_face(pf, f);
            continue;
        }
        ok = box_face(pf, f);
    }
    if (!ok) {
        prefiltered_destroy(pf);
        error_set(err, "out of memory for the box blur's line buffers");
        return NULL;
    }
    return pf;
}

const Prefiltered *res_prefiltered(ResourceManager *rm, const MomentMap *mm, PrefilterKind kind, int K, Error *err)
{
    if (K < 1 || K > PREFILTER_MAX_K) return error_set(err, "filter width K = %d outside [1, %d]", K, PREFILTER_MAX_K), NULL;
    size_t side = (size_t)mm->res + 2 * PREFILTER_PAD + (kind == PREFILTER_SAT);
    size_t bytes = (size_t)mm->num_faces * side * side * mm->channels * elem_bytes(mm->spec.f64);
    if (!check_bytes(kind == PREFILTER_SAT ? "the summed-area table" : "the box blur", mm->res, mm->num_faces,
                     mm->channels, mm->spec.f64, bytes, err))
        return NULL;
    Hasher h;
    hash_init(&h);
    hash_u64(&h, mm->key);
    hash_str(&h, kind == PREFILTER_SAT ? "sat" : "box");
    if (kind == PREFILTER_BOX) hash_u64(&h, (uint64_t)K);
    PrefilterArgs a = {mm, kind, K, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(mm->key, mk);
    if (kind == PREFILTER_SAT)
        snprintf(desc, sizeof desc, "summed-area table (%d ch, %s) of moments %s", mm->channels,
                 mm->spec.f64 ? "f64" : "f32", mk);
    else
        snprintf(desc, sizeof desc, "%dx%d box blur (%d ch, %s) of moments %s", K, K, mm->channels,
                 mm->spec.f64 ? "f64" : "f32", mk);
    return rm_acquire(rm, kind == PREFILTER_SAT ? &kind_sat : &kind_box, a.key, desc, build_prefiltered, &a, err);
}

/* ---- lookups ---- */

PfFootprint pf_footprint(double s, double t, int K, bool bilinear)
{
    PfFootprint fp = {.K = K, .bilinear = bilinear};
    if (!bilinear) {
        fp.i0 = (int)floor(s - 0.5 * K + 0.5);
        fp.j0 = (int)floor(t - 0.5 * K + 0.5);
        return fp;
    }
    double fs = s - 0.5 * K, ft = t - 0.5 * K;
    fp.i0 = (int)floor(fs);
    fp.j0 = (int)floor(ft);
    fp.ax = fs - fp.i0;
    fp.ay = ft - fp.j0;
    return fp;
}

/* Combine up to four per-window averages v[b][a] with weights w (log
 * channels: in the exponential domain, shifted by their max). */
static double combine(double v[2][2], double w[2][2], bool log_values)
{
    if (!log_values) return w[0][0] * v[0][0] + w[0][1] * v[0][1] + w[1][0] * v[1][0] + w[1][1] * v[1][1];
    double m = -INFINITY, sum = 0.0;
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++)
            if (w[b][a] > 0.0) m = fmax(m, v[b][a]);
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++)
            if (w[b][a] > 0.0) sum += w[b][a] * exp(v[b][a] - m);
    return m + log(sum);
}

static void footprint_weights(const PfFootprint *fp, double w[2][2])
{
    double wx[2] = {1.0 - fp->ax, fp->ax}, wy[2] = {1.0 - fp->ay, fp->ay};
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++) w[b][a] = wy[b] * wx[a];
}

static void fetch_box(const Prefiltered *pf, int face, const PfFootprint *fp, double w[2][2], double *out)
{
    int S = pf->stride, C = pf->channels, half = pf->K / 2;
    size_t at[2][2];
    for (int b = 0; b < 2; b++)
        for (int a = 0; a < 2; a++) {
            int I = clampi(fp->i0 + a + half + pf->pad, 0, S - 1), J = clampi(fp->j0 + b + half + pf->pad, 0, S - 1);
            at[b][a] = (((size_t)face * S + J) * S + I) * C;
        }
    int taps = (w[0][0] > 0.0) + (w[0][1] > 0.0) + (w[1][0] > 0.0) + (w[1][1] > 0.0);
    work_texels((uint64_t)taps, entry_bytes(pf, C)); /* the entries read below, all channels each */
    for (int c = 0; c < C; c++) {
        double v[2][2];
        for (int b = 0; b < 2; b++)
            for (int a = 0; a < 2; a++) v[b][a] = w[b][a] > 0.0 ? pf_get(&pf->data, at[b][a] + c) : 0.0;
        out[c] = combine(v, w, pf->log);
    }
}

/* Window sums from a SAT's 16 (or 4) corners; false where a log channel's
 * sum is within its rounding error. */
static bool fetch_sat(const Prefiltered *pf, int face, const PfFootprint *fp, double w[2][2], double *out)
{
    int E = pf->stride + 1, C = pf->channels, K = fp->K;
    int X[4], Y[4];
    for (int k = 0; k < 4; k++) {
        int d = (k & 1) + (k >> 1) * K; /* 0, 1, K, K + 1 */
        X[k] = clampi(fp->i0 + pf->pad + d, 0, E - 1);
        Y[k] = clampi(fp->j0 + pf->pad + d, 0, E - 1);
    }
    size_t face0 = (size_t)face * E * E;
    double area = (double)K * K;
    bool reliable = true;
    int windows = (w[0][0] > 0.0) + (w[0][1] > 0.0) + (w[1][0] > 0.0) + (w[1][1] > 0.0);
    work_texels(4 * (uint64_t)windows, entry_bytes(pf, C)); /* four corners per window read below */
    for (int c = 0; c < C; c++) {
        double v[2][2], off = pf->offset[face * C + c];
#define S_(x, y) pf_get(&pf->data, (face0 + (size_t)Y[y] * E + X[x]) * C + c)
        for (int b = 0; b < 2; b++)
            for (int a = 0; a < 2; a++) {
                if (!(w[b][a] > 0.0)) { v[b][a] = 0.0; continue; }
                double hi = S_(a + 2, b + 2), sum = hi - S_(a, b + 2) - S_(a + 2, b) + S_(a, b);
                if (pf->log && !(sum > pf->sat_rel_error * hi)) reliable = false;
                v[b][a] = sum / area;
            }
#undef S_
        if (!pf->log) {
            out[c] = combine(v, w, false) + off;
            continue;
        }
        double mean = combine(v, w, false);
        out[c] = (mean > 0.0 ? log(mean) : log(DBL_TRUE_MIN)) + off; /* finite even when nothing is left */
    }
    return reliable;
}

bool pf_fetch(const Prefiltered *pf, int face, const PfFootprint *fp, double *out)
{
    double w[2][2];
    footprint_weights(fp, w);
    if (pf->kind == PREFILTER_BOX) {
        fetch_box(pf, face, fp, w, out);
        return true;
    }
    return fetch_sat(pf, face, fp, w, out);
}

/* ---- variable-size windows from a SAT ---- */

/* The SAT entries and weights whose sum is the integral from the padded
 * origin to the continuous padded point (X, Y): bilinear between the four
 * integer corners around it, each weight times `sign`. */
static void sat_corner(const Prefiltered *pf, size_t face0, double X, double Y, double sign, size_t *at, double *w)
{
    int E = pf->stride + 1, C = pf->channels;
    X = X < 0.0 ? 0.0 : X > E - 1 ? E - 1 : X;
    Y = Y < 0.0 ? 0.0 : Y > E - 1 ? E - 1 : Y;
    int I = clampi((int)floor(X), 0, E - 2), J = clampi((int)floor(Y), 0, E - 2);
    double ax = X - I, ay = Y - J;
    for (int k = 0; k < 4; k++) {
        int di = k & 1, dj = k >> 1;
        at[k] = (face0 + (size_t)(J + dj) * E + (I + di)) * C;
        w[k] = sign * (di ? ax : 1.0 - ax) * (dj ? ay : 1.0 - ay);
    }
}

bool pf_fetch_box(const Prefiltered *pf, int face, double s, double t, double hx, double hy, int channels,
                  double *out)
{
    if (pf->kind != PREFILTER_SAT || pf->log || channels < 1 || channels > pf->channels) return false;
    if (!(hx > 0.0 && hx <= PREFILTER_MAX_HALF && hy > 0.0 && hy <= PREFILTER_MAX_HALF)) return false;
    int E = pf->stride + 1;
    size_t face0 = (size_t)face * E * E, at[16];
    double w[16], x0 = s - hx + pf->pad, x1 = s + hx + pf->pad, y0 = t - hy + pf->pad, y1 = t + hy + pf->pad;
    sat_corner(pf, face0, x1, y1, 1.0, at, w);
    sat_corner(pf, face0, x0, y1, -1.0, at + 4, w + 4);
    sat_corner(pf, face0, x1, y0, -1.0, at + 8, w + 8);
    sat_corner(pf, face0, x0, y0, 1.0, at + 12, w + 12);
    double inv_area = 1.0 / (4.0 * hx * hy);
    work_texels(16, entry_bytes(pf, channels));
    for (int c = 0; c < channels; c++) {
        double sum = 0.0;
        for (int k = 0; k < 16; k++) sum += w[k] * pf_get(&pf->data, at[k] + c);
        out[c] = sum * inv_area + pf->offset[face * pf->channels + c];
    }
    return true;
}

/* ---- min-max pyramid ---- */

static void pyramid_destroy(void *r)
{
    MinMaxPyramid *p = r;
    bufpool_free(p->minmax);
    free(p);
}

static size_t pyramid_pairs(const MinMaxPyramid *p)
{
    return p->offset[p->levels - 1] + (size_t)p->num_faces * p->size[p->levels - 1] * p->size[p->levels - 1];
}

static size_t pyramid_bytes(const void *r)
{
    const MinMaxPyramid *p = r;
    return sizeof *p + pyramid_pairs(p) * 2 * sizeof(float);
}

static const ResourceKind kind_pyramid = {"minmax_pyramid", pyramid_bytes, pyramid_destroy, RES_FRAME};

typedef struct PyramidArgs { const ShadowMap *map; uint64_t key; } PyramidArgs;

static inline float *node(const MinMaxPyramid *p, int level, int face, int i, int j)
{
    int n = p->size[level];
    return p->minmax + 2 * (p->offset[level] + ((size_t)face * n + j) * n + i);
}

static void *build_pyramid(const void *args, Error *err)
{
    const PyramidArgs *a = args;
    const ShadowMap *m = a->map;
    MinMaxPyramid *p = calloc(1, sizeof *p);
    if (!p) { error_set(err, "out of memory"); return NULL; }
    p->key = a->key;
    p->res = m->res;
    p->num_faces = m->num_faces;
    for (int n = m->res;; n = (n + 1) / 2) {
        p->size[p->levels] = n;
        p->offset[p->levels] = p->levels ? p->offset[p->levels - 1] + (size_t)p->num_faces * p->size[p->levels - 1] *
                                                                            p->size[p->levels - 1]
                                         : 0;
        p->levels++;
        if (n == 1) break;
    }
    p->minmax = bufpool_alloc(pyramid_pairs(p) * 2 * sizeof *p->minmax);
    if (!p->minmax) {
        free(p);
        error_set(err, "out of memory for a %d^2 min-max pyramid", m->res);
        return NULL;
    }
    for (int f = 0; f < p->num_faces; f++)
        for (int j = 0; j < m->res; j++)
            for (int i = 0; i < m->res; i++) {
                float *q = node(p, 0, f, i, j);
                q[0] = q[1] = shadowmap_texel(m, f, i, j);
            }
    for (int l = 1; l < p->levels; l++) {
        int n = p->size[l], below = p->size[l - 1];
        for (int f = 0; f < p->num_faces; f++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) {
                    float lo = INFINITY, hi = -INFINITY;
                    for (int b = 0; b < 2; b++)
                        for (int c = 0; c < 2; c++) {
                            const float *q = node(p, l - 1, f, clampi(2 * i + c, 0, below - 1), clampi(2 * j + b, 0, below - 1));
                            lo = nan_minf(lo, q[0]); /* a NaN texel: the node's bounds are unknown */
                            hi = nan_maxf(hi, q[1]);
                        }
                    float *q = node(p, l, f, i, j);
                    q[0] = lo;
                    q[1] = hi;
                }
    }
    return p;
}

const MinMaxPyramid *res_minmax_pyramid(ResourceManager *rm, const ShadowMap *map, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, map->key);
    hash_str(&h, "minmax");
    PyramidArgs a = {map, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(map->key, mk);
    snprintf(desc, sizeof desc, "min-max pyramid of map %s", mk);
    return rm_acquire(rm, &kind_pyramid, a.key, desc, build_pyramid, &a, err);
}

int minmax_query_level(const MinMaxPyramid *p, int i0, int j0, int i1, int j1)
{
    i0 = clampi(i0, 0, p->res - 1);
    i1 = clampi(i1, 0, p->res - 1);
    j0 = clampi(j0, 0, p->res - 1);
    j1 = clampi(j1, 0, p->res - 1);
    int l = 0;
    while (l + 1 < p->levels && ((i1 >> l) - (i0 >> l) > 1 || (j1 >> l) - (j0 >> l) > 1)) l++;
    return l;
}

void minmax_query(const MinMaxPyramid *p, int face, int i0, int j0, int i1, int j1, float *zmin, float *zmax)
{
    i0 = clampi(i0, 0, p->res - 1);
    i1 = clampi(i1, 0, p->res - 1);
    j0 = clampi(j0, 0, p->res - 1);
    j1 = clampi(j1, 0, p->res - 1);
    int l = minmax_query_level(p, i0, j0, i1, j1);
    float lo = INFINITY, hi = -INFINITY;
    work_texels((uint64_t)((j1 >> l) - (j0 >> l) + 1) * (uint64_t)((i1 >> l) - (i0 >> l) + 1), 2 * sizeof(float));
    for (int j = j0 >> l; j <= j1 >> l; j++)
        for (int i = i0 >> l; i <= i1 >> l; i++) {
            const float *q = node(p, l, face, i, j);
            lo = nan_minf(lo, q[0]);
            hi = nan_maxf(hi, q[1]);
        }
    *zmin = lo;
    *zmax = hi;
}

float minmax_node_min(const MinMaxPyramid *p, int face, int level, int *i, int *j)
{
    *i = clampi(*i, 0, p->size[level] - 1);
    *j = clampi(*j, 0, p->size[level] - 1);
    float lo = node(p, level, face, *i, *j)[0];
    uint64_t reads = 1;
    for (int l = level; l > 0; l--) { /* the child holding the minimum, the first in scan order on ties */
        int below = p->size[l - 1], ci = 2 * *i, cj = 2 * *j;
        for (int k = 0; k < 4; k++) {
            int a = clampi(2 * *i + (k & 1), 0, below - 1), b = clampi(2 * *j + (k >> 1), 0, below - 1);
            reads++;
            if (node(p, l - 1, face, a, b)[0] == lo) { ci = a; cj = b; break; }
        }
        *i = ci;
        *j = cj;
    }
    work_texels(reads, 2 * sizeof(float)); /* a node: its min and max */
    return lo;
}

/* ---- N-buffer level ---- */

static void buffer_destroy(void *r)
{
    MinMaxBuffer *b = r;
    bufpool_free(b->minmax);
    free(b);
}

static size_t buffer_bytes(const void *r)
{
    const MinMaxBuffer *b = r;
    return sizeof *b + (size_t)b->num_faces * b->res * b->res * 2 * sizeof(float);
}

static const ResourceKind kind_buffer = {"minmax_buffer", buffer_bytes, buffer_destroy, RES_FRAME};

typedef struct BufferArgs { const ShadowMap *map; int level; uint64_t key; } BufferArgs;

int minmax_buffer_level(int K)
{
    int level = 0;
    while ((2 << level) <= (K + 1) / 2) level++;
    return level;
}

/* Level k from level k - 1, in place: the four blocks of half the size at
 * offsets (0 or h, 0 or h), h = 2^(k-1), indices clamped to the face, as a
 * min/max along x and then along y (the four offsets are their product, and
 * the clamps are per axis). Each pass reads only entries ahead of the one it
 * writes along its own line, so lines (rows, then column strips) run in
 * parallel with no second buffer. */
#define NBUFFER_STRIP 64
static void buffer_double(float *mm, int res, int faces, int half)
{
    int rows = faces * res, strips = (res + NBUFFER_STRIP - 1) / NBUFFER_STRIP;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < rows; r++) {
        float *row = mm + 2 * (size_t)r * res;
        for (int i = 0; i < res; i++) {
            const float *q = row + 2 * (size_t)clampi(i + half, 0, res - 1);
            row[2 * i] = nan_minf(row[2 * i], q[0]);
            row[2 * i + 1] = nan_maxf(row[2 * i + 1], q[1]);
        }
    }
#pragma omp parallel for schedule(static)
    for (int t = 0; t < faces * strips; t++) {
        int f = t / strips, i0 = (t % strips) * NBUFFER_STRIP, i1 = i0 + NBUFFER_STRIP < res ? i0 + NBUFFER_STRIP : res;
        float *face = mm + 2 * (size_t)f * res * res;
        for (int j = 0; j < res; j++) {
            float *row = face + 2 * (size_t)j * res;
            const float *ahead = face + 2 * (size_t)clampi(j + half, 0, res - 1) * res;
            for (int i = i0; i < i1; i++) {
                row[2 * i] = nan_minf(row[2 * i], ahead[2 * i]);
                row[2 * i + 1] = nan_maxf(row[2 * i + 1], ahead[2 * i + 1]);
            }
        }
    }
}

static void *build_buffer(const void *args, Error *err)
{
    const BufferArgs *a = args;
    const ShadowMap *m = a->map;
    size_t n = (size_t)m->num_faces * m->res * m->res;
    MinMaxBuffer *b = calloc(1, sizeof *b);
    if (b) b->minmax = bufpool_alloc(n * 2 * sizeof *b->minmax);
    if (!b || !b->minmax) {
        if (b) buffer_destroy(b);
        error_set(err, "out of memory for a %d^2 min-max N-buffer", m->res);
        return NULL;
    }
    *b = (MinMaxBuffer){a->key, m->res, m->num_faces, a->level, b->minmax};
    for (size_t k = 0; k < n; k++) b->minmax[2 * k] = b->minmax[2 * k + 1] = m->depth[k];
    for (int l = 1; l <= a->level; l++) buffer_double(b->minmax, m->res, m->num_faces, 1 << (l - 1));
    return b;
}

const MinMaxBuffer *res_minmax_buffer(ResourceManager *rm, const ShadowMap *map, int level, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, map->key);
    hash_str(&h, "nbuffer");
    hash_u64(&h, (uint64_t)level);
    BufferArgs a = {map, level, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(map->key, mk);
    snprintf(desc, sizeof desc, "min-max N-buffer level %d (%d^2 blocks) of map %s", level, 1 << level, mk);
    return rm_acquire(rm, &kind_buffer, a.key, desc, build_buffer, &a, err);
}

/* Block starts covering [a, b] with blocks of `step`: a, a + step, ..., and
 * b - step + 1 last (overlaps are harmless for min and max). */
static int block_starts(int a, int b, int step, int *out, int max)
{
    int n = 0;
    for (int x = a; n < max - 1 && x + step - 1 < b; x += step) out[n++] = x;
    out[n++] = b - step + 1 > a ? b - step + 1 : a;
    return n;
}

void minmax_buffer_query(const MinMaxBuffer *b, int face, int i0, int j0, int i1, int j1, float *zmin, float *zmax)
{
    i0 = clampi(i0, 0, b->res - 1);
    i1 = clampi(i1, 0, b->res - 1);
    j0 = clampi(j0, 0, b->res - 1);
    j1 = clampi(j1, 0, b->res - 1);
    int step = 1 << b->level, xs[PREFILTER_MAX_K + 2], ys[PREFILTER_MAX_K + 2];
    int nx = block_starts(i0, i1, step, xs, PREFILTER_MAX_K + 2), ny = block_starts(j0, j1, step, ys, PREFILTER_MAX_K + 2);
    float lo = INFINITY, hi = -INFINITY;
    work_texels((uint64_t)nx * (uint64_t)ny, 2 * sizeof(float));
    for (int y = 0; y < ny; y++)
        for (int x = 0; x < nx; x++) {
            const float *q = b->minmax + 2 * (((size_t)face * b->res + ys[y]) * b->res + xs[x]);
            lo = nan_minf(lo, q[0]);
            hi = nan_maxf(hi, q[1]);
        }
    *zmin = lo;
    *zmax = hi;
}

/* ---- every N-buffer level of a pyramid level (MSSM) ---- */

static size_t levels_pairs(const MinMaxLevels *m) { return (size_t)m->levels * m->num_faces * m->res * m->res; }

static void levels_destroy(void *r)
{
    MinMaxLevels *m = r;
    bufpool_free(m->minmax);
    free(m);
}

static size_t levels_bytes(const void *r)
{
    const MinMaxLevels *m = r;
    return sizeof *m + levels_pairs(m) * 2 * sizeof(float);
}

static const ResourceKind kind_levels = {"minmax_levels", levels_bytes, levels_destroy, RES_FRAME};

typedef struct LevelsArgs { const MinMaxPyramid *pyramid; int base; uint64_t key; } LevelsArgs;

static inline const float *levels_entry(const MinMaxLevels *m, int k, int face, int x, int y)
{
    return m->minmax + 2 * ((((size_t)k * m->num_faces + face) * m->res + y) * m->res + x);
}

static void *build_levels(const void *args, Error *err)
{
    const LevelsArgs *a = args;
    const MinMaxPyramid *p = a->pyramid;
    MinMaxLevels *m = calloc(1, sizeof *m);
    if (!m) { error_set(err, "out of memory"); return NULL; }
    *m = (MinMaxLevels){a->key, a->base, p->size[a->base], p->num_faces, 1, NULL};
    while ((1 << (m->levels - 1)) < m->res) m->levels++;
    m->minmax = bufpool_alloc(levels_pairs(m) * 2 * sizeof *m->minmax);
    if (!m->minmax) {
        error_set(err, "out of memory for the %d levels of a %d^2 multiscale (MSSM) min-max map", m->levels, m->res);
        levels_destroy(m);
        return NULL;
    }
    size_t per_level = (size_t)m->num_faces * m->res * m->res;
    memcpy(m->minmax, node(p, a->base, 0, 0, 0), per_level * 2 * sizeof *m->minmax); /* faces are contiguous */
    for (int k = 1; k < m->levels; k++) {
        float *level = m->minmax + 2 * per_level * k;
        memcpy(level, level - 2 * per_level, per_level * 2 * sizeof *level);
        buffer_double(level, m->res, m->num_faces, 1 << (k - 1));
    }
    return m;
}

const MinMaxLevels *res_minmax_levels(ResourceManager *rm, const MinMaxPyramid *p, int base, Error *err)
{
    if (base < 0 || base >= p->levels) {
        error_set(err, "multiscale min-max map: base level %d outside the pyramid's [0, %d]", base, p->levels - 1);
        return NULL;
    }
    if (p->size[base] > MINMAX_LEVELS_MAX_RES) {
        error_set(err,
                  "multiscale min-max map (MSSM): %d^2 nodes at pyramid level %d, above the bound of %d^2 (course "
                  "§5.2.3.4: too expensive above 1024^2)",
                  p->size[base], base, MINMAX_LEVELS_MAX_RES);
        return NULL;
    }
    Hasher h;
    hash_init(&h);
    hash_u64(&h, p->key);
    hash_str(&h, "mssm");
    hash_u64(&h, (uint64_t)base);
    LevelsArgs a = {p, base, hash_final(&h)};
    char desc[160], pk[17];
    hash_hex(p->key, pk);
    snprintf(desc, sizeof desc, "multiscale (MSSM) min-max levels of pyramid %s level %d", pk, base);
    return rm_acquire(rm, &kind_levels, a.key, desc, build_levels, &a, err);
}

/* The level whose windows are the widest not wider than `width` nodes. */
static int levels_fit(const MinMaxLevels *m, int width)
{
    int k = 0;
    while (k + 1 < m->levels && (2 << k) <= width) k++;
    return k;
}

void minmax_levels_query(const MinMaxLevels *m, int face, int x0, int y0, int x1, int y1, float *zmin, float *zmax)
{
    x0 = clampi(x0, 0, m->res - 1);
    x1 = clampi(x1, 0, m->res - 1);
    y0 = clampi(y0, 0, m->res - 1);
    y1 = clampi(y1, 0, m->res - 1);
    int w = x1 - x0 + 1, h = y1 - y0 + 1, k = levels_fit(m, w < h ? w : h), n = 1 << k;
    /* windows of n <= width nodes at both ends of each axis; the wider axis
     * takes as many more as it needs (overlaps are harmless) */
    float lo = INFINITY, hi = -INFINITY;
    for (int y = y0;; y = y + n > y1 - n + 1 ? y1 - n + 1 : y + n) {
        for (int x = x0;; x = x + n > x1 - n + 1 ? x1 - n + 1 : x + n) {
            const float *q = levels_entry(m, k, face, x, y);
            lo = nan_minf(lo, q[0]);
            hi = nan_maxf(hi, q[1]);
            if (x >= x1 - n + 1) break;
        }
        if (y >= y1 - n + 1) break;
    }
    *zmin = lo;
    *zmax = hi;
}

float minmax_levels_min(const MinMaxLevels *m, int face, int k, int *x, int *y)
{
    *x = clampi(*x, 0, m->res - 1);
    *y = clampi(*y, 0, m->res - 1);
    float lo = levels_entry(m, k, face, *x, *y)[0];
    for (int l = k; l > 0; l--) { /* level l = level l - 1 at offsets 0 and h per axis, clamped */
        int h = 1 << (l - 1), cx = *x, cy = *y;
        for (int c = 0; c < 4; c++) {
            int a = clampi(*x + (c & 1) * h, 0, m->res - 1), b = clampi(*y + (c >> 1) * h, 0, m->res - 1);
            if (levels_entry(m, l - 1, face, a, b)[0] == lo) { cx = a; cy = b; break; }
        }
        *x = cx;
        *y = cy;
    }
    return lo;
}
