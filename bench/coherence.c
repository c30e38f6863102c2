/* coherence.c -- what moving data between this machine's cores costs, the
 * bound under the two-thread figures of data that one pass writes and the
 * next reads on whichever thread takes it (the rasterizer's set-up triangles
 * and bins, its tiles' copy into the map; issue 17):
 *   round trip: two threads pass a token through one cache line, each
 *     waiting for the other's write (ns per one-way hand-over);
 *   rewrite: a thread rewrites a buffer of --kib KiB that it wrote last
 *     (own) or that the other thread wrote last (other), ns per 64-byte line;
 *     other / own is what a pass pays for writing lines the other core holds.
 * Two OpenMP threads; rounds (--repeat) alternate own and other, and the
 * ratio is the median of the per-round ratios. Row in DIR/coherence.csv.
 * Usage: coherence [--kib K] [--repeat R] [-o DIR] */
#include <omp.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"

#define LINE 64
#define HANDOVERS 200000
#define HEADER "handover_ns,own_ns_per_line,other_ns_per_line,other_over_own,kib," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    int kib;
} Options;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    return strcmp(a, "--kib") == 0 && bench_parse_int(v, 4, 1 << 20, &o->kib) ? 2 : 0;
}

/* ns per one-way hand-over of a token between the two threads. */
static double handover_ns(void)
{
    _Alignas(LINE) static atomic_int token;
    atomic_store(&token, 0);
    double t0 = 0.0, t1 = 0.0;
#pragma omp parallel num_threads(2)
    {
        int me = omp_get_thread_num();
#pragma omp barrier
        if (me == 0) t0 = timer_now_s();
        for (int k = me; k < HANDOVERS; k += 2) {
            while (atomic_load_explicit(&token, memory_order_acquire) != k) {
            }
            atomic_store_explicit(&token, k + 1, memory_order_release);
        }
        if (me == 0) t1 = timer_now_s();
    }
    return (t1 - t0) * 1e9 / HANDOVERS;
}

/* Thread `writer` fills buf, then thread 0 rewrites it: ns per line of the
 * rewrite (writer 0: its own lines; 1: the other core's). */
static double rewrite_ns(unsigned char *buf, size_t bytes, int writer, int pass)
{
    double s = 0.0;
#pragma omp parallel num_threads(2)
    {
        int me = omp_get_thread_num();
        if (me == writer) memset(buf, pass & 0xff, bytes);
#pragma omp barrier
        if (me == 0) {
            double t0 = timer_now_s();
            memset(buf, (pass + 1) & 0xff, bytes);
            s = timer_now_s() - t0;
        }
    }
    return s * 1e9 / (double)(bytes / LINE);
}

int main(int argc, char **argv)
{
    Options o = {.kib = 256};
    if (!bench_parse(argc, argv, 9, &o.c, own_option, &o) || o.c.num_scenes > 0)
        return bench_usage("coherence [--kib K] [--repeat R] [-o DIR]");
    size_t bytes = (size_t)o.kib << 10;
    unsigned char *buf = aligned_alloc(LINE, bytes);
    double *own = malloc(sizeof(double) * 3 * (size_t)o.c.repeat), *other = own + o.c.repeat, *ratio = other + o.c.repeat;
    if (!buf || !own) return fprintf(stderr, "coherence: out of memory\n"), 1;
    rewrite_ns(buf, bytes, 0, 0); /* warm-up: pages touched, threads started */
    double ho = handover_ns();
    for (int r = 0; r < o.c.repeat; r++) {
        own[r] = rewrite_ns(buf, bytes, 0, 2 * r);
        other[r] = rewrite_ns(buf, bytes, 1, 2 * r + 1);
        ratio[r] = other[r] / own[r];
    }
    double mo = bench_median(own, o.c.repeat), mt = bench_median(other, o.c.repeat), q = bench_median(ratio, o.c.repeat);
    printf("coherence: hand-over %.1f ns one way; rewriting %d KiB: own lines %.2f ns/line, the other core's %.2f "
           "ns/line, x%.2f\n",
           ho, o.kib, mo, mt, q);
    char row[1024], tail[512], path[4096];
    bench_tail(tail, sizeof tail, 2);
    snprintf(row, sizeof row, "%.2f,%.3f,%.3f,%.3f,%d,%s\n", ho, mo, mt, q, o.kib, tail);
    snprintf(path, sizeof path, "%s/coherence.csv", o.c.dir);
    Error err = {0};
    bool ok = bench_csv_append(path, HEADER, row, &err);
    if (!ok) fprintf(stderr, "coherence: %s\n", err.msg);
    free(own);
    free(buf);
    return ok ? 0 : 1;
}
