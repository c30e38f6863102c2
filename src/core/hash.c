/* hash.c -- FNV-1a 64 (Fowler, Noll, Vo) and a 32-bit integer mixer. */
#include "core/hash.h"
#include <stdio.h>
#include <string.h>

#define FNV_OFFSET 0xcbf29ce484222325ull
#define FNV_PRIME 0x100000001b3ull

void hash_init(Hasher *hs) { hs->h = FNV_OFFSET; }

void hash_bytes(Hasher *hs, const void *data, size_t n)
{
    const unsigned char *p = data;
    uint64_t h = hs->h;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= FNV_PRIME;
    }
    hs->h = h;
}

void hash_u64(Hasher *hs, uint64_t v) { hash_bytes(hs, &v, sizeof v); }

void hash_f32(Hasher *hs, float v)
{
    if (v == 0.0f) v = 0.0f; /* fold -0 onto +0 */
    hash_bytes(hs, &v, sizeof v);
}

void hash_f64(Hasher *hs, double v)
{
    if (v == 0.0) v = 0.0;
    hash_bytes(hs, &v, sizeof v);
}

void hash_str(Hasher *hs, const char *s)
{
    size_t n = s ? strlen(s) : 0;
    hash_u64(hs, n);
    if (n) hash_bytes(hs, s, n);
}

uint64_t hash_final(const Hasher *hs) { return hs->h; }

void hash_hex(uint64_t h, char out[17]) { snprintf(out, 17, "%016llx", (unsigned long long)h); }

/* Integer finaliser with good avalanche (the "lowbias32" constants of
 * C. Wellons' hash-prospector). */
uint32_t hash_u32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}
