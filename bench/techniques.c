/* techniques.c -- every registered technique's cost (issue 8, items 3 and 5),
 * read from the registry, so techniques that land later are measured with
 * no edit here:
 *   growth: frame time (its resources' build times + set-up + the median
 *     evaluation, lab.h) and evaluation time against its main parameter
 *     (the one it declares in the registry), against map_size where it has one,
 *     against triangle count (the scene's objects[2].segments) and against
 *     image size (camera.width x camera.height at 4:3);
 *   constant: techniques with a summed-area-table prefilter (a `prefilter`
 *     choice named sat) at K = its minimum and maximum: frame time at the
 *     largest K within 1.2x of the smallest (the papers' claim);
 *   threads: each technique's evaluation, and the Embree reference, at 1
 *     thread against N, alternating in every round after a warm-up at each.
 * Rows: DIR/growth.csv, DIR/constant_time.csv, DIR/threads_eval.csv.
 * Usage: techniques [--only growth|constant|threads] [-t TECH]... [--threads N]
 *                   [--repeat R] [--quick] [-o DIR] [SCENE] */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "techniques/smap.h"

#define MAX_ITEMS 32
#define MAX_POINTS 8
#define CONSTANT_BOUND 1.2
#define GROWTH_HEADER "technique,axis,value,frame_ms,eval_ms,build_ms,resources_built,scene,width,height," \
                      BENCH_TAIL_HEADER "\n"
#define CONSTANT_HEADER "technique,prefilter,K_min,K_max,frame_min_ms,frame_max_ms,ratio,bound,within," \
                        BENCH_TAIL_HEADER "\n"
#define THREADS_HEADER "technique,ms_1,ms_n,speedup,scene,width,height," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    const char *scene, *only;
    const char *techs[MAX_ITEMS];
    int num_techs;
    bool quick;
} Options;

/* One measured configuration. */
typedef struct Point {
    double frame_s, eval_s, build_s;
    int built;
} Point;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    if (strcmp(a, "--quick") == 0) return o->quick = true;
    if (!v) return 0;
    if (strcmp(a, "--only") == 0) o->only = v;
    else if (strcmp(a, "-t") == 0 && o->num_techs < MAX_ITEMS) o->techs[o->num_techs++] = v;
    else return 0;
    return 2;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.quick = false};
    if (!bench_parse(argc, argv, 3, &o->c, own_option, o) || o->c.num_scenes > 1) return false;
    o->scene = o->c.num_scenes ? o->c.scenes[0] : "scenes/sphere-on-plane.lua";
    return true;
}

static bool wanted(const Options *o, const char *name)
{
    for (int i = 0; i < o->num_techs; i++)
        if (strcmp(o->techs[i], name) == 0) return true;
    return o->num_techs == 0;
}

static bool part(const Options *o, const char *name) { return !o->only || strcmp(o->only, name) == 0; }

static bool append(const Options *o, const char *file, const char *header, const char *row, Error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", o->c.dir, file);
    return bench_csv_append(path, header, row, err);
}

/* ---- one configuration ------------------------------------------------------ */

static Lab *open_lab(const Options *o, const char *const *overrides, int n, Error *err)
{
    return lab_open(o->scene, overrides, n, err);
}

/* One warm-up then o->c.repeat timed evaluations (lab.h's timing). */
static bool measure(Lab *lab, const Technique *t, const double *params, int repeat, Point *p, Error *err)
{
    RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = repeat};
    RenderTiming timing = {.warmup = 1, .budget_s = 0.0};
    RenderResult r;
    if (!lab_render_timed(lab, &req, &timing, &r, err)) return false;
    *p = (Point){r.frame_s, r.eval_median_s, r.tech_build_s, 0};
    for (int i = 0; i < r.num_tech_resources; i++) p->built += r.tech_resources[i].built;
    render_result_free(&r);
    return true;
}

/* ---- growth ---------------------------------------------------------------- */

/* The main knob the technique declares in the registry (-1: none). */
static int main_param(const Technique *t) { return t->main_param ? tech_param_index(t, t->main_param) : -1; }

/* Values of a parameter: its default times 1/4 ... 8, clamped to its range,
 * without repeats (ints rounded, odd where the default is: kernel widths). */
static int param_values(const ParamDesc *p, double *v)
{
    static const double factors[] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0};
    int n = 0;
    double def = p->def != 0.0 ? p->def : (p->min > 0.0 ? p->min : 1.0);
    for (int k = 0; k < 6; k++) {
        double x = def * factors[k];
        if (p->type == PARAM_INT) {
            x = round(x);
            if (fmod(def, 2.0) == 1.0 && fmod(x, 2.0) == 0.0) x += 1.0;
        }
        x = fmin(fmax(x, p->min), p->max);
        if (n == 0 || x != v[n - 1]) v[n++] = x;
    }
    return n;
}

static bool growth_row(const Options *o, const Technique *t, const char *axis, double value, const Point *p,
                       const Scene *sc, Error *err)
{
    char row[1024], tail[512];
    bench_tail(tail, sizeof tail, o->c.threads);
    snprintf(row, sizeof row, "%s,%s,%g,%.4f,%.4f,%.4f,%d,%s,%d,%d,%s\n", t->name, axis, value, p->frame_s * 1e3,
             p->eval_s * 1e3, p->build_s * 1e3, p->built, sc->name, sc->camera.width, sc->camera.height, tail);
    printf("  %-18s %-16s %10g: frame %9.3f ms, eval %9.3f ms, build %9.3f ms\n", t->name, axis, value,
           p->frame_s * 1e3, p->eval_s * 1e3, p->build_s * 1e3);
    return append(o, "growth.csv", GROWTH_HEADER, row, err);
}

/* A technique parameter swept in one Lab (its resources reused where keys allow). */
static bool growth_param(const Options *o, Lab *lab, const Technique *t, int index, const double *values, int n,
                         Error *err)
{
    double params[TECH_MAX_PARAMS];
    tech_params_default(t, params);
    for (int i = 0; i < n; i++) {
        params[index] = values[i];
        Point p;
        if (!measure(lab, t, params, o->c.repeat, &p, err) ||
            !growth_row(o, t, t->params[index].name, values[i], &p, lab_scene(lab), err))
            return false;
    }
    return true;
}

/* A scene override swept, one Lab per value (new geometry or camera). */
static bool growth_scene(const Options *o, const Technique *t, const char *axis, const char *fmt, const int *values,
                         int n, Error *err)
{
    double params[TECH_MAX_PARAMS];
    tech_params_default(t, params);
    for (int i = 0; i < n; i++) {
        char a[64], b[64];
        snprintf(a, sizeof a, fmt, values[i]);
        snprintf(b, sizeof b, "camera.height=%d", values[i] * 3 / 4);
        const char *ov[] = {a, b};
        Lab *lab = open_lab(o, ov, strcmp(axis, "image_width") == 0 ? 2 : 1, err);
        Point p;
        bool ok = lab && measure(lab, t, params, o->c.repeat, &p, err) &&
                  growth_row(o, t, axis, strcmp(axis, "triangles") == 0 ? lab_scene(lab)->num_triangles : values[i],
                             &p, lab_scene(lab), err);
        lab_close(lab);
        if (!ok) return false;
    }
    return true;
}

static bool growth(const Options *o, const Technique *t, Error *err)
{
    static const int maps[] = {256, 512, 1024, 2048, 4096}, segs[] = {24, 96, 256, 512, 1024};
    static const int widths[] = {160, 320, 640, 1280};
    int nq = o->quick ? 3 : 5;
    const char *size_ov[] = {"camera.width=320", "camera.height=240"};
    Lab *lab = open_lab(o, size_ov, 2, err);
    if (!lab) return false;
    bool ok = true;
    int mp = main_param(t), ms = tech_param_index(t, "map_size");
    if (mp >= 0) {
        double v[MAX_POINTS];
        ok = growth_param(o, lab, t, mp, v, param_values(&t->params[mp], v), err);
    }
    if (ok && ms >= 0) {
        double v[5];
        for (int i = 0; i < nq + 1 && i < 5; i++) v[i] = maps[i];
        ok = growth_param(o, lab, t, ms, v, nq + 1 < 5 ? nq + 1 : 5, err);
    }
    lab_close(lab);
    ok = ok && growth_scene(o, t, "triangles", "objects[2].segments=%d", segs, nq, err);
    return ok && growth_scene(o, t, "image_width", "camera.width=%d", widths, o->quick ? 3 : 4, err);
}

/* ---- constant time in K ------------------------------------------------------ */

/* Index of choice `name` of enum parameter p, or -1. */
static int choice(const ParamDesc *p, const char *name)
{
    for (int k = 0; p->type == PARAM_ENUM && p->choices && p->choices[k]; k++)
        if (strcmp(p->choices[k], name) == 0) return k;
    return -1;
}

static bool constant_time(const Options *o, const Technique *t, Error *err)
{
    int pf = tech_param_index(t, "prefilter"), kp = tech_param_index(t, "K");
    int sat = pf >= 0 ? choice(&t->params[pf], "sat") : -1;
    if (sat < 0 || kp < 0) return true; /* no SAT prefilter: nothing claimed */
    const char *ov[] = {"camera.width=320", "camera.height=240"};
    Lab *lab = open_lab(o, ov, 2, err);
    if (!lab) return false;
    double params[TECH_MAX_PARAMS];
    tech_params_default(t, params);
    params[pf] = sat;
    const ParamDesc *K = &t->params[kp];
    Point lo, hi;
    params[kp] = K->min;
    bool ok = measure(lab, t, params, o->c.repeat, &lo, err);
    params[kp] = K->max;
    ok = ok && measure(lab, t, params, o->c.repeat, &hi, err);
    lab_close(lab);
    if (!ok) return false;
    double ratio = hi.frame_s / lo.frame_s;
    char row[1024], tail[512];
    bench_tail(tail, sizeof tail, o->c.threads);
    snprintf(row, sizeof row, "%s,sat,%g,%g,%.4f,%.4f,%.3f,%.1f,%s,%s\n", t->name, K->min, K->max, lo.frame_s * 1e3,
             hi.frame_s * 1e3, ratio, CONSTANT_BOUND, ratio <= CONSTANT_BOUND ? "yes" : "no", tail);
    printf("  %-8s prefilter=sat: K=%g %.3f ms, K=%g %.3f ms, ratio %.2f (bound %.1f)%s\n", t->name, K->min,
           lo.frame_s * 1e3, K->max, hi.frame_s * 1e3, ratio, CONSTANT_BOUND, ratio <= CONSTANT_BOUND ? "" : "  OVER");
    return append(o, "constant_time.csv", CONSTANT_HEADER, row, err);
}

/* ---- thread scaling ------------------------------------------------------------ */

typedef struct Scaling {
    Lab *lab;
    const Technique *t; /* NULL: the reference */
    double params[TECH_MAX_PARAMS];
} Scaling;

/* One timed evaluation (or reference computation) at `threads`. */
static bool scaled_once(const Scaling *s, int threads, double *seconds, Error *err)
{
    omp_set_num_threads(threads);
    if (s->t) {
        Point p;
        if (!measure(s->lab, s->t, s->params, 1, &p, err)) return false;
        *seconds = p.eval_s;
        return true;
    }
    ResourceManager *rm = lab_resources(s->lab);
    const Scene *sc = lab_scene(s->lab);
    const RtScene *bvh = res_bvh(rm, sc, RT_CASTERS, err);
    const ViewSamples *vs = bvh ? res_view_samples(rm, sc, err) : NULL;
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, err) : NULL;
    ReferenceParams prm = {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1};
    Reference ref;
    double t0 = timer_now_s();
    bool ok = cls && reference_compute(bvh, sc, 0, vs, cls, &prm, &ref, err);
    *seconds = timer_now_s() - t0;
    if (ok) reference_free(&ref);
    return ok;
}

static bool scaling(const Options *o, Scaling *s, Error *err)
{
    double *t = malloc(sizeof *t * 3 * (size_t)o->c.repeat), w;
    if (!t) return error_set(err, "out of memory");
    bool ok = scaled_once(s, 1, &w, err) && scaled_once(s, o->c.threads, &w, err);
    for (int i = 0; ok && i < o->c.repeat; i++) {
        ok = scaled_once(s, 1, &t[i], err) && scaled_once(s, o->c.threads, &t[o->c.repeat + i], err);
        t[2 * o->c.repeat + i] = t[i] / t[o->c.repeat + i];
    }
    omp_set_num_threads(o->c.threads);
    double med[3];
    for (int k = 0; ok && k < 3; k++) med[k] = bench_median(t + k * o->c.repeat, o->c.repeat);
    free(t);
    if (!ok) return false;
    const Scene *sc = lab_scene(s->lab);
    const char *name = s->t ? s->t->name : "reference";
    char row[1024], tail[512];
    bench_tail(tail, sizeof tail, o->c.threads);
    snprintf(row, sizeof row, "%s,%.4f,%.4f,%.3f,%s,%d,%d,%s\n", name, med[0] * 1e3, med[1] * 1e3, med[2], sc->name,
             sc->camera.width, sc->camera.height, tail);
    printf("  %-18s 1 thread %9.3f ms, %d threads %9.3f ms, speed-up %.2f\n", name, med[0] * 1e3, o->c.threads,
           med[1] * 1e3, med[2]);
    return append(o, "threads_eval.csv", THREADS_HEADER, row, err);
}

static bool threads_all(const Options *o, Error *err)
{
    const char *ov[] = {"camera.width=640", "camera.height=480"};
    Scaling s = {open_lab(o, ov, 2, err), NULL, {0}};
    if (!s.lab) return false;
    bool ok = !wanted(o, "reference") || scaling(o, &s, err);
    for (int i = 0; ok && i < tech_count(); i++) {
        s.t = tech_at(i);
        if (!wanted(o, s.t->name)) continue;
        tech_params_default(s.t, s.params);
        ok = scaling(o, &s, err);
    }
    lab_close(s.lab);
    return ok;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o))
        return bench_usage("techniques [--only growth|constant|threads] [-t TECH]... [--threads N] [--repeat R] "
                           "[--quick] [-o DIR] [SCENE]");
    omp_set_num_threads(o.c.threads);
    rt_set_threads(o.c.threads);
    Error err;
    bool ok = true;
    for (int i = 0; ok && i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        if (!wanted(&o, t->name)) continue;
        if (part(&o, "growth")) ok = growth(&o, t, &err);
        if (ok && part(&o, "constant")) ok = constant_time(&o, t, &err);
    }
    if (ok && part(&o, "threads")) ok = threads_all(&o, &err);
    return ok ? 0 : bench_fail("techniques", &err);
}
