/* bench.h -- what every bench program shares: its CSV rows end with the same
 * columns (threads, commit, CPU model, 1-minute load average, date), are
 * added to reports/bench/NAME.csv atomically (a file with another header is
 * started afresh), and its timings are medians over rounds. The machines are
 * shared and noisy, so programs report ratios measured within one run. */
#ifndef SL_BENCH_H
#define SL_BENCH_H
#include <stdbool.h>
#include <stddef.h>
#include "core/error.h"
#include "lab/lab.h"
#include "raster/raster.h"
#include "resources/maps/shadowmap.h"

/* The columns bench_tail fills, at the end of every header. */
#define BENCH_TAIL_HEADER "threads,commit,cpu_model,load_1min,date"

/* "THREADS,COMMIT,CPU,LOAD,DATE" for a row (CSV-quoted where needed). */
void bench_tail(char *out, size_t n, int threads);
/* The 1-minute load average from /proc/loadavg, or -1. */
double bench_load1(void);
/* Append one row (ending in '\n') under `header`: the file's earlier rows
 * are kept when it starts with the same header. */
bool bench_csv_append(const char *path, const char *header, const char *row, Error *err);
/* Start the file afresh with only the header. */
bool bench_csv_reset(const char *path, const char *header, Error *err);
/* Copy s into out as one CSV field, quoted when it holds , " or newline. */
void bench_csv_field(char *out, size_t n, const char *s);
/* An integer argument in [lo, hi]; false when missing or malformed. */
bool bench_parse_int(const char *s, int lo, int hi, int *out);
/* The options most bench programs take: scene paths, --threads N,
 * --repeat R and -o DIR (the folder of the CSVs). */
#define BENCH_MAX_SCENES 8
typedef struct BenchCommon {
    const char *scenes[BENCH_MAX_SCENES];
    int num_scenes, threads, repeat;
    const char *dir;
} BenchCommon;
/* A program's own option `arg` with the argument after it (`value`, NULL
 * at the end): returns how many of the two it took (1 or 2), 0 when it is
 * unknown or malformed. */
typedef int (*BenchOptionFn)(void *options, const char *arg, const char *value);
/* Parse argv: the common options into *c (defaults: every core, `repeat`
 * rounds, reports/bench), the rest through `own`; false on a bad argument. */
bool bench_parse(int argc, char **argv, int repeat, BenchCommon *c, BenchOptionFn own, void *options);
/* Print "usage: TEXT" and return the usage exit status, 2. */
int bench_usage(const char *text);
/* Print "PROGRAM: error" and return the runtime-error exit status, 1. */
int bench_fail(const char *program, const Error *err);

/* Median of n values (n >= 1; sorts a copy). */
double bench_median(const double *v, int n);

/* The machine's own speed, a loop of four independent multiply-add chains
 * in registers (no memory; about 1.7 ns an iteration on this AMD EPYC):
 * seconds for `iters` iterations on the calling thread. */
double bench_spin_s(long iters);
/* The same work, `iters` iterations in all, split evenly over the current
 * OpenMP threads: its speed-up from 1 to N threads is what the machine
 * gives N busy threads at that moment (cpu_speed.c, and the control side
 * of techniques' curves). Seconds of wall time. */
double bench_spin_parallel_s(long iters);

/* One round of a two-sided comparison: the seconds of side a and side b. */
typedef bool (*BenchPairFn)(void *run, double *a_s, double *b_s, Error *err);
/* An untimed warm-up round, then `repeat` rounds; med = {median of a,
 * median of b, median of the per-round ratios a / b}. */
bool bench_paired(BenchPairFn round, void *run, int repeat, double med[3], Error *err);

/* The scene's casters as the rasterizer reads them (at most `max` meshes);
 * returns the mesh count, or -1 when there are more. */
int bench_casters(const Scene *scene, RasterMesh *out, int max, long *triangles);
/* The depth map the rasterizer benches draw: light 1's perspective map at
 * `res`, z_ndc, fitted to the scene (one face, whatever the light). */
const ShadowMap *bench_map(Lab *lab, int res, Error *err);

/* The light a technique was measured under (bench_lab_open), for its rows. */
typedef struct BenchLight {
    char text[160];   /* "sphere", or "rect 0.8 x 0.8 in place of sphere r=0.4" */
    bool substituted;
} BenchLight;
#define BENCH_MAX_OVERRIDES 8
/* Open `scene` with `overrides` (at most BENCH_MAX_OVERRIDES - 1) for
 * technique t. Where t does not handle light 1's kind (Technique.lights,
 * tech_check_light), light 1 is replaced by one of the first kind t handles
 * among rect, sphere, disk, point: same centre (a directional light's: one
 * scene extent back along its direction), as wide (a square of side 2r, a
 * sphere or disk of radius r, where r is the scene light's radius, half the
 * side of a square of its rectangle's area, or 1% of the scene's extent for a
 * delta light), facing the scene's centre, same colour and intensity. *used
 * says which. Fails, naming the kinds, where t handles none of those. */
Lab *bench_lab_open(const char *scene, const Technique *t, const char *const *overrides, int n, BenchLight *used,
                    Error *err);

/* A thread-scaling curve (issue 8, item 5): 1, 2, 4, ... below N, then N,
 * each of `sides` things timed at every count in every round, after one
 * untimed run of each at each count. Speed-ups are medians of per-round
 * ratios t(1) / t(k), so a round the shared machine slowed cancels. */
#define BENCH_MAX_CURVE 12
typedef struct BenchCurve {
    int threads[BENCH_MAX_CURVE], points, sides, rounds;
    double *s; /* seconds, s[(side * points + k) * rounds + round] */
} BenchCurve;
/* One timed run of `side` at `threads` (OpenMP already set to it). */
typedef bool (*BenchTimedFn)(void *ctx, int side, int threads, double *seconds, Error *err);
bool bench_curve_init(BenchCurve *c, int max_threads, int sides, int rounds, Error *err);
/* Every round, then OpenMP back at the curve's largest count. */
bool bench_curve_measure(BenchCurve *c, BenchTimedFn fn, void *ctx, Error *err);
/* Median seconds of `side` at point k. */
double bench_curve_median_s(const BenchCurve *c, int side, int k);
/* Median over rounds of the per-round speed-up t(1) / t(k) of `side`. */
double bench_curve_speedup(const BenchCurve *c, int side, int k);
/* Median over rounds of side a's per-round speed-up at point k divided by
 * side b's (b < 0: by 1), e.g. a program's scaling against a bare loop's. */
double bench_curve_relative(const BenchCurve *c, int a, int b, int k);
void bench_curve_free(BenchCurve *c);

#endif
