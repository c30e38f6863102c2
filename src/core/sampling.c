/* sampling.c -- R2, jittered-stratified and independent 2D sample streams.
 * R2 (M. Roberts 2018): x_i = frac(s + i * (1/phi2, 1/phi2^2)), phi2 the
 * plastic number 1.3247..., the 2D generalisation of the golden ratio. */
#include "core/sampling.h"
#include <math.h>
#include <string.h>
#include "core/hash.h"

static const char *const names[SAMPLING_PATTERN_COUNT] = {"r2", "stratified", "random"};

const char *sampling_pattern_name(SamplingPattern p) { return names[p]; }

bool sampling_pattern_parse(const char *name, SamplingPattern *p, Error *err)
{
    for (int i = 0; i < SAMPLING_PATTERN_COUNT; i++) {
        if (strcmp(name, names[i]) == 0) {
            *p = (SamplingPattern)i;
            return true;
        }
    }
    return error_set(err, "sampling pattern '%s' is not one of: r2, stratified, random", name);
}

static int isqrt(int n)
{
    int m = (int)sqrt((double)n);
    while (m * m > n) m--;
    while ((m + 1) * (m + 1) <= n) m++;
    return m;
}

bool sampling_check_count(SamplingPattern p, int count, Error *err)
{
    if (count < 1) return error_set(err, "sample count %d must be >= 1", count);
    if (p == SAMPLING_STRATIFIED && isqrt(count) * isqrt(count) != count)
        return error_set(err, "sample count %d must be a square (m x m) for the stratified pattern", count);
    return true;
}

int sampling_batches(SamplingPattern p, int count)
{
    switch (p) {
    case SAMPLING_R2: return count < SAMPLING_MAX_BATCHES ? count : SAMPLING_MAX_BATCHES;
    case SAMPLING_STRATIFIED: {
        int m = isqrt(count); /* a square count: batches d^2 of (m/d)^2 samples each */
        for (int d = 4; d > 1; d--)
            if (m % d == 0) return d * d;
        return 1;
    }
    case SAMPLING_RANDOM: break;
    }
    return 1;
}

int sampling_batch_of(SamplingPattern p, int i, int count) { return i % sampling_batches(p, count); }

uint32_t sampling_stream(uint32_t seed, uint32_t id) { return hash_u32(id ^ hash_u32(seed + 0x9e3779b9u)); }

/* 24 random bits to a float in [0,1). */
static float unit_float(uint32_t h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

static float frac(double x) { return (float)(x - floor(x)); }

void sample_2d(SamplingPattern p, uint32_t stream, int i, int count, float *u, float *v)
{
    switch (p) {
    case SAMPLING_R2: {
        const double a1 = 0.7548776662466927, a2 = 0.5698402909980532; /* 1/phi2, 1/phi2^2 */
        uint32_t m = (uint32_t)sampling_batches(p, count), b = (uint32_t)i % m, j = (uint32_t)i / m;
        uint32_t bs = stream ^ (0x85ebca6bu * b); /* the batch's own shift */
        double su = unit_float(hash_u32(bs)), sv = unit_float(hash_u32(bs ^ 0x5bd1e995u));
        *u = frac(su + a1 * (double)j);
        *v = frac(sv + a2 * (double)j);
        break;
    }
    case SAMPLING_STRATIFIED: {
        int m = sampling_batches(p, count), j = i / m; /* index within batch i % m */
        int side = isqrt(count / m); /* the batch's own jittered side x side grid */
        *u = ((float)(j % side) + unit_float(hash_u32(stream ^ (2u * (uint32_t)i)))) / (float)side;
        *v = ((float)(j / side) + unit_float(hash_u32(stream ^ (2u * (uint32_t)i + 1u) ^ 0x68e31da4u))) / (float)side;
        break;
    }
    case SAMPLING_RANDOM:
        *u = unit_float(hash_u32(stream ^ (2u * (uint32_t)i)));
        *v = unit_float(hash_u32(stream ^ (2u * (uint32_t)i + 1u) ^ 0x68e31da4u));
        break;
    }
    /* (float)(x + frac) can round up to 1.0: keep the half-open interval. */
    if (*u >= 1.0f) *u = 0x1.fffffep-1f;
    if (*v >= 1.0f) *v = 0x1.fffffep-1f;
}
