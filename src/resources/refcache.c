/* refcache.c -- reference cache files. Layout (little-endian, native):
 *   "SLREF\0\0\2" | key u64 | width, height, channels, measure, samples,
 *   pattern i32 | seed u32 | rays_per_sample, estimator, batches, shared_set i32 (0 or 1: formerly
 *   padding, always 0, so older entries read as per-view-sample sets) |
 *   rays i64 | value floats | std_error floats | FNV-1a 64 checksum of
 *   everything before it. Version 2: std_error by randomised QMC batches
 *   (version 1's smoothed binomial entries are read as corrupt and recomputed). */
#include "resources/refcache.h"
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "core/hash.h"

static const char MAGIC[8] = {'S', 'L', 'R', 'E', 'F', 0, 0, 2};

typedef struct Header {
    char magic[8];
    uint64_t key;
    int32_t width, height, channels, measure, samples, pattern;
    uint32_t seed;
    int32_t rays_per_sample, estimator, batches, shared_set;
    int64_t rays;
} Header;

void refcache_default_dir(char *out, size_t n)
{
    const char *env = getenv("SHADOWLAB_CACHE"), *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (env && *env) snprintf(out, n, "%s", env);
    else if (xdg && *xdg) snprintf(out, n, "%s/shadowlab", xdg);
    else snprintf(out, n, "%s/.cache/shadowlab", home && *home ? home : "/tmp");
}

void refcache_path(const char *dir, uint64_t key, char *out, size_t n)
{
    char hex[17];
    hash_hex(key, hex);
    snprintf(out, n, "%s/ref-%s.bin", dir, hex);
}

static RefcacheStatus corrupt(const char *path, const char *what, Error *why)
{
    error_set(why, "%s: corrupt reference cache entry (%s)", path, what);
    return REFCACHE_CORRUPT;
}

static bool header_sane(const Header *h, uint64_t key)
{
    return memcmp(h->magic, MAGIC, 8) == 0 && h->key == key && h->width > 0 && h->height > 0 &&
           h->width <= 65536 && h->height <= 65536 && (h->channels == 1 || h->channels == 3) &&
           h->measure >= 0 && h->measure <= MEASURE_IRRADIANCE && h->pattern >= 0 &&
           h->pattern < SAMPLING_PATTERN_COUNT && h->samples > 0 && h->rays_per_sample > 0 &&
           h->rays_per_sample <= h->samples && h->estimator >= 0 && h->estimator < REF_ERROR_ESTIMATOR_COUNT &&
           h->batches >= 1 && h->batches <= SAMPLING_MAX_BATCHES && (h->shared_set == 0 || h->shared_set == 1);
}

RefcacheStatus refcache_read(const char *path, uint64_t key, Reference *ref, Error *why)
{
    memset(ref, 0, sizeof *ref);
    size_t size;
    Error e;
    if (!file_exists(path)) return REFCACHE_MISS;
    char *buf = file_read_all(path, &size, &e);
    if (!buf) return corrupt(path, e.msg, why);
    Header h;
    RefcacheStatus st = REFCACHE_CORRUPT;
    if (size < sizeof h + 8) { corrupt(path, "truncated header", why); goto done; }
    memcpy(&h, buf, sizeof h);
    if (!header_sane(&h, key)) { corrupt(path, "bad header or key", why); goto done; }
    size_t n = (size_t)h.width * (size_t)h.height * (size_t)h.channels;
    size_t payload = sizeof h + 2 * n * sizeof(float);
    if (size != payload + 8) { corrupt(path, "wrong size", why); goto done; }
    Hasher hs;
    hash_init(&hs);
    hash_bytes(&hs, buf, payload);
    uint64_t sum;
    memcpy(&sum, buf + payload, 8);
    if (sum != hash_final(&hs)) { corrupt(path, "checksum mismatch", why); goto done; }
    if (!image_init(&ref->value, h.width, h.height, h.channels, why) ||
        !image_init(&ref->std_error, h.width, h.height, h.channels, why)) {
        reference_free(ref);
        goto done;
    }
    memcpy(ref->value.data, buf + sizeof h, n * sizeof(float));
    memcpy(ref->std_error.data, buf + sizeof h + n * sizeof(float), n * sizeof(float));
    ref->params = (ReferenceParams){(Measure)h.measure, h.samples, (SamplingPattern)h.pattern, h.seed, h.shared_set == 1};
    ref->rays = h.rays;
    ref->rays_per_sample = h.rays_per_sample;
    ref->estimator = (RefErrorEstimator)h.estimator;
    ref->batches = h.batches;
    st = REFCACHE_HIT;
done:
    free(buf);
    return st;
}

static bool write_chunk(AtomicFile *af, Hasher *hs, const void *data, size_t n)
{
    hash_bytes(hs, data, n);
    return fwrite(data, 1, n, af->fp) == n;
}

bool refcache_write(const char *dir, const char *path, uint64_t key, const Reference *ref, Error *err)
{
    if (!mkdir_p(dir, err)) return false;
    Header h = {.key = key, .width = ref->value.width, .height = ref->value.height, .channels = ref->value.channels,
                .measure = (int32_t)ref->params.measure, .samples = ref->params.samples,
                .pattern = (int32_t)ref->params.pattern, .seed = ref->params.seed,
                .rays_per_sample = ref->rays_per_sample, .estimator = (int32_t)ref->estimator,
                .batches = ref->batches, .shared_set = ref->params.shared_set, .rays = ref->rays};
    memcpy(h.magic, MAGIC, 8);
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    Hasher hs;
    hash_init(&hs);
    size_t n = image_count(&ref->value) * sizeof(float);
    bool ok = write_chunk(&af, &hs, &h, sizeof h) && write_chunk(&af, &hs, ref->value.data, n) &&
              write_chunk(&af, &hs, ref->std_error.data, n);
    uint64_t sum = hash_final(&hs);
    ok = ok && fwrite(&sum, 1, 8, af.fp) == 8;
    if (!ok) {
        atomic_abort(&af);
        return error_set(err, "%s: write failed", path);
    }
    return atomic_commit(&af, err);
}
