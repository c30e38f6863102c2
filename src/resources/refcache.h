/* refcache.h -- the on-disk reference cache: content-addressed by the
 * reference key (a hash of everything a reference depends on), written
 * atomically (temporary file, fsync, rename) and verified on read (magic,
 * version, key, sizes and a checksum of the whole payload), so a corrupt
 * entry is detected, reported and recomputed. */
#ifndef SL_REFCACHE_H
#define SL_REFCACHE_H
#include "rt/reference.h"

typedef enum RefcacheStatus { REFCACHE_MISS, REFCACHE_HIT, REFCACHE_CORRUPT } RefcacheStatus;

/* Default folder: $SHADOWLAB_CACHE, else $XDG_CACHE_HOME/shadowlab, else
 * ~/.cache/shadowlab. */
void refcache_default_dir(char *out, size_t n);
void refcache_path(const char *dir, uint64_t key, char *out, size_t n);
RefcacheStatus refcache_read(const char *path, uint64_t key, Reference *ref, Error *why);
bool refcache_write(const char *dir, const char *path, uint64_t key, const Reference *ref, Error *err);

#endif
