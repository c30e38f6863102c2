/* bufpool.c -- the kept buffers of bufpool.h: a short list, oldest first,
 * behind one lock (OpenMP's named critical section: the engine's threads
 * are OpenMP's). Each buffer carries its capacity in a header line just
 * before the bytes it hands out. */
#include "core/bufpool.h"
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct Kept {
    unsigned char *block; /* the header line; the buffer follows it */
    size_t capacity;      /* bytes after the header */
} Kept;

static Kept kept[BUFPOOL_MAX_BLOCKS]; /* oldest first */
static int num_kept;
static size_t kept_bytes;
static long reused, allocated;

static size_t lines(size_t bytes) { return (bytes + BUFPOOL_ALIGN - 1) / BUFPOOL_ALIGN * BUFPOOL_ALIGN; }
static unsigned char *header_of(void *p) { return (unsigned char *)p - BUFPOOL_ALIGN; }

/* Kept buffer i out of the list (its block). */
static unsigned char *take_kept(int i)
{
    unsigned char *block = kept[i].block;
    kept_bytes -= kept[i].capacity;
    memmove(&kept[i], &kept[i + 1], sizeof *kept * (size_t)(num_kept - i - 1));
    num_kept--;
    return block;
}

/* The smallest kept buffer holding `bytes` with at most half of it unused, or -1. */
static int best_fit(size_t bytes)
{
    int best = -1;
    for (int i = 0; i < num_kept; i++) {
        size_t c = kept[i].capacity;
        if (c >= bytes && c / 2 <= bytes && (best < 0 || c < kept[best].capacity)) best = i;
    }
    return best;
}

void *bufpool_alloc(size_t bytes)
{
    size_t capacity = lines(bytes > 0 ? bytes : 1);
    if (capacity < bytes || capacity > SIZE_MAX - BUFPOOL_ALIGN) return NULL; /* the rounding overflowed */
    unsigned char *block = NULL;
    if (capacity >= BUFPOOL_MIN_BYTES) {
#pragma omp critical(bufpool)
        {
            int i = best_fit(capacity);
            if (i >= 0) block = take_kept(i);
            reused += i >= 0;
            allocated += i < 0;
        }
    }
    if (block) return block + BUFPOOL_ALIGN; /* its header keeps its own capacity */
    block = aligned_alloc(BUFPOOL_ALIGN, BUFPOOL_ALIGN + capacity);
    if (!block) return NULL;
    memcpy(block, &capacity, sizeof capacity);
    return block + BUFPOOL_ALIGN;
}

void bufpool_free(void *p)
{
    if (!p) return;
    unsigned char *block = header_of(p);
    size_t capacity;
    memcpy(&capacity, block, sizeof capacity);
    if (capacity < BUFPOOL_MIN_BYTES || capacity > BUFPOOL_MAX_BYTES) {
        free(block);
        return;
    }
#pragma omp critical(bufpool)
    {
        while (num_kept > 0 && (num_kept == BUFPOOL_MAX_BLOCKS || kept_bytes + capacity > BUFPOOL_MAX_BYTES))
            free(take_kept(0));
        kept[num_kept++] = (Kept){block, capacity};
        kept_bytes += capacity;
    }
}

void bufpool_release(void)
{
#pragma omp critical(bufpool)
    while (num_kept > 0) free(take_kept(num_kept - 1));
}

BufpoolStats bufpool_stats(void)
{
    BufpoolStats s;
#pragma omp critical(bufpool)
    s = (BufpoolStats){kept_bytes, num_kept, reused, allocated};
    return s;
}
