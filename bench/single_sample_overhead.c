/* single_sample_overhead.c -- seed 002 §4: "The ray tracer was approximately
 * 20% slower after the change". Times `hard` and `single_sample_rt` (default
 * parameters: min, polynomial, analytic spheres) on the same view samples,
 * light and threads, and the primary rays that find those samples (one
 * Embree ray per pixel): one untimed warm-up each (it builds the resources),
 * then rounds alternating primary rays, hard and single_sample_rt. Reported:
 * the median per-round ratio of the shadow queries, single_sample_rt / hard,
 * and of a whole ray tracer without shading, (primary + single_sample_rt) /
 * (primary + hard), the paper's measure. One row per scene and light radius
 * in DIR/single_sample_overhead.csv, started afresh, ending in bench_tail's
 * columns like every bench CSV.
 * Usage: single_sample_overhead [--radius R]... [--threads N] [--repeat R] [-o DIR] SCENE... */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"

#define MAX_ITEMS 16
#define CSV_HEADER                                                                                                 \
    "scene,triangles,light,radius,rounds,primary_s,hard_s,single_sample_s,shadow_ratio,ray_tracer_ratio,"          \
    "outer_build_s,outer_bytes," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    double radii[MAX_ITEMS]; /* lights[1].radius overrides; none: the scene's own */
    int num_radii;
    char csv[4096];
} Options;

typedef struct Row {
    const Scene *scene;
    double primary_s, hard_s, ss_s; /* medians over rounds */
    double shadow_ratio, tracer_ratio;
    double outer_build_s;
    size_t outer_bytes;
} Row;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    char *end;
    double r = v ? strtod(v, &end) : 0.0;
    if (strcmp(a, "--radius") != 0 || !v || end == v || *end != '\0' || !(r >= 1e-9 && r <= 1e6) ||
        o->num_radii == MAX_ITEMS)
        return 0;
    o->radii[o->num_radii++] = r;
    return 2;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.num_radii = 0};
    if (!bench_parse(argc, argv, 9, &o->c, own_option, o)) return false;
    if (o->c.num_scenes == 0) o->c.scenes[o->c.num_scenes++] = "scenes/sphere-on-plane.lua";
    snprintf(o->csv, sizeof o->csv, "%s/single_sample_overhead.csv", o->c.dir);
    return true;
}

/* One evaluation of a technique with its default parameters (seconds). */
static bool time_once(Lab *lab, const char *name, double *seconds, Error *err)
{
    const Technique *t = tech_find(name, err);
    if (!t) return false;
    double params[TECH_MAX_PARAMS];
    tech_params_default(t, params);
    RenderRequest rq = {t, params, 0, 1};
    RenderResult rr;
    if (!lab_render(lab, &rq, &rr, err)) return false;
    *seconds = rr.eval_median_s;
    render_result_free(&rr);
    return true;
}

/* The warm-up render of single_sample_rt built the outer objects: find them in the log. */
static void outer_build(Lab *lab, Row *row)
{
    ResourceManager *rm = lab_resources(lab);
    for (int i = 0; i < rm_log_count(rm); i++) {
        const ResourceEvent *ev = rm_log_event(rm, i);
        if (strcmp(ev->kind, "outer_objects") == 0) row->outer_build_s = ev->build_s, row->outer_bytes = ev->bytes;
    }
}

/* One pass of primary rays: the view samples traced afresh (seconds). */
static bool time_primary(Lab *lab, double *seconds, Error *err)
{
    const RtScene *all = res_bvh(lab_resources(lab), lab_scene(lab), RT_ALL_OBJECTS, err);
    ViewSamples vs;
    double t0 = timer_now_s();
    if (!all || !view_samples_trace(all, lab_scene(lab), &vs, err)) return false;
    *seconds = timer_now_s() - t0;
    view_samples_free(&vs);
    return true;
}

/* Rounds of primary, hard, single_sample_rt; medians of times and ratios. */
static bool measure(Lab *lab, const Options *o, Row *row, Error *err)
{
    int n = o->c.repeat;
    double warm, *t = malloc(sizeof(double) * 5 * (size_t)n);
    if (!t) return error_set(err, "out of memory");
    double *primary = t, *hard = t + n, *ss = t + 2 * n, *shadow = t + 3 * n, *tracer = t + 4 * n;
    rm_log_reset(lab_resources(lab));
    bool ok = time_once(lab, "hard", &warm, err) && time_once(lab, "single_sample_rt", &warm, err);
    outer_build(lab, row);
    for (int r = 0; ok && r < n; r++) {
        ok = time_primary(lab, &primary[r], err) && time_once(lab, "hard", &hard[r], err) &&
             time_once(lab, "single_sample_rt", &ss[r], err);
        shadow[r] = ss[r] / hard[r];
        tracer[r] = (primary[r] + ss[r]) / (primary[r] + hard[r]);
    }
    if (ok)
        *row = (Row){row->scene, timer_median(primary, n), timer_median(hard, n), timer_median(ss, n),
                     timer_median(shadow, n), timer_median(tracer, n), row->outer_build_s, row->outer_bytes};
    free(t);
    return ok;
}

static bool write_row(const Row *r, const Options *o, Error *err)
{
    char row[1024], name[160], tail[512];
    bench_csv_field(name, sizeof name, r->scene->name);
    bench_tail(tail, sizeof tail, o->c.threads);
    const Light *l = &r->scene->lights[0];
    snprintf(row, sizeof row, "%s,%d,%s,%.6g,%d,%.6g,%.6g,%.6g,%.4f,%.4f,%.6g,%zu,%s\n", name,
             r->scene->num_triangles, light_kind_name(l->kind), (double)l->radius, o->c.repeat, r->primary_s,
             r->hard_s, r->ss_s, r->shadow_ratio, r->tracer_ratio, r->outer_build_s, r->outer_bytes, tail);
    return bench_csv_append(o->csv, CSV_HEADER, row, err);
}

/* One scene at one light radius (radius < 0: as the scene has it). */
static bool bench_one(const char *path, double radius, const Options *o, Error *err)
{
    char assign[64];
    snprintf(assign, sizeof assign, "lights[1].radius=%.9g", radius);
    const char *overrides[] = {assign};
    Lab *lab = lab_open(path, overrides, radius < 0 ? 0 : 1, err);
    if (!lab) return false;
    Row row = {.scene = lab_scene(lab)};
    bool ok = measure(lab, o, &row, err);
    if (ok) {
        const Light *l = &row.scene->lights[0];
        printf("%s (%d triangles, %s light, radius %g): primary %.4f s, hard %.4f s, single_sample_rt %.4f s; "
               "shadow rays x%.3f, ray tracer x%.3f (medians of %d rounds, %d threads); outer objects %.4f s\n",
               row.scene->name, row.scene->num_triangles, light_kind_name(l->kind), (double)l->radius,
               row.primary_s, row.hard_s, row.ss_s, row.shadow_ratio, row.tracer_ratio, o->c.repeat, o->c.threads,
               row.outer_build_s);
        ok = write_row(&row, o, err);
    }
    lab_close(lab);
    return ok;
}

static bool bench_all(const Options *o, Error *err)
{
    if (!bench_csv_reset(o->csv, CSV_HEADER, err)) return false;
    for (int i = 0; i < o->c.num_scenes; i++)
        for (int k = 0; k < (o->num_radii ? o->num_radii : 1); k++)
            if (!bench_one(o->c.scenes[i], o->num_radii ? o->radii[k] : -1, o, err))
                return error_prefix(err, "%s: ", o->c.scenes[i]);
    printf("results: %s\n", o->csv);
    return true;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o))
        return bench_usage("single_sample_overhead [--radius R]... [--threads N] [--repeat R] [-o DIR] SCENE...");
    omp_set_num_threads(o.c.threads);
    rt_set_threads(o.c.threads);
    Error err;
    return bench_all(&o, &err) ? 0 : bench_fail("single_sample_overhead", &err);
}
