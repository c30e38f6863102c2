/* raster_threads.c -- the rasterizer's thread scaling (issue 8, item 5) and
 * the driver its profiles run under: raster_depth of light 1's map of each
 * scene (bench_map: perspective, z_ndc) at each --res, on the curve 1, 2,
 * 4, ... N threads (N = --threads; bench.h's BenchCurve: every count in
 * every round after one warm-up at each); a point's speed-up is the median
 * of the per-round ratios t(1) / t(k). One row per scene, size and thread
 * count in DIR/raster_threads.csv. With --profile only N threads run,
 * --repeat times, and nothing is written (for perf and callgrind:
 * `valgrind --tool=callgrind raster_threads --profile ...`).
 * Usage: raster_threads [--res R]... [--threads N] [--repeat R] [--profile]
 *                       [-o DIR] SCENE... */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"

#define MAX_ITEMS 8
#define MAX_MESHES 64
#define HEADER "scene,triangles,res,ms_1,ms_n,speedup,texels_written," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    int res[MAX_ITEMS], num_res;
    bool profile;
} Options;

typedef struct Job {
    RasterMesh mesh[MAX_MESHES];
    int num_meshes;
    long triangles;
    const RasterView *view;
    RasterOptions opt;
    DepthBuffer db;
    RasterStats stats;
} Job;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    if (strcmp(a, "--profile") == 0) return o->profile = true;
    bool ok = strcmp(a, "--res") == 0 && o->num_res < MAX_ITEMS && bench_parse_int(v, 16, 16384, &o->res[o->num_res++]);
    return ok ? 2 : 0;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.profile = false};
    return bench_parse(argc, argv, 7, &o->c, own_option, o) && o->c.num_scenes > 0 && o->num_res > 0;
}

static bool timed_render(Job *j, int threads, double *seconds, Error *err)
{
    omp_set_num_threads(threads);
    double t0 = timer_now_s();
    bool ok = raster_depth(j->mesh, j->num_meshes, j->view, &j->opt, &j->db, &j->stats, err);
    *seconds = timer_now_s() - t0;
    return ok;
}

/* BenchTimedFn: one render at the curve's thread count. */
static bool curve_render(void *job, int side, int threads, double *seconds, Error *err)
{
    (void)side;
    return timed_render(job, threads, seconds, err);
}

static bool profile(Job *j, const Options *o, Error *err)
{
    double s = 0.0;
    for (int i = 0; i < o->c.repeat; i++)
        if (!timed_render(j, o->c.threads, &s, err)) return false;
    printf("  %d^2, %d threads: last render %.2f ms, %ld texels written\n", j->db.width, o->c.threads, s * 1e3,
           j->stats.texels_written);
    return true;
}

/* One row per point of the curve (threads = that point's count). */
static bool write_rows(const Options *o, const Scene *sc, const Job *j, const BenchCurve *c, Error *err)
{
    char path[4096], name[160];
    snprintf(path, sizeof path, "%s/raster_threads.csv", o->c.dir);
    bench_csv_field(name, sizeof name, sc->name);
    double ms1 = bench_curve_median_s(c, 0, 0) * 1e3;
    printf("  %5d^2: 1 thread %8.2f ms", j->db.width, ms1);
    bool ok = true;
    for (int k = 0; ok && k < c->points; k++) {
        char row[1024], tail[512];
        double msk = bench_curve_median_s(c, 0, k) * 1e3, speedup = bench_curve_speedup(c, 0, k);
        bench_tail(tail, sizeof tail, c->threads[k]);
        snprintf(row, sizeof row, "%s,%ld,%d,%.3f,%.3f,%.3f,%ld,%s\n", name, j->triangles, j->db.width, ms1, msk,
                 speedup, j->stats.texels_written, tail);
        if (k > 0) printf("; %d: %.2f ms, speed-up %.2f", c->threads[k], msk, speedup);
        ok = bench_csv_append(path, HEADER, row, err);
    }
    printf("\n");
    return ok;
}

static bool curve(Lab *lab, Job *j, const Options *o, Error *err)
{
    BenchCurve c;
    bool ok = bench_curve_init(&c, o->c.threads, 1, o->c.repeat, err) &&
              bench_curve_measure(&c, curve_render, j, err) && write_rows(o, lab_scene(lab), j, &c, err);
    bench_curve_free(&c);
    return ok;
}

static bool bench_size(Lab *lab, Job *j, const Options *o, int res, Error *err)
{
    const ShadowMap *map = bench_map(lab, res, err);
    if (!map || !depth_buffer_init(&j->db, res, res, false, err)) return false;
    j->view = &map->view.face[0].raster;
    j->opt = (RasterOptions){.depth = RASTER_DEPTH_NDC};
    bool ok = o->profile ? profile(j, o, err) : curve(lab, j, o, err);
    depth_buffer_free(&j->db);
    return ok;
}

static bool bench_scene(const char *path, const Options *o, Error *err)
{
    Lab *lab = lab_open(path, NULL, 0, err);
    if (!lab) return false;
    Job j = {0};
    j.num_meshes = bench_casters(lab_scene(lab), j.mesh, MAX_MESHES, &j.triangles);
    bool ok = j.num_meshes >= 0 || error_set(err, "more than %d caster objects", MAX_MESHES);
    if (ok) printf("%s: %ld caster triangles\n", lab_scene(lab)->name, j.triangles);
    for (int i = 0; ok && i < o->num_res; i++) ok = bench_size(lab, &j, o, o->res[i], err);
    lab_close(lab);
    return ok;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o))
        return bench_usage("raster_threads [--res R]... [--threads N] [--repeat R] [--profile] [-o DIR] SCENE...");
    Error err;
    for (int i = 0; i < o.c.num_scenes; i++)
        if (!bench_scene(o.c.scenes[i], &o, &err)) return bench_fail("raster_threads", &err);
    return 0;
}
