/* bufpool.c -- the kept buffers of bufpool.h: a short list, oldest first,
 * behind one lock (OpenMP's named critical section: the engine's threads
 * are OpenMP's). Each buffer carries its capacity in a header line just
 * before the bytes it hands out. Buffers of BUFPOOL_MIN_BYTES and more are
 * mapped from the kernel and populated (fresh_block), smaller ones come from
 * malloc. */
#include "core/bufpool.h"
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define HUGE_PAGE ((size_t)2 << 20) /* bytes: x86-64's and arm64's transparent huge page */

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

/* Large blocks mapped from the kernel (fresh_block), except under
 * AddressSanitizer, which guards only the heap's blocks with red zones. */
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANITIZED_HEAP 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(SANITIZED_HEAP)
enum { MAP_LARGE = 0 };
#else
enum { MAP_LARGE = 1 };
#endif

static bool mapped(size_t capacity) { return MAP_LARGE && capacity >= BUFPOOL_MIN_BYTES; }

/* Bytes mapped for a block of `capacity` bytes after its header: whole
 * pages (the last huge page's worth may be 4 KiB pages: no huge page is
 * rounded up to). */
static size_t mapped_bytes(size_t capacity)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    return (BUFPOOL_ALIGN + capacity + page - 1) / page * page;
}

/* Ask for [p, p + n) in huge pages and populated for writing in one call
 * (Linux's MADV_HUGEPAGE and MADV_POPULATE_WRITE): hints; true when the
 * pages are there now. */
static bool populate(unsigned char *p, size_t n)
{
#if defined(MADV_HUGEPAGE)
    (void)madvise(p, n, MADV_HUGEPAGE); /* refused where transparent huge pages are off: 4 KiB pages then */
#endif
#if defined(MADV_POPULATE_WRITE)
    return madvise(p, n, MADV_POPULATE_WRITE) == 0;
#else
    (void)p;
    (void)n;
    return false;
#endif
}

/* A block for `capacity` bytes after its header, mapped on a huge page's
 * boundary and populated (populate; where the kernel refuses, its pages
 * fault in one by one as before). Its first touch then costs no fault per
 * 4 KiB page: on the virtual machines this project is measured on a fault
 * costs about 3 us, and 256 MiB first written took 700-950 ms one page at a
 * time against 20 ms so (bench/README.md, step 11). NULL when the kernel
 * has no room. */
static unsigned char *fresh_block(size_t capacity)
{
    size_t n = mapped_bytes(capacity);
    if (n < capacity || n > SIZE_MAX - HUGE_PAGE) return NULL;
    unsigned char *p = mmap(NULL, n + HUGE_PAGE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) return NULL;
    size_t head = (HUGE_PAGE - (uintptr_t)p % HUGE_PAGE) % HUGE_PAGE; /* up to the boundary */
    if (head) munmap(p, head);
    munmap(p + head + n, HUGE_PAGE - head); /* the tail past the block */
    p += head;
    (void)populate(p, n);
    return p;
}

static size_t capacity_of(const unsigned char *block)
{
    size_t capacity;
    memcpy(&capacity, block, sizeof capacity);
    return capacity;
}

/* Give a block back: to the kernel (fresh_block's) or to malloc. */
static void block_free(unsigned char *block)
{
    size_t capacity = capacity_of(block);
    if (mapped(capacity)) munmap(block, mapped_bytes(capacity));
    else free(block);
}

/* Probed on one huge page each call (tens of microseconds). */
bool bufpool_populates(void)
{
    if (!MAP_LARGE) return false;
    unsigned char *p = mmap(NULL, HUGE_PAGE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) return false;
    bool ok = populate(p, HUGE_PAGE);
    munmap(p, HUGE_PAGE);
    return ok;
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
    block = mapped(capacity) ? fresh_block(capacity) : aligned_alloc(BUFPOOL_ALIGN, BUFPOOL_ALIGN + capacity);
    if (!block) return NULL;
    memcpy(block, &capacity, sizeof capacity);
    return block + BUFPOOL_ALIGN;
}

void bufpool_free(void *p)
{
    if (!p) return;
    unsigned char *block = header_of(p);
    size_t capacity = capacity_of(block);
    if (capacity < BUFPOOL_MIN_BYTES || capacity > BUFPOOL_MAX_BYTES) {
        block_free(block);
        return;
    }
#pragma omp critical(bufpool)
    {
        while (num_kept > 0 && (num_kept == BUFPOOL_MAX_BLOCKS || kept_bytes + capacity > BUFPOOL_MAX_BYTES))
            block_free(take_kept(0));
        kept[num_kept++] = (Kept){block, capacity};
        kept_bytes += capacity;
    }
}

void bufpool_release(void)
{
#pragma omp critical(bufpool)
    while (num_kept > 0) block_free(take_kept(num_kept - 1));
}

BufpoolStats bufpool_stats(void)
{
    BufpoolStats s;
#pragma omp critical(bufpool)
    s = (BufpoolStats){kept_bytes, num_kept, reused, allocated};
    return s;
}
