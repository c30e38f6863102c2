/* hash.h -- the one hashing helper: 64-bit FNV-1a over typed values.
 * Used for content-addressed keys (scenes, resources, references) and for
 * checksums of cache files. Floats are hashed by their bit pattern, with
 * -0.0 folded onto 0.0 so equal values give equal keys. */
#ifndef SL_HASH_H
#define SL_HASH_H
#include <stddef.h>
#include <stdint.h>

typedef struct Hasher { uint64_t h; } Hasher;

void hash_init(Hasher *hs);
void hash_bytes(Hasher *hs, const void *data, size_t n);
void hash_u64(Hasher *hs, uint64_t v);
void hash_f32(Hasher *hs, float v);
void hash_f64(Hasher *hs, double v);
void hash_str(Hasher *hs, const char *s); /* length-prefixed, NULL allowed */
uint64_t hash_final(const Hasher *hs);
/* 16 lowercase hex digits plus NUL. */
void hash_hex(uint64_t h, char out[17]);

/* Stateless integer hash (for per-pixel random seeds). */
uint32_t hash_u32(uint32_t x);

#endif
