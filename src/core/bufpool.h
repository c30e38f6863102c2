/* bufpool.h -- large buffers kept between the builds that use them.
 *
 * A renderer allocates its shadow map once and draws into it every frame;
 * a resource that is built, destroyed and built again (the median of a
 * scope's builds, a sweep's next point, an animation's next frame) would
 * otherwise map fresh pages from the kernel each time, and on a virtual
 * machine the page faults of a 4096^2 map cost 10-30x its render
 * (bench/README.md, step 9). Buffers of at least BUFPOOL_MIN_BYTES freed
 * here are kept (up to BUFPOOL_MAX_BLOCKS of them and BUFPOOL_MAX_BYTES in
 * all, the oldest given back first) and handed to the next request they
 * fit without wasting more than half of themselves. Their contents are
 * whatever the last user left: callers write every byte they read.
 * Every buffer starts on a BUFPOOL_ALIGN-byte line and is a whole number of
 * lines long. A fresh buffer of at least BUFPOOL_MIN_BYTES comes with its
 * pages in place (bufpool_populates): its first write faults no page in.
 * Thread-safe. */
#ifndef SL_BUFPOOL_H
#define SL_BUFPOOL_H
#include <stdbool.h>
#include <stddef.h>

#define BUFPOOL_ALIGN 64                        /* bytes: a cache line */
#define BUFPOOL_MIN_BYTES ((size_t)1 << 20)     /* smaller buffers: malloc's own free lists serve them */
#define BUFPOOL_MAX_BLOCKS 16
#define BUFPOOL_MAX_BYTES ((size_t)1 << 30)     /* kept in all, at most */

/* NULL when out of memory; bytes == 0 gives a buffer of one line. */
void *bufpool_alloc(size_t bytes);
/* p from bufpool_alloc, or NULL (nothing). */
void bufpool_free(void *p);
/* Whether fresh buffers of BUFPOOL_MIN_BYTES and more come populated: Linux
 * 5.14 and later (MADV_POPULATE_WRITE), not under AddressSanitizer (whose
 * red zones guard heap blocks only: there they come from malloc). */
bool bufpool_populates(void);
/* Give every kept buffer back to the system. */
void bufpool_release(void);

typedef struct BufpoolStats {
    size_t kept_bytes;
    int kept_blocks;
    long reused, allocated; /* requests of at least BUFPOOL_MIN_BYTES served from the pool / the system */
} BufpoolStats;
BufpoolStats bufpool_stats(void);
#endif
