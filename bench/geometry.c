/* geometry.c -- the geometry family's costs (issue 14's bench items).
 *   --silhouette: the silhouette resource (edge adjacency and possible
 *     silhouette edges for light 1's centre, src/resources/geometry/silhouette.c)
 *     built from scratch on sphere-on-plane's ball at 16 ... 1024 segments
 *     (about segments^2 triangles: 256 ... 1M): nanoseconds per triangle at
 *     each size, and the largest size's over the smallest (linear in
 *     triangles: a flat line, the ratio near 1).
 *   --volumes: `shadow_volume` (its defaults: z-fail, infinite extrusion)
 *     against `sm` at map_size 2048 and 4096 and against `hard`, frame time
 *     (the counts built every frame plus the evaluation; sm: its map), each
 *     pair alternating in every round (bench_paired), on the given scenes.
 *   --vsm: `view_sample_mapping` at 256 light samples (its default) against
 *     the Embree reference at 256 samples on the same view (r2, seed 1,
 *     computed, not cached: reference_compute), frame time (its mapping is
 *     its prepare) against the reference's time, alternating per round, on
 *     sphere-on-plane and the bunny (320 x 240; --quick 160 x 120); and its
 *     frame time per influence pair (work.influence: the (caster triangle,
 *     view sample) pairs map_triangle maps, the sum of the triangles'
 *     influence regions) against the ball's triangles on sphere-on-plane
 *     (segments 16 ... 128: 290 ... 16,642 triangles), then on the bunny;
 *     each row's ns per pair over the first's (near 1: the cost is linear in
 *     the sum of the influence regions), the pairs' share of triangles x
 *     lit candidates (the bound the regions are a subset of), and the ns
 *     per pair added since the first row (the slope).
 * Rows: DIR/silhouette.csv, DIR/volumes.csv, DIR/vsm_reference.csv, DIR/vsm_triangles.csv.
 * Usage: geometry [--silhouette] [--volumes] [--vsm] [--quick] [--threads N] [--repeat R] [-o DIR] [SCENE...] */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "resources/geometry/silhouette.h"
#include "rt/rt.h"

#define SIL_HEADER "segments,triangles,silhouette_edges,build_ms,ns_per_triangle,ns_per_triangle_over_smallest," \
                   BENCH_TAIL_HEADER "\n"
#define VOL_HEADER "scene,triangles,versus,map_size,shadow_volume_ms,other_ms,ratio," BENCH_TAIL_HEADER "\n"
#define VSM_REF_HEADER "scene,triangles,width,height,samples,vsm_ms,reference_ms,ratio," BENCH_TAIL_HEADER "\n"
#define VSM_TRI_HEADER "scene,segments,triangles,lit_candidates,influence_pairs,pairs_over_triangles_samples," \
                       "frame_ms,ns_per_pair,ns_per_pair_over_smallest,ns_per_added_pair," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    bool silhouette, volumes, vsm, quick;
} Options;

static int own_option(void *options, const char *arg, const char *value)
{
    Options *o = options;
    (void)value;
    if (strcmp(arg, "--silhouette") == 0) return o->silhouette = true, 1;
    if (strcmp(arg, "--volumes") == 0) return o->volumes = true, 1;
    if (strcmp(arg, "--vsm") == 0) return o->vsm = true, 1;
    if (strcmp(arg, "--quick") == 0) return o->quick = true, 1;
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

/* ---- view sample mapping against the reference ----------------------------- */

typedef struct VsmRun {
    Lab *lab;
    const Technique *t;
    double params[TECH_MAX_PARAMS];
    int samples;
} VsmRun;

/* The Embree reference's own rays for light 1 at `samples` (what
 * view_sample_mapping's light samples are, bit for bit), computed. */
static bool reference_s(Lab *lab, int samples, double *s, Error *err)
{
    ResourceManager *rm = lab_resources(lab);
    const Scene *sc = lab_scene(lab);
    const RtScene *bvh = res_bvh(rm, sc, RT_CASTERS, err);
    const ViewSamples *vs = bvh ? res_view_samples(rm, sc, err) : NULL;
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, err) : NULL;
    ReferenceParams prm = {MEASURE_VISIBILITY, samples, SAMPLING_R2, 1, false};
    Reference ref;
    double t0 = timer_now_s();
    bool ok = cls && reference_compute(bvh, sc, 0, vs, cls, &prm, &ref, err);
    *s = timer_now_s() - t0;
    if (ok) reference_free(&ref);
    return ok;
}

static bool vsm_round(void *run, double *a_s, double *b_s, Error *err)
{
    VsmRun *v = run;
    return frame_s(v->lab, v->t, v->params, a_s, err) && reference_s(v->lab, v->samples, b_s, err);
}

static const char *const *view_size(const Options *o)
{
    static const char *const full[] = {"camera.width=320", "camera.height=240"};
    static const char *const quick[] = {"camera.width=160", "camera.height=120"};
    return o->quick ? quick : full;
}

static bool vsm_versus_reference(const BenchCommon *c, const Options *o, const char *scene, const char *path,
                                 Error *err)
{
    VsmRun v = {.samples = 256};
    if (!(v.t = tech_find("view_sample_mapping", err))) return false;
    tech_params_default(v.t, v.params);
    char setting[64];
    snprintf(setting, sizeof setting, "samples=%d", v.samples);
    if (!tech_param_parse(v.t, setting, v.params, err) || !(v.lab = lab_open(scene, view_size(o), 2, err)))
        return false;
    double med[3];
    bool ok = bench_paired(vsm_round, &v, c->repeat, med, err);
    const Scene *sc = lab_scene(v.lab);
    if (ok) {
        char name[300], row[1024], tail[512];
        bench_csv_field(name, sizeof name, scene);
        bench_tail(tail, sizeof tail, c->threads);
        snprintf(row, sizeof row, "%s,%ld,%d,%d,%d,%.3f,%.3f,%.3f,%s\n", name, scene_triangles(sc), sc->camera.width,
                 sc->camera.height, v.samples, med[0] * 1e3, med[1] * 1e3, med[2], tail);
        printf("vsm: %s %dx%d: view_sample_mapping %.3f ms, reference (%d samples) %.3f ms: ratio %.3f\n", scene,
               sc->camera.width, sc->camera.height, med[0] * 1e3, v.samples, med[1] * 1e3, med[2]);
        ok = bench_csv_append(path, VSM_REF_HEADER, row, err);
    }
    lab_close(v.lab);
    return ok;
}

/* One view_sample_mapping frame size: the median frame time over the rounds
 * and one frame's influence pairs (work.influence, counted in map_triangle:
 * the sum of the caster triangles' influence regions in view samples). */
typedef struct VsmFrame {
    long triangles, lit;
    uint64_t pairs;
    double frame_s;
} VsmFrame;

static bool vsm_frame(const BenchCommon *c, const char *scene, const char *const *overrides, int num_overrides,
                      VsmFrame *out, Error *err)
{
    const Technique *t = tech_find("view_sample_mapping", err);
    Lab *lab = t ? lab_open(scene, overrides, num_overrides, err) : NULL;
    if (!lab) return false;
    double params[TECH_MAX_PARAMS], times[64];
    tech_params_default(t, params);
    RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    int rounds = c->repeat > 64 ? 64 : c->repeat;
    bool ok = true;
    for (int r = 0; ok && r < rounds; r++) {
        RenderResult res;
        ok = lab_render(lab, &req, &res, err);
        if (!ok) break;
        times[r] = res.frame_s;
        out->lit = res.lit_candidates;
        out->pairs = res.frame_work.influence; /* the mapping is the prepare: the frame's work */
        render_result_free(&res);
    }
    out->triangles = ok ? scene_triangles(lab_scene(lab)) : 0;
    lab_close(lab);
    if (ok) out->frame_s = bench_median(times, rounds);
    return ok;
}

/* One row of vsm_triangles.csv: ns per influence pair, its ratio to the
 * first row's (`first`, set by that row), the pairs' share of the triangles
 * x lit candidates bound, and the ns per pair added since the first row
 * ((frame - first frame) / (pairs - first pairs): the slope, free of the
 * per-view-sample cost of drawing and binning its light samples). */
static bool vsm_influence_row(const BenchCommon *c, const char *scene, int segments, const VsmFrame *f,
                              VsmFrame *first, double *smallest, const char *path, Error *err)
{
    double bound = (double)f->triangles * (double)f->lit;
    double ns = f->pairs > 0 ? f->frame_s * 1e9 / (double)f->pairs : NAN; /* NaN: no pair mapped */
    double share = bound > 0.0 ? (double)f->pairs / bound : NAN;          /* NaN: nothing lit */
    if (*smallest == 0.0) { /* the first row */
        *smallest = ns;
        *first = *f;
    }
    double added = (double)f->pairs - (double)first->pairs; /* 0 on the first row: NaN */
    double ns_added = added != 0.0 ? (f->frame_s - first->frame_s) * 1e9 / added : NAN;
    char name[300], row[1024], tail[512];
    bench_csv_field(name, sizeof name, scene);
    bench_tail(tail, sizeof tail, c->threads);
    snprintf(row, sizeof row, "%s,%d,%ld,%ld,%llu,%.5f,%.3f,%.3f,%.3f,%.3f,%s\n", name, segments, f->triangles,
             f->lit, (unsigned long long)f->pairs, share, f->frame_s * 1e3, ns, ns / *smallest, ns_added, tail);
    printf("vsm: %s %4d segments, %7ld triangles, %6ld lit samples: %11llu influence pairs (%.5f of triangles x "
           "samples), frame %9.3f ms, %.3f ns per pair (x%.3f the smallest), %.3f ns per added pair\n", scene,
           segments, f->triangles, f->lit, (unsigned long long)f->pairs, share, f->frame_s * 1e3, ns, ns / *smallest,
           ns_added);
    return bench_csv_append(path, VSM_TRI_HEADER, row, err);
}

/* Frame time per influence pair against the ball's triangles on
 * sphere-on-plane, then on the bunny (segments 0: its mesh as loaded). */
static bool vsm_triangles(const BenchCommon *c, const Options *o, Error *err)
{
    static const int segments[] = {16, 32, 64, 128};
    char path[4096];
    snprintf(path, sizeof path, "%s/vsm_triangles.csv", c->dir);
    if (!bench_csv_reset(path, VSM_TRI_HEADER, err)) return false;
    double smallest = 0.0;
    VsmFrame f, first = {0};
    for (size_t k = 0; k < sizeof segments / sizeof segments[0]; k++) {
        char seg[64];
        snprintf(seg, sizeof seg, "objects[2].segments=%d", segments[k]);
        const char *ov[] = {seg, view_size(o)[0], view_size(o)[1]};
        if (!vsm_frame(c, "scenes/sphere-on-plane.lua", ov, 3, &f, err) ||
            !vsm_influence_row(c, "scenes/sphere-on-plane.lua", segments[k], &f, &first, &smallest, path, err))
            return false;
    }
    return vsm_frame(c, "scenes/bunny.lua", view_size(o), 2, &f, err) &&
           vsm_influence_row(c, "scenes/bunny.lua", 0, &f, &first, &smallest, path, err);
}

static bool bench_vsm(const BenchCommon *c, const Options *o, Error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/vsm_reference.csv", c->dir);
    if (!bench_csv_reset(path, VSM_REF_HEADER, err)) return false;
    static const char *const scenes[] = {"scenes/sphere-on-plane.lua", "scenes/bunny.lua"};
    for (int i = 0; i < 2; i++)
        if (!vsm_versus_reference(c, o, scenes[i], path, err)) return false;
    return vsm_triangles(c, o, err);
}

int main(int argc, char **argv)
{
    BenchCommon c;
    Options o = {0};
    if (!bench_parse(argc, argv, 5, &c, own_option, &o))
        return bench_usage("geometry [--silhouette] [--volumes] [--vsm] [--quick] [--threads N] [--repeat R] [-o DIR] "
                           "[SCENE...]");
    if (!o.silhouette && !o.volumes && !o.vsm) o.silhouette = o.volumes = o.vsm = true;
    omp_set_num_threads(c.threads);
    rt_set_threads(c.threads);
    Error err;
    if (o.silhouette && !bench_silhouette(&c, &err)) return bench_fail("geometry", &err);
    if (o.volumes && !bench_volumes(&c, &err)) return bench_fail("geometry", &err);
    if (o.vsm && !bench_vsm(&c, &o, &err)) return bench_fail("geometry", &err);
    return 0;
}
