/* single_sample_overhead.c -- seed 002 §4: "The ray tracer was approximately
 * 20% slower after the change". Times `hard` and `single_sample_rt` (default
 * parameters: min, polynomial, analytic spheres) on the same view samples,
 * light and threads, and the primary rays that find those samples (one
 * Embree ray per pixel): one untimed warm-up each (it builds the resources),
 * then rounds alternating primary rays, hard and single_sample_rt. Reported:
 * the median per-round ratio of the shadow queries, single_sample_rt / hard,
 * and of a whole ray tracer without shading, (primary + single_sample_rt) /
 * (primary + hard), the paper's measure. One CSV row per scene and light
 * radius, written afresh (atomically) to reports/bench/single_sample_overhead.csv.
 * Usage: single_sample_overhead [--radius R]... [--threads N] [--repeat R] [-o CSV] SCENE... */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "core/fsutil.h"
#include "core/timer.h"
#include "lab/lab.h"
#include "version.h"

#define MAX_ITEMS 16
#define CSV_HEADER                                                                                               \
    "scene,triangles,light,radius,threads,rounds,primary_s,hard_s,single_sample_s,shadow_ratio,ray_tracer_ratio," \
    "outer_build_s,outer_bytes,commit,date\n"

typedef struct Options {
    const char *scenes[MAX_ITEMS];
    int num_scenes;
    double radii[MAX_ITEMS]; /* lights[1].radius overrides; none: the scene's own */
    int num_radii;
    int threads, repeat;
    const char *csv;
} Options;

typedef struct Row {
    const Scene *scene;
    double primary_s, hard_s, ss_s; /* medians over rounds */
    double shadow_ratio, tracer_ratio;
    double outer_build_s;
    size_t outer_bytes;
} Row;

static bool parse_number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || end == s || *end != '\0' || !(v >= lo && v <= hi)) return false;
    *out = v;
    return true;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.threads = omp_get_max_threads(), .repeat = 9, .csv = "reports/bench/single_sample_overhead.csv"};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        double x = 0;
        bool ok = true;
        if (a[0] != '-') {
            if (o->num_scenes == MAX_ITEMS) return false;
            o->scenes[o->num_scenes++] = a;
            continue;
        }
        if (strcmp(a, "--radius") == 0 && o->num_radii < MAX_ITEMS) ok = parse_number(v, 1e-9, 1e6, &o->radii[o->num_radii++]);
        else if (strcmp(a, "--threads") == 0) ok = parse_number(v, 1, 1024, &x), o->threads = (int)x;
        else if (strcmp(a, "--repeat") == 0) ok = parse_number(v, 1, 1000, &x), o->repeat = (int)x;
        else if (strcmp(a, "-o") == 0) ok = (o->csv = v) != NULL;
        else return false;
        if (!ok) return false;
        i++;
    }
    if (o->num_scenes == 0) o->scenes[o->num_scenes++] = "scenes/sphere-on-plane.lua";
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
    int n = o->repeat;
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

static void write_row(FILE *fp, const Row *r, const Options *o)
{
    char date[32], name[SCENE_NAME_MAX];
    time_t now = time(NULL);
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    snprintf(name, sizeof name, "%s", r->scene->name);
    for (char *c = name; *c; c++)
        if (*c == ',' || *c == '"' || *c == '\n') *c = '_';
    const Light *l = &r->scene->lights[0];
    fprintf(fp, "%s,%d,%s,%.6g,%d,%d,%.6g,%.6g,%.6g,%.4f,%.4f,%.6g,%zu,%s,%s\n", name, r->scene->num_triangles,
            light_kind_name(l->kind), (double)l->radius, o->threads, o->repeat, r->primary_s, r->hard_s, r->ss_s,
            r->shadow_ratio, r->tracer_ratio, r->outer_build_s, r->outer_bytes, SHADOWLAB_COMMIT, date);
}

/* One scene at one light radius (radius < 0: as the scene has it). */
static bool bench_one(const char *path, double radius, const Options *o, FILE *csv, Error *err)
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
               row.primary_s, row.hard_s, row.ss_s, row.shadow_ratio, row.tracer_ratio, o->repeat, o->threads,
               row.outer_build_s);
        write_row(csv, &row, o);
    }
    lab_close(lab);
    return ok;
}

static bool bench_all(const Options *o, Error *err)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", o->csv);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    if (slash && !mkdir_p(dir, err)) return false;
    AtomicFile af;
    if (!atomic_open(&af, o->csv, err)) return false;
    fputs(CSV_HEADER, af.fp);
    for (int i = 0; i < o->num_scenes; i++)
        for (int k = 0; k < (o->num_radii ? o->num_radii : 1); k++)
            if (!bench_one(o->scenes[i], o->num_radii ? o->radii[k] : -1, o, af.fp, err)) {
                atomic_abort(&af);
                return error_prefix(err, "%s: ", o->scenes[i]);
            }
    if (!atomic_commit(&af, err)) return false;
    printf("results: %s\n", o->csv);
    return true;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o)) {
        fprintf(stderr, "usage: single_sample_overhead [--radius R]... [--threads N] [--repeat R] [-o CSV] SCENE...\n");
        return 2;
    }
    omp_set_num_threads(o.threads);
    rt_set_threads(o.threads);
    Error err;
    if (!bench_all(&o, &err)) {
        fprintf(stderr, "single_sample_overhead: %s\n", err.msg);
        return 1;
    }
    return 0;
}
