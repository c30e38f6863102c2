/* cpu_speed.c -- how fast each of this machine's CPUs runs two fixed loops
 * alone and with every other one busy: the bound the machine itself puts on
 * an N-thread speed-up, measured beside the figures it bounds (issue 17). On
 * a shared VM the vCPUs do not keep one speed: one can run at half the
 * other's for minutes, which a 1-thread run landing on the fast one reads as
 * poor scaling, and on the slow one as a superlinear speed-up.
 *   compute: bench_spin_s, four multiply-add chains in registers (no memory:
 *     the cores' own speed);
 *   stream: a read of a private STREAM_MIB MiB buffer (each thread its own,
 *     far over the caches: the memory bandwidth the CPUs share);
 * hand-overs between cores are coherence.c's. For each loop:
 *   alone: on CPU c, pinned (sched_setaffinity), the others idle;
 *   together: on every CPU 0 ... N-1 at once, each pinned;
 * every round runs each CPU alone then all together, and a figure is the
 * median over rounds. The bounds, against the median CPU's alone time t1:
 *   dynamic = sum_c t1 / together_c (work handed out as threads ask for it:
 *     each CPU adds its own rate),
 *   static = N t1 / max_c together_c (equal shares: the slowest finishes last).
 * One row per loop and CPU in DIR/cpu_speed.csv (the bounds repeated on each), tagged
 * with --label (when in the run it was taken).
 * Usage: cpu_speed [--threads N] [--repeat R] [--label L] [-o DIR] */
#define _GNU_SOURCE
#include <omp.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"

#define MAX_CPUS 256
#define SPIN_ITERS 20000000L /* about 35 ms a run on this AMD EPYC */
#define STREAM_MIB 64
#define STREAM_PASSES 4
#define HEADER "label,loop,cpu,alone_ms,together_ms,alone_over_median,together_over_alone,dynamic_bound,static_bound," \
               BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    const char *label;
} Options;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    if (strcmp(a, "--label") != 0 || !v || !*v || strlen(v) > 64 || strpbrk(v, ",\"\n")) return 0;
    o->label = v;
    return 2;
}

/* The stream loop's result, written so the loop stays (one per thread: all write it at once). */
static _Thread_local volatile double stream_result;

/* The stream loop (milliseconds): STREAM_PASSES reads of buf, four sums. */
static double stream_ms(const double *buf)
{
    size_t n = ((size_t)STREAM_MIB << 20) / sizeof(double);
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    double t0 = timer_now_s();
    for (int p = 0; p < STREAM_PASSES; p++)
        for (size_t i = 0; i < n; i += 4) {
            s0 += buf[i];
            s1 += buf[i + 1];
            s2 += buf[i + 2];
            s3 += buf[i + 3];
        }
    double ms = (timer_now_s() - t0) * 1e3;
    stream_result = s0 + s1 + s2 + s3;
    return ms;
}

enum { LOOP_COMPUTE, LOOP_STREAM, NUM_LOOPS };
static const char *const loop_name[NUM_LOOPS] = {"compute", "stream"};

/* One run of loop `loop` on the calling thread (buf: its stream buffer). */
static double run_loop(int loop, const double *buf)
{
    return loop == LOOP_COMPUTE ? bench_spin_s(SPIN_ITERS) * 1e3 : stream_ms(buf);
}

/* Pin the calling thread to CPU c; false where the system refuses. */
static bool pin(int c)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(c, &set);
    return sched_setaffinity(0, sizeof set, &set) == 0;
}

/* One round of loop `loop`: each CPU alone (the others' threads wait at
 * the barrier), then all at once; bufs[c]: CPU c's stream buffer. false
 * where a CPU cannot be pinned. */
static bool round_once(int loop, int n, double *const *bufs, double *alone, double *together)
{
    bool ok = true;
#pragma omp parallel num_threads(n) reduction(&& : ok)
    {
        int me = omp_get_thread_num();
        cpu_set_t saved;
        ok = sched_getaffinity(0, sizeof saved, &saved) == 0 && pin(me);
        if (loop == LOOP_STREAM) /* first touch on its own CPU */
            memset(bufs[me], 1, (size_t)STREAM_MIB << 20); /* nonzero: no page a host could share */
        for (int c = 0; c < n; c++) {
#pragma omp barrier
            if (me == c) alone[c] = run_loop(loop, bufs[me]);
        }
#pragma omp barrier
        together[me] = run_loop(loop, bufs[me]);
        if (ok) sched_setaffinity(0, sizeof saved, &saved);
    }
    return ok;
}

/* Loop `loop`'s rounds (t: R rounds of n alone then n together times,
 * scratch) into medians, bounds, the printed lines and its rows. */
static bool measure_loop(const Options *o, int loop, double *const *bufs, double *t, Error *err)
{
    int n = o->c.threads, R = o->c.repeat;
    double *alone = t, *together = t + (size_t)n * R, *col = together + (size_t)n * R; /* col: one CPU's rounds */
    for (int r = 0; r < R; r++)
        if (!round_once(loop, n, bufs, alone + (size_t)r * n, together + (size_t)r * n))
            return error_set(err, "cannot pin a thread to each of CPUs 0 ... %d", n - 1);
    double med_alone[MAX_CPUS], med_together[MAX_CPUS];
    for (int c = 0; c < n; c++) {
        for (int r = 0; r < R; r++) col[r] = alone[(size_t)r * n + c];
        med_alone[c] = bench_median(col, R);
        for (int r = 0; r < R; r++) col[r] = together[(size_t)r * n + c];
        med_together[c] = bench_median(col, R);
    }
    double t1 = bench_median(med_alone, n), slowest = 0.0, dynamic = 0.0;
    for (int c = 0; c < n; c++) {
        dynamic += t1 / med_together[c];
        if (med_together[c] > slowest) slowest = med_together[c];
    }
    double stat = n * t1 / slowest;
    printf("cpu_speed (%s), %s: the machine's bound on a %d-thread speed-up %.2f dynamic, %.2f static\n", o->label,
           loop_name[loop], n, dynamic, stat);
    char tail[512], path[4096];
    bench_tail(tail, sizeof tail, n);
    snprintf(path, sizeof path, "%s/cpu_speed.csv", o->c.dir);
    for (int c = 0; c < n; c++) {
        char row[1024];
        printf("  CPU %3d: alone %7.2f ms (x%.2f of the median), with all busy %7.2f ms (x%.2f of alone)\n", c,
               med_alone[c], med_alone[c] / t1, med_together[c], med_together[c] / med_alone[c]);
        snprintf(row, sizeof row, "%s,%s,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%s\n", o->label, loop_name[loop], c,
                 med_alone[c], med_together[c], med_alone[c] / t1, med_together[c] / med_alone[c], dynamic, stat, tail);
        if (!bench_csv_append(path, HEADER, row, err)) return false;
    }
    return true;
}

int main(int argc, char **argv)
{
    Options o = {.label = "run"};
    if (!bench_parse(argc, argv, 5, &o.c, own_option, &o) || o.c.num_scenes > 0)
        return bench_usage("cpu_speed [--threads N] [--repeat R] [--label L] [-o DIR]");
    int n = o.c.threads;
    if (n > MAX_CPUS || n > CPU_SETSIZE) return fprintf(stderr, "cpu_speed: --threads %d over %d\n", n, MAX_CPUS), 2;
    double *t = malloc(sizeof(double) * (2 * (size_t)n + 1) * (size_t)o.c.repeat), *bufs[MAX_CPUS];
    bool ok = t != NULL;
    for (int c = 0; c < n; c++) {
        bufs[c] = ok ? malloc((size_t)STREAM_MIB << 20) : NULL;
        ok = ok && bufs[c];
    }
    Error err = {0};
    if (!ok) error_set(&err, "out of memory (%d x %d MiB)", n, STREAM_MIB);
    bench_spin_s(SPIN_ITERS); /* warm-up: the clock ramps, the threads start */
    for (int loop = 0; ok && loop < NUM_LOOPS; loop++) ok = measure_loop(&o, loop, bufs, t, &err);
    if (!ok) fprintf(stderr, "cpu_speed: %s\n", err.msg);
    for (int c = 0; c < n; c++) free(bufs[c]);
    free(t);
    return ok ? 0 : 1;
}
