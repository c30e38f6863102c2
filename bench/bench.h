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
#include "resources/shadowmap.h"

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

/* The scene's casters as the rasterizer reads them (at most `max` meshes);
 * returns the mesh count, or -1 when there are more. */
int bench_casters(const Scene *scene, RasterMesh *out, int max, long *triangles);
/* The depth map the rasterizer benches draw: light 1's perspective map at
 * `res`, z_ndc, fitted to the scene (one face, whatever the light). */
const ShadowMap *bench_map(Lab *lab, int res, Error *err);

#endif
