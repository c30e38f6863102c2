/* geometry.c -- the geometry family's costs (issue 14's bench items).
 *   --silhouette: the silhouette resource (edge adjacency and possible
 *     silhouette edges for light 1's centre, src/resources/silhouette.c)
 *     built from scratch on sphere-on-plane's ball at 16 ... 1024 segments
 *     (about segments^2 triangles: 256 ... 1M): nanoseconds per triangle at
 *     each size, and the largest size's over the smallest (linear in
 *     triangles: a flat line, the ratio near 1).
 *   --volumes: `shadow_volume` (its defaults: z-fail, infinite extrusion)
 *     against `sm` at map_size 2048 and 4096 and against `hard`, frame time
 *     (the counts built every frame plus the evaluation; sm: its map), each
 *     pair alternating in every round (bench_paired), on the given scenes.
 * Rows: DIR/silhouette.csv, DIR/volumes.csv.
 * Usage: geometry [--silhouette] [--volumes] [--threads N] [--repeat R] [-o DIR] [SCENE...] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "resources/silhouette.h"
#include "rt/rt.h"

#define SIL_HEADER "segments,triangles,silhouette_edges,build_ms,ns_per_triangle,ns_per_triangle_over_smallest," \
                   BENCH_TAIL_HEADER "\n"
#define VOL_HEADER "scene,triangles,versus,map_size,shadow_volume_ms,other_ms,ratio," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    bool silhouette, volumes;
} Options;

static int own_option(void *options, const char *arg, const char *value)
{
    Options *o = options;
    (void)value;
    if (strcmp(arg, "--silhouette") == 0) return o->silhouette = true, 1;
    if (strcmp(arg, "--volumes") == 0) return o->volumes = true, 1;
    return 0;
}

static long scene_triangles(const Scene *sc)
{
    long n = 0;
    for (int i = 0; i < sc->num_objects; i++) n += sc->objects[i].mesh.num_triangles;
    return n;
}

/* ---- silhouette extraction against triangles -------------------------------- */

/* Median seconds of `repeat` builds, each in a fresh manager (nothing reused). */
static bool silhouette_build_s(const Scene *sc, int repeat, double *median_s, int *edges, Error *err)
{
    double t[64];
    repeat = repeat > 64 ? 64 : repeat;
    for (int r = 0; r < repeat; r++) {
        ResourceManager *rm = rm_create();
        if (!rm) return error_set(err, "out of memory");
        double t0 = timer_now_s();
        const Silhouette *s = res_silhouette(rm, sc, 0, err);
        t[r] = timer_now_s() - t0;
        if (s) *edges = s->num_edges;
        rm_destroy(rm);
        if (!s) return false;
    }
    *median_s = timer_median(t, repeat);
    return true;
}

static bool bench_silhouette(const BenchCommon *c, Error *err)
{
    static const int segments[] = {16, 32, 64, 128, 256, 512, 1024};
    char path[4096];
    snprintf(path, sizeof path, "%s/silhouette.csv", c->dir);
    if (!bench_csv_reset(path, SIL_HEADER, err)) return false;
    double smallest_ns = 0.0;
    for (size_t k = 0; k < sizeof segments / sizeof segments[0]; k++) {
        char seg[64];
        snprintf(seg, sizeof seg, "objects[2].segments=%d", segments[k]);
        const char *ov[] = {seg, "camera.width=8", "camera.height=6"};
        Lab *lab = lab_open("scenes/sphere-on-plane.lua", ov, 3, err);
        if (!lab) return false;
        const Scene *sc = lab_scene(lab);
        long tris = scene_triangles(sc);
        double s = 0.0;
        int edges = 0;
        bool ok = silhouette_build_s(sc, c->repeat, &s, &edges, err);
        lab_close(lab);
        if (!ok) return false;
        double ns = tris > 0 ? s * 1e9 / (double)tris : 0.0 / 0.0; /* NaN for an empty scene: shown, not hidden */
        if (k == 0) smallest_ns = ns;
        char row[512], tail[512];
        bench_tail(tail, sizeof tail, c->threads);
        snprintf(row, sizeof row, "%d,%ld,%d,%.3f,%.2f,%.3f,%s\n", segments[k], tris, edges, s * 1e3, ns,
                 ns / smallest_ns, tail);
        printf("silhouette: %4d segments, %8ld triangles, %6d edges: %8.3f ms, %.2f ns/triangle (x%.2f the smallest)\n",
               segments[k], tris, edges, s * 1e3, ns, ns / smallest_ns);
        if (!bench_csv_append(path, SIL_HEADER, row, err)) return false;
    }
    return true;
}

/* ---- shadow volumes against shadow maps and rays ---------------------------- */

typedef struct Pair {
    Lab *lab;
    const Technique *a, *b;
    double pa[TECH_MAX_PARAMS], pb[TECH_MAX_PARAMS];
} Pair;

static bool frame_s(Lab *lab, const Technique *t, const double *params, double *s, Error *err)
{
    RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    RenderResult r;
    if (!lab_render(lab, &req, &r, err)) return false;
    *s = r.frame_s;
    render_result_free(&r);
    return true;
}

static bool pair_round(void *run, double *a_s, double *b_s, Error *err)
{
    Pair *p = run;
    return frame_s(p->lab, p->a, p->pa, a_s, err) && frame_s(p->lab, p->b, p->pb, b_s, err);
}

static bool versus(const BenchCommon *c, const char *scene, Lab *lab, const char *other, int map_size,
                   const char *path, Error *err)
{
    Pair p = {.lab = lab};
    if (!(p.a = tech_find("shadow_volume", err)) || !(p.b = tech_find(other, err))) return false;
    tech_params_default(p.a, p.pa);
    tech_params_default(p.b, p.pb);
    char setting[64];
    snprintf(setting, sizeof setting, "map_size=%d", map_size);
    if (map_size > 0 && !tech_param_parse(p.b, setting, p.pb, err)) return false;
    double med[3];
    if (!bench_paired(pair_round, &p, c->repeat, med, err)) return false;
    char name[300], row[1024], tail[512];
    bench_csv_field(name, sizeof name, scene);
    bench_tail(tail, sizeof tail, c->threads);
    snprintf(row, sizeof row, "%s,%ld,%s,%d,%.3f,%.3f,%.3f,%s\n", name, scene_triangles(lab_scene(lab)), other,
             map_size, med[0] * 1e3, med[1] * 1e3, med[2], tail);
    printf("volumes: %s: shadow_volume %.3f ms, %s %s %.3f ms: ratio %.3f\n", scene, med[0] * 1e3, other,
           map_size > 0 ? setting : "", med[1] * 1e3, med[2]);
    return bench_csv_append(path, VOL_HEADER, row, err);
}

static bool bench_volumes(const BenchCommon *c, Error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/volumes.csv", c->dir);
    if (!bench_csv_reset(path, VOL_HEADER, err)) return false;
    static const char *const fallback[] = {"scenes/bunny.lua", "scenes/terrain.lua"};
    int n = c->num_scenes ? c->num_scenes : 2;
    for (int i = 0; i < n; i++) {
        const char *scene = c->num_scenes ? c->scenes[i] : fallback[i];
        Lab *lab = lab_open(scene, NULL, 0, err);
        if (!lab) return false;
        bool ok = versus(c, scene, lab, "sm", 2048, path, err) && versus(c, scene, lab, "sm", 4096, path, err) &&
                  versus(c, scene, lab, "hard", 0, path, err);
        lab_close(lab);
        if (!ok) return false;
    }
    return true;
}

int main(int argc, char **argv)
{
    BenchCommon c;
    Options o = {0};
    if (!bench_parse(argc, argv, 5, &c, own_option, &o))
        return bench_usage("geometry [--silhouette] [--volumes] [--threads N] [--repeat R] [-o DIR] [SCENE...]");
    if (!o.silhouette && !o.volumes) o.silhouette = o.volumes = true;
    omp_set_num_threads(c.threads);
    rt_set_threads(c.threads);
    Error err;
    if (o.silhouette && !bench_silhouette(&c, &err)) return bench_fail("geometry", &err);
    if (o.volumes && !bench_volumes(&c, &err)) return bench_fail("geometry", &err);
    return 0;
}
