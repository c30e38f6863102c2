/* raster_threads.c -- the rasterizer's thread scaling (issue 8, item 5) and
 * the driver its profiles run under: raster_depth of light 1's map of each
 * scene (bench_map: perspective, z_ndc) at each --res, at 1 thread and at
 * --threads N, alternating within every round after one warm-up at each;
 * the speed-up is the median of the per-round ratios t(1) / t(N). One row
 * per scene and size in DIR/raster_threads.csv. With --profile only N
 * threads run, --repeat times, and nothing is written (for perf and
 * callgrind: `valgrind --tool=callgrind raster_threads --profile ...`).
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

/* Rounds of (1 thread, N threads); med = {t1, tN, t1/tN}. */
static bool measure(Job *j, const Options *o, double med[3], Error *err)
{
    double *t = malloc(sizeof *t * 3 * (size_t)o->c.repeat), w;
    if (!t) return error_set(err, "out of memory");
    bool ok = timed_render(j, 1, &w, err) && timed_render(j, o->c.threads, &w, err);
    for (int i = 0; ok && i < o->c.repeat; i++) {
        ok = timed_render(j, 1, &t[i], err) && timed_render(j, o->c.threads, &t[o->c.repeat + i], err);
        t[2 * o->c.repeat + i] = t[i] / t[o->c.repeat + i];
    }
    for (int k = 0; ok && k < 3; k++) med[k] = bench_median(t + k * o->c.repeat, o->c.repeat);
    free(t);
    return ok;
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

static bool write_row(const Options *o, const Scene *sc, const Job *j, const double med[3], Error *err)
{
    char row[1024], tail[512], name[160], path[4096];
    bench_tail(tail, sizeof tail, o->c.threads);
    bench_csv_field(name, sizeof name, sc->name);
    snprintf(row, sizeof row, "%s,%ld,%d,%.3f,%.3f,%.3f,%ld,%s\n", name, j->triangles, j->db.width, med[0] * 1e3,
             med[1] * 1e3, med[2], j->stats.texels_written, tail);
    printf("  %5d^2: 1 thread %8.2f ms, %d threads %8.2f ms, speed-up %.2f\n", j->db.width, med[0] * 1e3, o->c.threads,
           med[1] * 1e3, med[2]);
    snprintf(path, sizeof path, "%s/raster_threads.csv", o->c.dir);
    return bench_csv_append(path, HEADER, row, err);
}

static bool bench_size(Lab *lab, Job *j, const Options *o, int res, Error *err)
{
    const ShadowMap *map = bench_map(lab, res, err);
    if (!map || !depth_buffer_init(&j->db, res, res, false, err)) return false;
    j->view = &map->view.face[0].raster;
    j->opt = (RasterOptions){.depth = RASTER_DEPTH_NDC};
    double med[3];
    bool ok = o->profile ? profile(j, o, err) : measure(j, o, med, err) && write_row(o, lab_scene(lab), j, med, err);
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
