/* test_bufpool.c -- the kept buffers of core/bufpool.h: a large buffer freed
 * is handed back to the next request it fits (so a map built again maps no
 * fresh pages: the process's minor page faults stay flat), a fresh one comes
 * with its pages where the kernel populates them, one that would
 * waste more than half of itself is not, small buffers and the pool's
 * limits are respected, and every buffer starts on a line. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include "core/bufpool.h"
#include "test.h"

static long minor_faults(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_minflt;
}

TEST(test_bufpool_reuses_a_freed_buffer_of_the_same_size)
{
    bufpool_release();
    BufpoolStats s0 = bufpool_stats();
    size_t bytes = (size_t)4 << 20;
    unsigned char *a = bufpool_alloc(bytes);
    CHECK(a && (uintptr_t)a % BUFPOOL_ALIGN == 0);
    bufpool_free(a);
    CHECK(bufpool_stats().kept_blocks == 1 && bufpool_stats().kept_bytes == bytes);
    unsigned char *b = bufpool_alloc(bytes - 100); /* rounds up to the same lines */
    CHECK(b == a);
    BufpoolStats s1 = bufpool_stats();
    CHECK(s1.reused == s0.reused + 1 && s1.allocated == s0.allocated + 1 && s1.kept_blocks == 0);
    bufpool_free(b);
    bufpool_release();
    CHECK(bufpool_stats().kept_blocks == 0 && bufpool_stats().kept_bytes == 0);
}

/* Minor page faults of writing every byte of a bufpool buffer of `bytes`;
 * the buffer is kept (freed to the pool) afterwards. */
static long faults_writing(size_t bytes)
{
    unsigned char *d = bufpool_alloc(bytes);
    if (!d) return -1;
    long f0 = minor_faults();
    memset(d, 0x7f, bytes);
    long faults = minor_faults() - f0;
    bufpool_free(d);
    return faults;
}

/* A 64 MiB map written, freed and written again: the second pass touches
 * pages already mapped (a fresh allocation faulting its pages in one by one
 * takes 16384 faults); where the kernel populates fresh buffers
 * (bufpool_populates), the first pass touches mapped pages too. */
TEST(test_bufpool_buffers_come_with_their_pages)
{
    bufpool_release();
    size_t bytes = (size_t)64 << 20, pages = bytes / 4096;
    long first = faults_writing(bytes), again = faults_writing(bytes);
    bufpool_release();
    CHECK_MSG(again >= 0 && again < (long)pages / 100, "%ld minor faults writing a kept 64 MiB buffer (%zu pages)",
              again, pages);
    if (bufpool_populates())
        CHECK_MSG(first >= 0 && first < (long)pages / 100,
                  "%ld minor faults writing a fresh, populated 64 MiB buffer (%zu pages)", first, pages);
    else
        printf("    note: this kernel or build does not populate fresh buffers: %ld faults on the first write\n",
               first);
}

TEST(test_bufpool_refuses_to_waste_more_than_half_a_buffer)
{
    bufpool_release();
    unsigned char *big = bufpool_alloc((size_t)8 << 20);
    CHECK(big);
    bufpool_free(big);
    unsigned char *small = bufpool_alloc((size_t)3 << 20); /* 8 MiB would leave 5 unused */
    CHECK(small && small != big);
    CHECK(bufpool_stats().kept_blocks == 1);
    unsigned char *half = bufpool_alloc((size_t)4 << 20); /* exactly half: fits */
    CHECK(half == big);
    bufpool_free(small);
    bufpool_free(half);
    bufpool_release();
}

TEST(test_bufpool_keeps_no_small_buffers_and_at_most_its_limit)
{
    bufpool_release();
    void *tiny = bufpool_alloc(1000);
    CHECK(tiny && (uintptr_t)tiny % BUFPOOL_ALIGN == 0);
    bufpool_free(tiny);
    CHECK(bufpool_stats().kept_blocks == 0);
    void *zero = bufpool_alloc(0);
    CHECK(zero);
    bufpool_free(zero);
    bufpool_free(NULL);
    void *p[BUFPOOL_MAX_BLOCKS + 2];
    for (int i = 0; i < BUFPOOL_MAX_BLOCKS + 2; i++) CHECK((p[i] = bufpool_alloc(BUFPOOL_MIN_BYTES)) != NULL);
    for (int i = 0; i < BUFPOOL_MAX_BLOCKS + 2; i++) bufpool_free(p[i]);
    BufpoolStats s = bufpool_stats();
    CHECK(s.kept_blocks == BUFPOOL_MAX_BLOCKS && s.kept_bytes == BUFPOOL_MAX_BLOCKS * BUFPOOL_MIN_BYTES);
    void *again = bufpool_alloc(BUFPOOL_MIN_BYTES); /* the oldest two went back to the system: p[2] is the oldest kept */
    CHECK(again == p[2]);
    bufpool_free(again);
    bufpool_release();
    CHECK(bufpool_stats().kept_bytes == 0);
}
