/* techniques.c -- every registered technique's cost (issue 8, items 3 and 5),
 * read from the registry, so techniques that land later are measured with
 * no edit here. Each runs on SCENE as it is where it handles light 1's kind,
 * else with light 1 replaced by one of a kind it handles (bench_lab_open);
 * every row names the scene and the light, and a technique that fails is
 * reported and the others still run (exit status 1 at the end).
 *   growth: frame time (its resources' build times + set-up + the median
 *     evaluation, lab.h) and evaluation time against its main parameter
 *     (the one it declares in the registry), against map_size where it has one,
 *     against triangle count (the scene's objects[2].segments) and against
 *     image size (camera.width x camera.height at 4:3); --quick: one of
 *     these four axes a technique, rotating with its registry index
 *     (growth_axis), maps up to 1024^2 on the map_size axis and at most
 *     QUICK_MAP_SIZE^2 on the others (a larger default lowered, the
 *     row's settings saying so), the main parameter from 1/4 to 2 times its
 *     default (an enum or bool main parameter: each of its choices, the row's
 *     value its index), and a point's builds and evaluations each stop once they took
 *     GROWTH_QUICK_BUDGET_S;
 *   constant: techniques with a summed-area-table prefilter (a `prefilter`
 *     choice named sat) at K = its minimum and maximum: frame time at the
 *     largest K within 1.2x of the smallest (the papers' claim);
 *   threads: each technique's evaluation, and the Embree reference, on the
 *     curve 1, 2, 4, ... N threads (bench.h's BenchCurve; --quick: maps of
 *     at most QUICK_MAP_SIZE^2, a larger default lowered), with the CPU time
 *     a technique's threads ran (lab.h's eval_cpu_s, eval_busiest_s); a
 *     point's time is the median of as many evaluations as take about
 *     SCALING_MIN_S at one thread (the count fixed in the warm-up round), so
 *     a 7 ms evaluation is not one scheduler tick's worth of noise;
 *   lightsize: every soft technique that handles sphere lights at light 1's
 *     radius 0.05 and 0.8 (map_size 2048 where it has one; --quick: 1024;
 *     -p map_size=N: N; where it refuses that size, the largest half it accepts),
 *     the two radii in two Labs timed alternately in every round: frame (and
 *     evaluation) time at 0.8 over 0.05, against the 1.2 bound the constant-time
 *     claims name (prefiltered PCSS, CSSM, VSSM, ESSM, moment soft shadows:
 *     course §5.2.2; occlusion textures: §5.2.5), `pcss` beside them growing;
 *   work: each technique's machine-independent work counters (core/counters.h:
 *     texel fetches and rays per lit candidate, the frame's triangles, texels
 *     rasterised, texel fetches, rays and bytes built) at 160x120, beside the
 *     hand count where one is known: a K x K box PCF reads K^2 texels per lit
 *     candidate, a single-layer sm one, hard and single_sample_rt trace one
 *     ray (bench_lab_open's scene: every sample lies in the fitted map).
 *   sweep (only with --only): cost against one axis, --sweep NAME=V1,V2,...
 *     (a parameter of the selected techniques, or a scene key): every round
 *     times each value once; ns per lit candidate, and per lit candidate per
 *     unit of the value, over the first value's (linear: near 1; issue 15),
 *     and ns per micropatch (evaluation time / work.micropatches, the
 *     occluder polygons backprojected; NaN for a technique that has none);
 *   matched (only with --only): the prefiltered PCSS family (or -t's) over
 *     map sizes 64 ... 2048: penumbra RMSE against the Embree reference
 *     (--samples) and frame time, and the time each needs at pcss's RMSE
 *     (its defaults) over pcss's, timed in the same rounds (issue 16).
 * -p NAME=VALUE sets that parameter in every technique that has one (the
 * rows' `settings` column lists what was set).
 * Rows: DIR/growth.csv, DIR/constant_time.csv, DIR/threads_eval.csv, DIR/light_size.csv,
 * DIR/work.csv, DIR/sweep.csv, DIR/matched_curve.csv, DIR/matched.csv.
 * Usage: techniques [--only growth|constant|threads|lightsize|work|sweep|matched] [-t TECH]... [-p NAME=VALUE]...
 *                   [--sweep NAME=V1,V2,...] [--samples N] [--threads N] [--repeat R] [--quick] [-o DIR] [SCENE] */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "lab/compare.h"
#include "resources/refcache.h"
#include "techniques/smap.h"

#define MAX_ITEMS 32
#define MAX_POINTS 8
#define CONSTANT_BOUND 1.2
/* Every row: ..., scene, light, settings, width, height, then bench_tail's columns. */
#define WHERE_HEADER "scene,light,settings,width,height," BENCH_TAIL_HEADER "\n"
#define GROWTH_HEADER "technique,axis,value,frame_ms,eval_ms,build_ms,resources_built,note," WHERE_HEADER
#define CONSTANT_HEADER "technique,prefilter,K_min,K_max,frame_min_ms,frame_max_ms,ratio,bound,within," WHERE_HEADER
/* --quick: a growth point's builds and evaluations each stop once they took
 * this long (lab.h RenderTiming; a 1024^2 cssm moment map builds in about 2 s
 * and was built 4 times a point: the growth step took 11 of QUICK's minutes). */
#define GROWTH_QUICK_BUDGET_S 1.0
/* The first round of timed_rounds: a configuration's repeated builds (and
 * evaluations) stop once they took this long; a build slower than that is
 * the one timed, cold (its pages' first touch a small part of it). */
#define ROUNDS_BUILD_BUDGET_S 2.0
/* --quick: the largest map growth's main parameter, triangle and image axes
 * and the threads part build (a default above it is lowered unless -p
 * map_size is given): on 1024^2 cube maps at one thread, cssm's 33-image
 * summed-area tables took 13 s a growth point on the triangle axis, lvsm's
 * 16 layers 15 s (growth: 288 s of the 19-minute QUICK run); threads' builds
 * at 640 x 480 took most of its 233 s (penumbra_deep_map's 1024^2 cube: 11 s
 * of its 25, where the evaluations are 0.05 s each). */
#define QUICK_MAP_SIZE 512

#define THREADS_HEADER "technique,ms_1,ms_n,speedup,cpu_ms_1,cpu_ms_n,busiest_ms_n,cpu_bound,machine_speedup,over_machine,evals," \
                       WHERE_HEADER
#define LIGHT_SIZE_HEADER "technique,map_size,radius_small,radius_large,frame_small_ms,frame_large_ms,ratio,bound,within," \
                          "eval_small_ms,eval_large_ms,eval_ratio,bytes_small,bytes_large,bytes_ratio,note," \
                          WHERE_HEADER
#define LIGHT_SMALL 0.05 /* light 1's radii of the lightsize part, world units */
#define LIGHT_LARGE 0.8
#define SWEEP_HEADER "technique,axis,value,frame_ms,eval_ms,lit_candidates,eval_ns_per_sample," \
                     "eval_ns_per_sample_per_value,frame_ratio,eval_ratio,frame_per_value_ratio,per_value_ratio," \
                     "micropatches,ns_per_micropatch," WHERE_HEADER
#define CURVE_HEADER "technique,map_size,penumbra_rmse,penumbra_noise_rms,penumbra_samples,frame_ms,eval_ms,note," \
                     WHERE_HEADER
#define MATCHED_HEADER "technique,target_rmse,pcss_frame_ms,frame_at_target_ms,ratio,pcss_eval_ms,eval_at_target_ms," \
                       "eval_ratio,reached,note," WHERE_HEADER
#define WORK_HEADER "technique,lit_candidates,texel_fetches_per_sample,texel_bytes_per_sample,rays_per_sample," \
                    "frame_triangles,frame_fragments,frame_texel_fetches,frame_rays,frame_bytes_built,hand_rule," \
                    "hand_texel_fetches_per_sample,hand_rays_per_sample,agrees," WHERE_HEADER

typedef struct Options {
    BenchCommon c;
    const char *scene, *only;
    const char *techs[MAX_ITEMS], *settings[MAX_ITEMS];
    int num_techs, num_settings;
    bool quick;
    const char *sweep; /* --sweep NAME=V1,V2,...: the sweep part's axis */
    char axis[128];    /* its NAME: a technique parameter, or a scene key (holds '.' or '[') */
    char value_text[MAX_POINTS][64]; /* its values as given: numbers, or an enum's choices */
    double values[MAX_POINTS];        /* as numbers (NaN for a choice: no per-unit figures) */
    int num_values;
    int samples;       /* --samples N: the matched part's reference light samples */
} Options;

/* One technique as measured: its parameters (defaults, then -p) and light. */
typedef struct Subject {
    const Technique *t;
    double params[TECH_MAX_PARAMS];
    char settings[256]; /* the -p assignments it has, or "defaults" */
    BenchLight light;
    int refused;        /* growth points the technique refused (growth_point) */
} Subject;

/* One measured configuration. */
typedef struct Point {
    double frame_s, eval_s, build_s;
    int built;
    double cpu_s, busiest_s; /* the evaluation's CPU seconds: all threads, the busiest (lab.h) */
    long lit; /* lit candidates evaluated (what per-sample costs divide by) */
    double bytes_per_lit; /* texel bytes one evaluation read per lit candidate (core/counters.h) */
    uint64_t micropatches; /* occluder polygons one evaluation backprojected (core/counters.h) */
} Point;

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    if (strcmp(a, "--quick") == 0) return o->quick = true;
    if (!v) return 0;
    if (strcmp(a, "--only") == 0) o->only = v;
    else if (strcmp(a, "--sweep") == 0 && strchr(v, '=')) o->sweep = v;
    else if (strcmp(a, "--samples") == 0) return bench_parse_int(v, 1, REFERENCE_MAX_SAMPLES, &o->samples) ? 2 : 0;
    else if (strcmp(a, "-t") == 0 && o->num_techs < MAX_ITEMS) o->techs[o->num_techs++] = v;
    else if (strcmp(a, "-p") == 0 && o->num_settings < MAX_ITEMS && strchr(v, '=')) o->settings[o->num_settings++] = v;
    else return 0;
    return 2;
}

static bool wanted(const Options *o, const char *name)
{
    for (int i = 0; i < o->num_techs; i++)
        if (strcmp(o->techs[i], name) == 0) return true;
    return o->num_techs == 0;
}

/* The NAME of a -p NAME=VALUE (own_option checked the '='). */
typedef struct ParamName {
    char s[128];
} ParamName;
static ParamName param_name(const char *assignment)
{
    ParamName n;
    snprintf(n.s, sizeof n.s, "%.*s", (int)(strchr(assignment, '=') - assignment), assignment);
    return n;
}

/* Whether the --sweep axis is a scene key (lights[1].radius), not a parameter. */
static bool sweep_on_scene(const Options *o) { return strchr(o->axis, '.') || strchr(o->axis, '['); }

/* Whether a technique -t selects has the parameter `option` (-p, --sweep) assigns (a typo is refused). */
static bool setting_used(const Options *o, const char *option, const char *assignment)
{
    ParamName name = param_name(assignment);
    for (int i = 0; i < tech_count(); i++)
        if (wanted(o, tech_at(i)->name) && tech_param_index(tech_at(i), name.s) >= 0) return true;
    fprintf(stderr, "techniques: %s %s: no selected technique has a parameter '%s'\n", option, assignment, name.s);
    return false;
}

/* --sweep NAME=V1,V2,...: at most MAX_POINTS values, of a scene key or of a
 * parameter of a selected technique (each value checked by every selected
 * technique that has it: its range or choices named where one is refused). */
static bool parse_sweep(Options *o)
{
    snprintf(o->axis, sizeof o->axis, "%s", param_name(o->sweep).s);
    for (const char *v = strchr(o->sweep, '=') + 1; *v;) {
        size_t len = strcspn(v, ",");
        if (len == 0 || len >= sizeof o->value_text[0] || o->num_values == MAX_POINTS) {
            fprintf(stderr, "techniques: --sweep %s: expected NAME=V1,V2,... with at most %d non-empty values\n",
                    o->sweep, MAX_POINTS);
            return false;
        }
        char *text = o->value_text[o->num_values], *end;
        snprintf(text, sizeof o->value_text[0], "%.*s", (int)len, v);
        double x = strtod(text, &end);
        o->values[o->num_values++] = *end == '\0' && isfinite(x) ? x : NAN;
        v += len + (v[len] == ',');
    }
    if (o->num_values == 0 || sweep_on_scene(o)) return o->num_values > 0;
    if (!setting_used(o, "--sweep", o->sweep)) return false;
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        if (!wanted(o, t->name) || tech_param_index(t, o->axis) < 0) continue;
        for (int k = 0; k < o->num_values; k++) {
            double scratch[TECH_MAX_PARAMS];
            char a[256];
            Error err;
            tech_params_default(t, scratch);
            snprintf(a, sizeof a, "%s=%s", o->axis, o->value_text[k]);
            if (!tech_param_parse(t, a, scratch, &err)) {
                fprintf(stderr, "techniques: --sweep: %s: %s\n", t->name, err.msg);
                return false;
            }
        }
    }
    return true;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.quick = false, .samples = 64};
    if (!bench_parse(argc, argv, 3, &o->c, own_option, o) || o->c.num_scenes > 1) return false;
    if (o->only && strcmp(o->only, "sweep") == 0 && !o->sweep) return false; /* --only's name: main, against PARTS */
    for (int i = 0; i < o->num_techs; i++) {
        Error err;
        if (strcmp(o->techs[i], "reference") == 0 || tech_find(o->techs[i], &err)) continue;
        fprintf(stderr, "techniques: -t: %s\n", err.msg);
        return false;
    }
    for (int i = 0; i < o->num_settings; i++)
        if (!setting_used(o, "-p", o->settings[i])) return false;
    if (o->sweep && !parse_sweep(o)) return false;
    o->scene = o->c.num_scenes ? o->c.scenes[0] : "scenes/sphere-on-plane.lua";
    return true;
}

static bool part(const Options *o, const char *name) { return !o->only || strcmp(o->only, name) == 0; }

static bool append(const Options *o, const char *file, const char *header, const char *row, Error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", o->c.dir, file);
    return bench_csv_append(path, header, row, err);
}

/* ---- one configuration ------------------------------------------------------ */

/* The technique's defaults with every -p assignment it has a parameter for. */
static bool subject_init(const Options *o, const Technique *t, Subject *sj, Error *err)
{
    *sj = (Subject){.t = t, .settings = ""};
    tech_params_default(t, sj->params);
    size_t used = 0;
    for (int i = 0; i < o->num_settings; i++) {
        if (tech_param_index(t, param_name(o->settings[i]).s) < 0) continue;
        if (!tech_param_parse(t, o->settings[i], sj->params, err)) return false;
        used += (size_t)snprintf(sj->settings + used, sizeof sj->settings - used, "%s%s", used ? " " : "",
                                 o->settings[i]);
    }
    if (!used) snprintf(sj->settings, sizeof sj->settings, "defaults");
    return true;
}

/* The scene with `overrides`, under a light the subject handles. */
static Lab *open_lab(const Options *o, Subject *sj, const char *const *overrides, int n, Error *err)
{
    return bench_lab_open(o->scene, sj->t, overrides, n, &sj->light, err);
}

/* The columns every row ends with (WHERE_HEADER). */
static void where(const Subject *sj, const Scene *sc, int threads, char *out, size_t n)
{
    char name[160], light[200], settings[300], tail[512];
    bench_csv_field(name, sizeof name, sc->name);
    bench_csv_field(light, sizeof light, sj->light.text);
    bench_csv_field(settings, sizeof settings, sj->settings);
    bench_tail(tail, sizeof tail, threads);
    snprintf(out, n, "%s,%s,%s,%d,%d,%s\n", name, light, settings, sc->camera.width, sc->camera.height, tail);
}

/* "TECH on SCENE, light 1: LIGHT (SETTINGS)", printed before its figures. */
static void announce(const Options *o, const Subject *sj, const char *what)
{
    printf("%s: %s on %s, light 1: %s (%s)\n", what, sj->t->name, o->scene, sj->light.text, sj->settings);
}

/* One warm-up then o->c.repeat timed evaluations (lab.h's timing). */
static bool measure_within(Lab *lab, const Technique *t, const double *params, int repeat, double budget_s, Point *p,
                           Error *err)
{
    RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = repeat};
    RenderTiming timing = {.warmup = 1, .budget_s = budget_s};
    RenderResult r;
    if (!lab_render_timed(lab, &req, &timing, &r, err)) return false;
    double lit = r.lit_candidates > 0 ? (double)r.lit_candidates : NAN; /* none lit: NaN, shown */
    *p = (Point){r.frame_s, r.eval_median_s, r.tech_build_s, 0, r.eval_cpu_s, r.eval_busiest_s, r.lit_candidates,
                 (double)r.eval_work.texel_bytes / lit, r.eval_work.micropatches};
    for (int i = 0; i < r.num_tech_resources; i++) p->built += r.tech_resources[i].built;
    render_result_free(&r);
    return true;
}

/* measure_within with exactly `repeat` timed builds and evaluations. */
static bool measure(Lab *lab, const Technique *t, const double *params, int repeat, Point *p, Error *err)
{
    return measure_within(lab, t, params, repeat, 0.0, p, err);
}

/* ---- growth ---------------------------------------------------------------- */

/* The main knob the technique declares in the registry (-1: none). */
static int main_param(const Technique *t) { return t->main_param ? tech_param_index(t, t->main_param) : -1; }

/* Values of a parameter: an enum's or a bool's every choice (at most
 * MAX_POINTS); a number's default times 1/4 ... 8 (--quick: ... 2), clamped
 * to its range, without repeats (ints rounded, odd where the default is:
 * kernel widths). */
static int param_values(const ParamDesc *p, bool quick, double *v)
{
    int n = 0;
    if (p->type == PARAM_ENUM || p->type == PARAM_BOOL) {
        for (double x = p->min; x <= p->max && n < MAX_POINTS; x += 1.0) v[n++] = x;
        return n;
    }
    static const double factors[] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0};
    int nf = quick ? 4 : 6;
    double def = p->def != 0.0 ? p->def : (p->min > 0.0 ? p->min : 1.0);
    for (int k = 0; k < nf; k++) {
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

/* One point of a growth curve: measured, or refused by the technique (a
 * resource over its cap, say), which is printed and kept in the row's note
 * with empty timings; only a failure to write the row is an error. */
static bool growth_point(const Options *o, Lab *lab, Subject *sj, const double *params, const char *axis,
                         double value, Error *err)
{
    char row[4096], end[1024], note[1100] = "", timings[160];
    Point p;
    Error refusal;
    if (measure_within(lab, sj->t, params, o->c.repeat, o->quick ? GROWTH_QUICK_BUDGET_S : 0.0, &p, &refusal)) {
        snprintf(timings, sizeof timings, "%.4f,%.4f,%.4f,%d", p.frame_s * 1e3, p.eval_s * 1e3, p.build_s * 1e3,
                 p.built);
        printf("  %-18s %-16s %10g: frame %9.3f ms, eval %9.3f ms, build %9.3f ms\n", sj->t->name, axis, value,
               p.frame_s * 1e3, p.eval_s * 1e3, p.build_s * 1e3);
    } else {
        snprintf(timings, sizeof timings, ",,,");
        bench_csv_field(note, sizeof note, refusal.msg);
        printf("  %-18s %-16s %10g: REFUSED: %s\n", sj->t->name, axis, value, refusal.msg);
        sj->refused++;
    }
    where(sj, lab_scene(lab), o->c.threads, end, sizeof end);
    snprintf(row, sizeof row, "%s,%s,%g,%s,%s,%s", sj->t->name, axis, value, timings, note, end);
    return append(o, "growth.csv", GROWTH_HEADER, row, err);
}

/* A technique parameter swept in one Lab (its resources reused where keys allow). */
static bool growth_param(const Options *o, Lab *lab, Subject *sj, int index, const double *values, int n, Error *err)
{
    double params[TECH_MAX_PARAMS];
    memcpy(params, sj->params, sizeof params);
    for (int i = 0; i < n; i++) {
        params[index] = values[i];
        if (!growth_point(o, lab, sj, params, sj->t->params[index].name, values[i], err)) return false;
    }
    return true;
}

/* A scene override swept, one Lab per value (new geometry or camera). */
static bool growth_scene(const Options *o, Subject *sj, const char *axis, const char *fmt, const int *values, int n,
                         Error *err)
{
    for (int i = 0; i < n; i++) {
        char a[64], b[64];
        snprintf(a, sizeof a, fmt, values[i]);
        snprintf(b, sizeof b, "camera.height=%d", values[i] * 3 / 4);
        const char *ov[] = {a, b};
        Lab *lab = open_lab(o, sj, ov, strcmp(axis, "image_width") == 0 ? 2 : 1, err);
        bool ok = lab && growth_point(o, lab, sj, sj->params, axis,
                                      strcmp(axis, "triangles") == 0 ? lab_scene(lab)->num_triangles : values[i], err);
        lab_close(lab);
        if (!ok) return false;
    }
    return true;
}

/* The growth axes, in the order --quick rotates through them. */
enum { AXIS_MAIN, AXIS_MAP, AXIS_TRIANGLES, AXIS_IMAGE, NUM_AXES };

/* Position of t in the registry (tech_at). */
static int registry_index(const Technique *t)
{
    for (int i = 0; i < tech_count(); i++)
        if (tech_at(i) == t) return i;
    return 0;
}

/* Does growth run axis a for sj? Every axis in a full run; with --quick one
 * axis a technique, its registry index modulo the axes (the next one that
 * applies where that one does not: no main parameter or no map), so every
 * technique is measured and every axis by a quarter of them. */
static bool growth_axis(const Options *o, const Subject *sj, int a)
{
    if (!o->quick) return true;
    bool applies[NUM_AXES] = {main_param(sj->t) >= 0, tech_param_index(sj->t, "map_size") >= 0, true, true};
    int k = registry_index(sj->t) % NUM_AXES;
    while (!applies[k]) k = (k + 1) % NUM_AXES;
    return k == a;
}

/* Whether -p assigned the parameter `name` (a part then leaves it as given). */
static bool assigned(const Options *o, const char *name)
{
    for (int i = 0; i < o->num_settings; i++)
        if (strcmp(param_name(o->settings[i]).s, name) == 0) return true;
    return false;
}

/* sj's map_size lowered to `size` where it is larger and -p map_size did
 * not set it, the lowering added to its settings ("map_size=N (--quick)"). */
static void lower_map_size(const Options *o, Subject *sj, int size)
{
    int ms = tech_param_index(sj->t, "map_size");
    if (ms < 0 || assigned(o, "map_size") || sj->params[ms] <= size) return;
    sj->params[ms] = size;
    if (strcmp(sj->settings, "defaults") == 0) sj->settings[0] = '\0';
    size_t used = strlen(sj->settings);
    snprintf(sj->settings + used, sizeof sj->settings - used, "%smap_size=%d (--quick)", used ? " " : "", size);
}

static bool growth(const Options *o, Subject *given, Error *err)
{
    Subject quick = *given, *sj = &quick;
    /* --quick: the axes other than map_size are curves in their own value,
     * and the map's build was most of a point's time */
    if (o->quick && !growth_axis(o, sj, AXIS_MAP)) lower_map_size(o, sj, QUICK_MAP_SIZE);
    static const int maps[] = {256, 512, 1024, 2048, 4096}, segs[] = {24, 96, 256, 512, 1024};
    static const int widths[] = {160, 320, 640, 1280};
    int nq = o->quick ? 3 : 5;
    const char *size_ov[] = {"camera.width=320", "camera.height=240"};
    Lab *lab = open_lab(o, sj, size_ov, 2, err);
    if (!lab) return false;
    announce(o, sj, "growth");
    bool ok = true;
    int mp = main_param(sj->t), ms = tech_param_index(sj->t, "map_size");
    if (mp >= 0 && growth_axis(o, sj, AXIS_MAIN)) {
        double v[MAX_POINTS];
        ok = growth_param(o, lab, sj, mp, v, param_values(&sj->t->params[mp], o->quick, v), err);
    }
    if (ok && ms >= 0 && growth_axis(o, sj, AXIS_MAP)) {
        double v[5];
        int nmaps = o->quick ? 3 : 5; /* --quick: up to 1024^2 */
        for (int i = 0; i < nmaps; i++) v[i] = maps[i];
        ok = growth_param(o, lab, sj, ms, v, nmaps, err);
    }
    lab_close(lab);
    if (ok && growth_axis(o, sj, AXIS_TRIANGLES))
        ok = growth_scene(o, sj, "triangles", "objects[2].segments=%d", segs, nq, err);
    if (ok && growth_axis(o, sj, AXIS_IMAGE))
        ok = growth_scene(o, sj, "image_width", "camera.width=%d", widths, o->quick ? 3 : 4, err);
    given->refused = sj->refused;
    return ok;
}

/* ---- constant time in K ------------------------------------------------------ */

/* Index of choice `name` of enum parameter p, or -1. */
static int choice(const ParamDesc *p, const char *name)
{
    for (int k = 0; p->type == PARAM_ENUM && p->choices && p->choices[k]; k++)
        if (strcmp(p->choices[k], name) == 0) return k;
    return -1;
}

/* Whether the technique claims constant time in K: a SAT prefilter choice. */
static bool has_sat(const Technique *t)
{
    int pf = tech_param_index(t, "prefilter");
    return pf >= 0 && tech_param_index(t, "K") >= 0 && choice(&t->params[pf], "sat") >= 0;
}

static bool constant_time(const Options *o, Subject *sj, Error *err)
{
    const Technique *t = sj->t;
    int pf = tech_param_index(t, "prefilter"), kp = tech_param_index(t, "K");
    const char *ov[] = {"camera.width=320", "camera.height=240"};
    Lab *lab = open_lab(o, sj, ov, 2, err);
    if (!lab) return false;
    announce(o, sj, "constant");
    double params[TECH_MAX_PARAMS];
    memcpy(params, sj->params, sizeof params);
    params[pf] = choice(&t->params[pf], "sat");
    const ParamDesc *K = &t->params[kp];
    Point lo, hi;
    params[kp] = K->min;
    bool ok = measure(lab, t, params, o->c.repeat, &lo, err);
    params[kp] = K->max;
    ok = ok && measure(lab, t, params, o->c.repeat, &hi, err);
    char row[2048], end[1024];
    if (ok) where(sj, lab_scene(lab), o->c.threads, end, sizeof end);
    lab_close(lab);
    if (!ok) return false;
    double ratio = hi.frame_s / lo.frame_s;
    snprintf(row, sizeof row, "%s,sat,%g,%g,%.4f,%.4f,%.3f,%.1f,%s,%s", t->name, K->min, K->max, lo.frame_s * 1e3,
             hi.frame_s * 1e3, ratio, CONSTANT_BOUND, ratio <= CONSTANT_BOUND ? "yes" : "no", end);
    printf("  %-8s prefilter=sat: K=%g %.3f ms, K=%g %.3f ms, ratio %.2f (bound %.1f)%s\n", t->name, K->min,
           lo.frame_s * 1e3, K->max, hi.frame_s * 1e3, ratio, CONSTANT_BOUND, ratio <= CONSTANT_BOUND ? "" : "  OVER");
    return append(o, "constant_time.csv", CONSTANT_HEADER, row, err);
}

/* Median over rounds of point k's per-round time over point 0's, times
 * scale (t[r * n + k]: round r, point k). */
static double round_ratio(const double *t, int rounds, int n, int k, double scale)
{
    double v[64];
    for (int r = 0; r < rounds; r++) v[r] = t[r * n + k] / t[r * n] * scale;
    return bench_median(v, rounds);
}

/* Median over rounds of point k's time. */
static double round_median(const double *t, int rounds, int n, int k)
{
    double v[64];
    for (int r = 0; r < rounds; r++) v[r] = t[r * n + k];
    return bench_median(v, rounds);
}

/* Every round times each of n configurations (labs[k], params[k]) once, in
 * order, each after measure's own untimed warm-up: frame and evaluation
 * seconds in frame[r * n + k], eval[r * n + k]; last[k] its last Point
 * (lit candidates, texel bytes per lit candidate). Round 0 builds each
 * configuration's frame resources `rounds` times (until they took
 * ROUNDS_BUILD_BUDGET_S) and the later rounds reuse them, so a frame's
 * builds are the median of warm ones, as a renderer's that allocates its
 * maps once, not the one cold build's first touch of its pages (on a
 * virtual machine up to 5x the build: bench/README.md, step 11). */
static bool timed_rounds(Lab *const *labs, const Technique *t, double (*params)[TECH_MAX_PARAMS], int n, int rounds,
                         double *frame, double *eval, Point *last, Error *err)
{
    for (int r = 0; r < rounds; r++)
        for (int k = 0; k < n; k++) {
            Point *p = &last[k];
            if (!measure_within(labs[k], t, params[k], r == 0 ? rounds : 1, r == 0 ? ROUNDS_BUILD_BUDGET_S : 0.0, p,
                                err))
                return false;
            frame[r * n + k] = p->frame_s;
            eval[r * n + k] = p->eval_s;
        }
    return true;
}

/* ---- constant in the light's size -------------------------------------------- */

static bool soft_on_spheres(const Technique *t)
{
    return strcmp(t->family, "soft") == 0 && (t->lights & LIGHT_BIT(LIGHT_SPHERE));
}

/* The two radii's times at map_size `map_size` (0: the technique has none),
 * one Lab each, alternating in every round (timed_rounds): medians in
 * frame_ms[2], eval_ms[2]; *frame_ratio, *eval_ratio the medians of the
 * per-round ratios large / small. */
typedef struct RadiusPair {
    double frame_ms[2], eval_ms[2], frame_ratio, eval_ratio;
    double bytes[2]; /* texel bytes read per lit candidate (machine-independent: early outs, subdivision) */
} RadiusPair;

static bool both_radii(const Options *o, Subject *sj, int map_size, RadiusPair *rp, char *end, size_t n, Error *err)
{
    static const double radii[2] = {LIGHT_SMALL, LIGHT_LARGE};
    int rounds = o->c.repeat > 64 ? 64 : o->c.repeat, ms = tech_param_index(sj->t, "map_size");
    double params[2][TECH_MAX_PARAMS], frame[2 * 64], eval[2 * 64];
    Point last[2];
    Lab *labs[2] = {NULL, NULL};
    bool ok = true;
    for (int k = 0; ok && k < 2; k++) {
        memcpy(params[k], sj->params, sizeof params[k]);
        if (ms >= 0) params[k][ms] = map_size;
        char r[64];
        snprintf(r, sizeof r, "lights[1].radius=%g", radii[k]);
        const char *ov[] = {"camera.width=320", "camera.height=240", r};
        ok = (labs[k] = open_lab(o, sj, ov, 3, err)) != NULL;
    }
    ok = ok && timed_rounds(labs, sj->t, params, 2, rounds, frame, eval, last, err);
    if (ok) {
        where(sj, lab_scene(labs[1]), o->c.threads, end, n);
        for (int k = 0; k < 2; k++) {
            rp->frame_ms[k] = round_median(frame, rounds, 2, k) * 1e3;
            rp->eval_ms[k] = round_median(eval, rounds, 2, k) * 1e3;
            rp->bytes[k] = last[k].bytes_per_lit;
        }
        rp->frame_ratio = round_ratio(frame, rounds, 2, 1, 1.0);
        rp->eval_ratio = round_ratio(eval, rounds, 2, 1, 1.0);
    }
    lab_close(labs[0]);
    lab_close(labs[1]);
    return ok;
}

/* At map_size 2048 (--quick: 1024; -p map_size=N: N), or, where the technique
 * refuses that with its own error (a resource over its cap), at the first of
 * half, a quarter, ... (down to 256) it accepts, as memory.c does; the row's
 * note names the size refused and why. Only a technique that refuses every
 * size (or has no map_size and refuses) fails. */
static bool light_size(const Options *o, Subject *sj, Error *err)
{
    const Technique *t = sj->t;
    int ms = tech_param_index(t, "map_size");
    int map_size = ms < 0 ? 0 : assigned(o, "map_size") ? (int)sj->params[ms] : o->quick ? 1024 : 2048;
    RadiusPair rp;
    char end[1024], note[1200] = "";
    while (!both_radii(o, sj, map_size, &rp, end, sizeof end, err)) {
        if (ms < 0 || map_size / 2 < 256) return false;
        if (!note[0]) {
            char why[1100];
            snprintf(why, sizeof why, "map_size %d REFUSED (%s); measured at the largest half accepted", map_size,
                     err->msg);
            bench_csv_field(note, sizeof note, why);
        }
        printf("  %-18s map_size %d REFUSED (%s); trying %d\n", t->name, map_size, err->msg, map_size / 2);
        map_size /= 2;
    }
    announce(o, sj, "lightsize");
    double ratio = rp.frame_ratio;
    char row[4096];
    snprintf(row, sizeof row, "%s,%d,%g,%g,%.4f,%.4f,%.3f,%.1f,%s,%.4f,%.4f,%.3f,%.1f,%.1f,%.3f,%s,%s", t->name,
             map_size, LIGHT_SMALL, LIGHT_LARGE, rp.frame_ms[0], rp.frame_ms[1], ratio, CONSTANT_BOUND,
             ratio <= CONSTANT_BOUND ? "yes" : "no", rp.eval_ms[0], rp.eval_ms[1], rp.eval_ratio, rp.bytes[0],
             rp.bytes[1], rp.bytes[1] / rp.bytes[0], note, end);
    printf("  %-18s map_size %d: radius %g: frame %.3f ms (eval %.3f), radius %g: frame %.3f ms (eval %.3f), "
           "ratio %.2f (bound %.1f; eval %.2f; texel bytes per lit sample %.0f -> %.0f, x%.2f)%s\n", t->name,
           map_size, LIGHT_SMALL, rp.frame_ms[0], rp.eval_ms[0], LIGHT_LARGE, rp.frame_ms[1], rp.eval_ms[1], ratio,
           CONSTANT_BOUND, rp.eval_ratio, rp.bytes[0], rp.bytes[1], rp.bytes[1] / rp.bytes[0],
           ratio <= CONSTANT_BOUND ? "" : "  OVER");
    return append(o, "light_size.csv", LIGHT_SIZE_HEADER, row, err);
}

/* ---- cost against one axis (--sweep) ---------------------------------------- */

/* The subject at every value of the --sweep axis (320 x 240): a parameter in
 * one Lab, a scene key in one Lab per value. Every round times each value
 * once, in order (measure's own warm-up before each); rows give the medians,
 * the evaluation's ns per lit candidate and per lit candidate per unit of
 * the value, and the medians of the per-round ratios to the first value:
 * of the frame and evaluation times, and of both per lit candidate per unit
 * of the value (linear in it: near 1); and the median evaluation's ns per
 * micropatch backprojected (the last round's count: each does the same work). */
static bool sweep_cost(const Options *o, Subject *sj, Error *err)
{
    int n = o->num_values, rounds = o->c.repeat > 64 ? 64 : o->c.repeat;
    int pi = sweep_on_scene(o) ? -1 : tech_param_index(sj->t, o->axis);
    Lab *labs[MAX_POINTS] = {0};
    double params[MAX_POINTS][TECH_MAX_PARAMS], frame[64 * MAX_POINTS], eval[64 * MAX_POINTS];
    Point last[MAX_POINTS];
    long lit[MAX_POINTS] = {0};
    uint64_t patches[MAX_POINTS] = {0};
    bool ok = true;
    for (int k = 0; ok && k < n; k++) {
        char key[256];
        snprintf(key, sizeof key, "%s=%s", o->axis, o->value_text[k]);
        memcpy(params[k], sj->params, sizeof params[k]);
        if (pi >= 0 && !(ok = tech_param_parse(sj->t, key, params[k], err))) break; /* parse_sweep checked it */
        if (k > 0 && pi >= 0) {
            labs[k] = labs[0];
            continue;
        }
        const char *ov[] = {"camera.width=320", "camera.height=240", key};
        ok = (labs[k] = open_lab(o, sj, ov, pi >= 0 ? 2 : 3, err)) != NULL;
    }
    if (ok) announce(o, sj, "sweep");
    ok = ok && timed_rounds(labs, sj->t, params, n, rounds, frame, eval, last, err);
    for (int k = 0; ok && k < n; k++) {
        lit[k] = last[k].lit;
        patches[k] = last[k].micropatches;
    }
    for (int k = 0; ok && k < n; k++) {
        double f = round_median(frame, rounds, n, k), e = round_median(eval, rounds, n, k);
        double per_sample = lit[k] > 0 ? e * 1e9 / (double)lit[k] : NAN; /* no lit candidate: NaN, shown */
        double per_value = o->values[k] != 0.0 ? per_sample / o->values[k] : NAN; /* a choice (NaN) or 0: no unit */
        double per_patch = patches[k] > 0 ? e * 1e9 / (double)patches[k] : NAN; /* none backprojected: NaN */
        double fr = round_ratio(frame, rounds, n, k, 1.0), er = round_ratio(eval, rounds, n, k, 1.0);
        /* per lit candidate per unit, over the first value's: the lit counts
         * differ with a scene key (a light's size moves the shadow) */
        double scale = lit[0] > 0 && lit[k] > 0 && o->values[0] != 0.0 && o->values[k] != 0.0
                           ? (double)lit[0] / (double)lit[k] * o->values[0] / o->values[k] : NAN; /* a 0: no unit */
        double pvr = round_ratio(eval, rounds, n, k, scale), fpvr = round_ratio(frame, rounds, n, k, scale);
        char row[4096], end[1024];
        where(sj, lab_scene(labs[k]), o->c.threads, end, sizeof end);
        snprintf(row, sizeof row, "%s,%s,%s,%.4f,%.4f,%ld,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%llu,%.3f,%s", sj->t->name,
                 o->axis, o->value_text[k], f * 1e3, e * 1e3, lit[k], per_sample, per_value, fr, er, fpvr, pvr,
                 (unsigned long long)patches[k], per_patch, end);
        printf("  %-18s %s %-8s frame %9.3f ms, eval %9.3f ms, %9.2f ns per lit sample, %8.3f per unit; "
               "ratios to the first: frame %.3f, eval %.3f, per sample per unit: frame %.3f, eval %.3f; "
               "%.2f ns per micropatch\n",
               sj->t->name, o->axis, o->value_text[k], f * 1e3, e * 1e3, per_sample, per_value, fr, er, fpvr, pvr,
               per_patch);
        ok = append(o, "sweep.csv", SWEEP_HEADER, row, err);
    }
    for (int k = 0; k < n; k++)
        if (k == 0 || pi < 0) lab_close(labs[k]);
    return ok;
}

/* ---- error against time at pcss's penumbra RMSE (issue 16) -------------------- */

/* The prefiltered PCSS family of course §5.2.2 that issue 16 sets against pcss. */
#define MATCHED_SMALLEST_MAP 64 /* texels per side */
static const char *const matched_family[] = {"pcss", "pcss_prefiltered", "cssm", "vssm", "essm",
                                             "evssm", "moment_soft", "dpcf"};

static bool in_matched_family(const char *name)
{
    for (size_t i = 0; i < sizeof matched_family / sizeof matched_family[0]; i++)
        if (strcmp(matched_family[i], name) == 0) return true;
    return false;
}

/* One configuration of a curve: its penumbra error (once: it does not vary)
 * and, per round, its frame time. */
typedef struct CurvePoint {
    int map_size;
    double params[TECH_MAX_PARAMS];
    double rmse, noise_rms;
    long samples;
    double frame[64], eval[64];
} CurvePoint;

/* The penumbra RMSE of one configuration against the Embree reference
 * (o->samples light samples, r2, seed 1; the disk cache). */
static bool penumbra_error(const Options *o, Lab *lab, const Technique *t, CurvePoint *cp, Error *err)
{
    char cache[1024];
    refcache_default_dir(cache, sizeof cache);
    CompareRequest req = {.tech = t, .params = cp->params, .light_index = 0, .repeat = 1, .warmup = 0,
                          .reference = true, .ref = {MEASURE_VISIBILITY, o->samples, SAMPLING_R2, 1},
                          .cache_dir = cache};
    CompareResult res;
    if (!lab_compare(lab, &req, &res, err)) return false;
    const ErrorStats *pen = &res.metrics.region[REGION_PENUMBRA];
    cp->rmse = pen->rmse;
    cp->noise_rms = pen->noise_rms;
    cp->samples = pen->count;
    compare_result_free(&res);
    return true;
}

/* The frame (eval: evaluation) time at RMSE `target` on a curve in order of
 * map size, in one round: log-log interpolation on the first segment that brackets it; the
 * first point's time where that point is already at or below it (an upper
 * bound); NaN where no point reaches it. *how says which. */
static double time_at_rmse(const CurvePoint *c, int n, int round, bool eval, double target, const char **how)
{
    *how = "no";
    if (n > 0 && c[0].rmse <= target) {
        *how = "at_first_point";
        return eval ? c[0].eval[round] : c[0].frame[round];
    }
    for (int k = 0; k + 1 < n; k++) {
        double ra = c[k].rmse, rb = c[k + 1].rmse;
        if (!(ra > target && rb <= target)) continue; /* NaN rmse: not a bracket */
        *how = "interpolated";
        double ta = eval ? c[k].eval[round] : c[k].frame[round];
        double tb = eval ? c[k + 1].eval[round] : c[k + 1].frame[round];
        double u = ra == rb ? 0.0 : (log(target) - log(ra)) / (log(rb) - log(ra)); /* ra > target >= rb > 0 */
        return exp(log(ta) + u * (log(tb) - log(ta)));
    }
    return NAN;
}

/* time_at_rmse's answer, as printed before the times. */
static const char *reach_text(const char *how)
{
    if (strcmp(how, "no") == 0) return "NOT REACHED by any map size, ";
    return strcmp(how, "at_first_point") == 0 ? "below it already at its smallest map (an upper bound), " : "";
}

/* A kernel cap in texels (`max_radius`, pcss and the filtered-soft family)
 * caps the penumbra's width in world units at texels x texel size: read as
 * at pcss's default 1024^2 map and scaled with the map, so every point of a
 * curve has the same world-space cap (unscaled, a 2048^2 map halves it:
 * overlap, pcss, penumbra RMSE 0.114 at 1024^2, 0.178 at 2048^2 unscaled,
 * 0.116 scaled). Clamped to its range: the filtered-soft family's 31.5
 * texels (its summed-area tables' padding) still halve the cap at 2048^2. */
static void scale_max_radius(const Technique *t, int map_size, double *params)
{
    int k = tech_param_index(t, "max_radius");
    if (k < 0) return;
    const ParamDesc *d = &t->params[k];
    double r = params[k] * map_size / 1024.0;
    params[k] = r < d->min ? d->min : r > d->max ? d->max : r;
}

/* The subject's curve over map sizes 64 ... 2048 (--quick: ... 1024) and
 * pcss at its defaults (the target: its penumbra RMSE and frame time), in
 * one Lab at 240 x 180 (--quick: 160 x 120), timed alternately in every
 * round; the time the subject needs at pcss's RMSE over pcss's time is the
 * median of the per-round ratios. A map size the subject refuses is noted
 * and left out of the curve. */
static bool matched(const Options *o, Subject *sj, Error *err)
{
    static const int maps[] = {MATCHED_SMALLEST_MAP, 128, 256, 512, 1024, 2048};
    int nmaps = o->quick ? 5 : 6, rounds = o->c.repeat > 64 ? 64 : o->c.repeat;
    const char *ov[] = {o->quick ? "camera.width=160" : "camera.width=240",
                        o->quick ? "camera.height=120" : "camera.height=180"};
    Subject base;
    const Technique *pcss = tech_find("pcss", err);
    if (!pcss || !subject_init(o, pcss, &base, err)) return false;
    Lab *lab = open_lab(o, sj, ov, 2, err);
    if (!lab) return false;
    CurvePoint *c = calloc((size_t)nmaps + 1, sizeof *c), *target = NULL;
    char note[1200] = "", curve_note[64] = "", end[1024];
    int n = 0, ms = tech_param_index(sj->t, "map_size");
    bool ok = c != NULL && ms >= 0;
    if (!c) error_set(err, "out of memory");
    else if (ms < 0) error_set(err, "%s has no map_size to sweep", sj->t->name);
    for (int k = 0; ok && k < nmaps; k++) {
        CurvePoint *cp = &c[n];
        memcpy(cp->params, sj->params, sizeof cp->params);
        cp->map_size = maps[k];
        cp->params[ms] = maps[k];
        scale_max_radius(sj->t, maps[k], cp->params);
        Error refusal;
        if (penumbra_error(o, lab, sj->t, cp, &refusal)) {
            n++;
        } else if (!note[0]) {
            char why[1100];
            snprintf(why, sizeof why, "map_size %d REFUSED (%s)", maps[k], refusal.msg);
            bench_csv_field(note, sizeof note, why);
            /* no comma: report.sh's plots split matched_curve.csv on commas */
            snprintf(curve_note, sizeof curve_note, "map_size %d REFUSED (matched.csv says why)", maps[k]);
            printf("  %-18s map_size %d REFUSED (%s)\n", sj->t->name, maps[k], refusal.msg);
        }
    }
    if (ok && n == 0) ok = error_set(err, "%s refused every map size", sj->t->name);
    if (ok) {
        target = &c[n];
        memcpy(target->params, base.params, sizeof target->params);
        target->map_size = (int)base.params[tech_param_index(pcss, "map_size")];
        ok = penumbra_error(o, lab, pcss, target, err);
    }
    if (ok) announce(o, sj, "matched");
    for (int r = 0; ok && r < rounds; r++)
        for (int k = 0; ok && k <= n; k++) {
            Point p;
            ok = measure(lab, k < n ? sj->t : pcss, c[k].params, 1, &p, err);
            c[k].frame[r] = p.frame_s;
            c[k].eval[r] = p.eval_s;
        }
    if (ok) where(sj, lab_scene(lab), o->c.threads, end, sizeof end);
    for (int k = 0; ok && k < n; k++) {
        char row[4096];
        double f = bench_median(c[k].frame, rounds), e = bench_median(c[k].eval, rounds);
        snprintf(row, sizeof row, "%s,%d,%.6f,%.6f,%ld,%.4f,%.4f,%s,%s", sj->t->name, c[k].map_size, c[k].rmse,
                 c[k].noise_rms, c[k].samples, f * 1e3, e * 1e3, k == 0 ? curve_note : "", end);
        printf("  %-18s map_size %4d: penumbra RMSE %.5f (reference noise %.5f, %ld samples), frame %9.3f ms\n",
               sj->t->name, c[k].map_size, c[k].rmse, c[k].noise_rms, c[k].samples, f * 1e3);
        ok = append(o, "matched_curve.csv", CURVE_HEADER, row, err);
    }
    if (ok) {
        double ratio[2][64], at[2][64]; /* frame, evaluation */
        const char *how = "no";
        for (int r = 0; r < rounds; r++)
            for (int e = 0; e < 2; e++) {
                at[e][r] = time_at_rmse(c, n, r, e, target->rmse, &how);
                ratio[e][r] = at[e][r] / (e ? target->eval[r] : target->frame[r]);
            }
        double pcss_ms = bench_median(target->frame, rounds) * 1e3;
        double pcss_eval_ms = bench_median(target->eval, rounds) * 1e3;
        double at_ms = bench_median(at[0], rounds) * 1e3, rt = bench_median(ratio[0], rounds);
        double at_eval_ms = bench_median(at[1], rounds) * 1e3, rt_eval = bench_median(ratio[1], rounds);
        char row[4096];
        snprintf(row, sizeof row, "%s,%.6f,%.4f,%.4f,%.3f,%.4f,%.4f,%.3f,%s,%s,%s", sj->t->name, target->rmse, pcss_ms,
                 at_ms, rt, pcss_eval_ms, at_eval_ms, rt_eval, how, note, end);
        printf("  %-18s at pcss's penumbra RMSE %.5f (pcss %d^2, frame %.3f ms, eval %.3f ms): %sframe %.3f ms, "
               "ratio %.3f; eval %.3f ms, ratio %.3f\n", sj->t->name, target->rmse, target->map_size, pcss_ms,
               pcss_eval_ms,
               reach_text(how), at_ms, rt, at_eval_ms, rt_eval);
        ok = append(o, "matched.csv", MATCHED_HEADER, row, err);
    }
    free(c);
    lab_close(lab);
    return ok;
}

/* ---- thread scaling ------------------------------------------------------------ */

typedef struct Scaling {
    Lab *lab;
    const Subject *sj; /* its t NULL: the reference */
    const BenchCurve *c;
    /* a technique's evaluation CPU seconds (lab.h) at point k in run i, the
     * warm-up round's first: cpu[k * (rounds + 1) + i], busiest likewise;
     * calls[k] the runs so far */
    double *cpu, *busiest;
    int calls[BENCH_MAX_CURVE];
    int repeat; /* evaluations a timed point takes the median of (0: not yet fixed) */
} Scaling;

/* A point's evaluations together take about this long at one thread, at most
 * SCALING_MAX_REPEAT of them (seconds). */
#define SCALING_MIN_S 0.1
#define SCALING_MAX_REPEAT 32

/* Evaluations per timed point: enough that one thread's take SCALING_MIN_S,
 * from the first (warm-up) evaluation's time eval_s. */
static int scaling_repeat(double eval_s)
{
    double n = eval_s > 0.0 ? ceil(SCALING_MIN_S / eval_s) : SCALING_MAX_REPEAT; /* below the clock: the most */
    return n < 1.0 ? 1 : n > SCALING_MAX_REPEAT ? SCALING_MAX_REPEAT : (int)n;
}

/* The point of s's curve at `threads`. */
static int curve_point(const Scaling *s, int threads)
{
    int k = 0;
    while (k < s->c->points - 1 && s->c->threads[k] != threads) k++;
    return k;
}

/* The curves' control side: a fixed register-only loop split over the
 * threads (bench_spin_parallel_s), about 10 ms on one thread, timed in the
 * same rounds as the subject: its speed-up is what the machine gave that
 * many busy threads at those moments, the bound beside the subject's. */
#define CONTROL_SPIN_ITERS 6000000L
enum { SIDE_SUBJECT, SIDE_CONTROL, NUM_SIDES };

/* One timed evaluation (or reference computation), or the control; BenchTimedFn. */
static bool scaled_once(void *ctx, int side, int threads, double *seconds, Error *err)
{
    Scaling *s = ctx;
    if (side == SIDE_CONTROL) {
        *seconds = bench_spin_parallel_s(CONTROL_SPIN_ITERS);
        return true;
    }
    if (s->sj->t) {
        Point p;
        if (!measure(s->lab, s->sj->t, s->sj->params, s->repeat > 0 ? s->repeat : 1, &p, err)) return false;
        *seconds = p.eval_s;
        int k = curve_point(s, threads), i = s->calls[k]++;
        if (s->repeat == 0) s->repeat = scaling_repeat(p.eval_s); /* the warm-up at one thread */
        s->cpu[k * (s->c->rounds + 1) + i] = p.cpu_s;
        s->busiest[k * (s->c->rounds + 1) + i] = p.busiest_s;
        return true;
    }
    ResourceManager *rm = lab_resources(s->lab);
    const Scene *sc = lab_scene(s->lab);
    const RtScene *bvh = res_bvh(rm, sc, RT_CASTERS, err);
    const ViewSamples *vs = bvh ? res_view_samples(rm, sc, err) : NULL;
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, err) : NULL;
    ReferenceParams prm = {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1, false};
    Reference ref;
    double t0 = timer_now_s();
    bool ok = cls && reference_compute(bvh, sc, 0, vs, cls, &prm, &ref, err);
    *seconds = timer_now_s() - t0;
    if (ok) reference_free(&ref);
    return ok;
}

/* Median milliseconds of a technique's timed runs at point k (v: s->cpu or s->busiest). */
static double cpu_median_ms(const Scaling *s, const double *v, int k)
{
    return bench_median(v + k * (s->c->rounds + 1) + 1, s->c->rounds) * 1e3;
}

/* A technique's CPU columns at point k (empty for the reference): CPU
 * milliseconds on 1 thread and on k, the busiest thread's, and the
 * speed-up they bound, cpu(1) / busiest(k), which the load does not move. */
static void cpu_columns(const Scaling *s, int k, char *out, size_t n, double *bound)
{
    *bound = NAN;
    if (!s->sj->t) {
        snprintf(out, n, ",,,");
        return;
    }
    double cpu1 = cpu_median_ms(s, s->cpu, 0), busiest = cpu_median_ms(s, s->busiest, k);
    *bound = busiest > 0.0 ? cpu1 / busiest : NAN; /* below the CPU clock's resolution: unknown */
    snprintf(out, n, "%.4f,%.4f,%.4f,%.3f", cpu1, cpu_median_ms(s, s->cpu, k), busiest, *bound);
}

/* One row per point of the curve (threads = that point's count). */
static bool scaling_rows(const Options *o, const Scaling *s, const BenchCurve *c, Error *err)
{
    const char *name = s->sj->t ? s->sj->t->name : "reference";
    bool ok = true;
    double ms1 = bench_curve_median_s(c, SIDE_SUBJECT, 0) * 1e3;
    printf("  %-18s 1 thread %9.3f ms (median of %d)", name, ms1, s->repeat > 0 ? s->repeat : 1);
    for (int k = 0; ok && k < c->points; k++) {
        char row[2048], end[1024], cpu[256];
        double msk = bench_curve_median_s(c, SIDE_SUBJECT, k) * 1e3, speedup = bench_curve_speedup(c, SIDE_SUBJECT, k);
        double machine = bench_curve_speedup(c, SIDE_CONTROL, k);
        double over = bench_curve_relative(c, SIDE_SUBJECT, SIDE_CONTROL, k), bound;
        where(s->sj, lab_scene(s->lab), c->threads[k], end, sizeof end);
        cpu_columns(s, k, cpu, sizeof cpu, &bound);
        snprintf(row, sizeof row, "%s,%.4f,%.4f,%.3f,%s,%.3f,%.3f,%d,%s", name, ms1, msk, speedup, cpu, machine, over,
                 s->repeat > 0 ? s->repeat : 1, end);
        if (k > 0) printf("; %d: %.3f ms, speed-up %.2f (machine %.2f)", c->threads[k], msk, speedup, machine);
        if (k > 0 && s->sj->t)
            printf(" (CPU bound %.2f, CPU %.2fx of 1 thread's)", bound,
                   cpu_median_ms(s, s->cpu, k) / cpu_median_ms(s, s->cpu, 0));
        ok = append(o, "threads_eval.csv", THREADS_HEADER, row, err);
    }
    printf("\n");
    return ok;
}

/* The subject's (or the reference's, sj->t NULL) curve at 640 x 480. */
static bool scaling(const Options *o, Subject *given, Error *err)
{
    Subject quick = *given, *sj = &quick;
    if (sj->t && o->quick) lower_map_size(o, sj, QUICK_MAP_SIZE); /* the curve is the evaluation's */
    const char *ov[] = {"camera.width=640", "camera.height=480"};
    Scaling s = {.sj = sj};
    if (sj->t) s.lab = open_lab(o, sj, ov, 2, err);
    else s.lab = lab_open(o->scene, ov, 2, err);
    if (!s.lab) return false;
    if (!sj->t) snprintf(sj->light.text, sizeof sj->light.text, "%s", light_kind_name(lab_scene(s.lab)->lights[0].kind));
    if (sj->t) announce(o, sj, "threads");
    BenchCurve c;
    bool ok = bench_curve_init(&c, o->c.threads, NUM_SIDES, o->c.repeat, err);
    size_t runs = ok ? (size_t)c.points * (size_t)(c.rounds + 1) : 0;
    s.c = &c;
    s.cpu = runs ? calloc(2 * runs, sizeof *s.cpu) : NULL;
    s.busiest = s.cpu ? s.cpu + runs : NULL;
    if (ok && !s.cpu) ok = error_set(err, "out of memory");
    ok = ok && bench_curve_measure(&c, scaled_once, &s, err) && scaling_rows(o, &s, &c, err);
    free(s.cpu);
    bench_curve_free(&c);
    lab_close(s.lab);
    return ok;
}

/* ---- work counters against hand counts ------------------------------------- */

/* The hand count of a technique's evaluation, per lit candidate, where its
 * rule is known (false: none): texel fetches and rays, and the rule. */
static bool hand_count(const Technique *t, const double *params, double *texels, double *rays, const char **rule)
{
    int K = tech_param_index(t, "K"), kernel = tech_param_index(t, "kernel"), layers = tech_param_index(t, "layers");
    *texels = *rays = 0.0;
    if (strcmp(t->name, "pcf") == 0 && K >= 0 && kernel >= 0 && params[kernel] == 0.0) { /* kernel 0: box */
        *texels = params[K] * params[K];
        *rule = "K x K box: K^2 texels";
    } else if (strcmp(t->name, "sm") == 0 && (layers < 0 || params[layers] == 0.0)) { /* one layer */
        *texels = 1.0;
        *rule = "one texel";
    } else if (strcmp(t->name, "hard") == 0 || strcmp(t->name, "single_sample_rt") == 0) {
        *rays = 1.0;
        *rule = "one ray";
    } else {
        return false;
    }
    return true;
}

static bool work_counts(const Options *o, Subject *sj, Error *err)
{
    static const char *const small[] = {"camera.width=160", "camera.height=120"};
    Lab *lab = open_lab(o, sj, small, 2, err);
    if (!lab) return false;
    RenderRequest req = {.tech = sj->t, .params = sj->params, .light_index = 0, .repeat = 1};
    RenderResult r;
    bool ok = lab_render(lab, &req, &r, err);
    if (ok) {
        const WorkCounters *e = &r.eval_work, *f = &r.frame_work;
        double n = r.lit_candidates > 0 ? (double)r.lit_candidates : NAN;
        double texels = (double)e->texel_fetches / n, rays = (double)e->rays / n, hand_t, hand_r;
        const char *rule = "";
        bool known = hand_count(sj->t, sj->params, &hand_t, &hand_r, &rule);
        bool agrees = known && texels == hand_t && rays == hand_r;
        printf("%-22s %8.2f texels/sample %6.2f rays/sample | frame %9llu triangles %9llu texels rasterised "
               "%10llu bytes built%s%s%s\n",
               sj->t->name, texels, rays, (unsigned long long)f->triangles, (unsigned long long)f->fragments,
               (unsigned long long)r.frame_bytes, known ? " | hand count: " : "", rule,
               known ? (agrees ? " (agrees)" : " (DISAGREES)") : "");
        char row[2048], tail[1024];
        where(sj, lab_scene(lab), omp_get_max_threads(), tail, sizeof tail);
        snprintf(row, sizeof row, "%s,%ld,%.4f,%.4f,%.4f,%llu,%llu,%llu,%llu,%zu,%s,%s%.4g,%s%.4g,%s,%s", sj->t->name,
                 r.lit_candidates, texels, (double)e->texel_bytes / n, rays, (unsigned long long)f->triangles,
                 (unsigned long long)f->fragments, (unsigned long long)f->texel_fetches,
                 (unsigned long long)f->rays, r.frame_bytes, rule, "", known ? hand_t : NAN, "",
                 known ? hand_r : NAN, known ? (agrees ? "yes" : "no") : "", tail);
        ok = append(o, "work.csv", WORK_HEADER, row, err);
        if (ok && known && !agrees)
            ok = error_set(err, "work counters disagree with the hand count (%s): %.4g texels, %.4g rays per sample",
                           rule, texels, rays);
        render_result_free(&r);
    }
    lab_close(lab);
    return ok;
}

/* ---- main ------------------------------------------------------------------ */

/* Which techniques a part measures (NULL in Part: every one). */
static bool constant_applies(const Options *o, const Technique *t) { (void)o; return has_sat(t); }
static bool lightsize_applies(const Options *o, const Technique *t) { (void)o; return soft_on_spheres(t); }
static bool sweep_applies(const Options *o, const Technique *t)
{
    return sweep_on_scene(o) || tech_param_index(t, o->axis) >= 0;
}
static bool matched_applies(const Options *o, const Technique *t)
{
    return o->num_techs > 0 || in_matched_family(t->name);
}

/* The parts of the bench (--only NAME), in the order a technique runs them:
 * each for the techniques `applies` admits; an `only_asked` part runs only
 * when --only names it. */
typedef struct Part {
    const char *name;
    bool only_asked;
    bool (*applies)(const Options *o, const Technique *t);
    bool (*run)(const Options *o, Subject *sj, Error *err);
} Part;

static const Part PARTS[] = {
    {"growth", false, NULL, growth},
    {"constant", false, constant_applies, constant_time},
    {"threads", false, NULL, scaling},
    {"lightsize", false, lightsize_applies, light_size},
    {"work", false, NULL, work_counts},
    {"sweep", true, sweep_applies, sweep_cost},
    {"matched", true, matched_applies, matched},
};
#define NUM_PARTS (int)(sizeof PARTS / sizeof PARTS[0])

static bool part_named(const char *name)
{
    for (int i = 0; i < NUM_PARTS; i++)
        if (strcmp(PARTS[i].name, name) == 0) return true;
    return false;
}

/* Whether part p runs for technique t. */
static bool part_runs(const Options *o, const Part *p, const Technique *t)
{
    bool asked = p->only_asked ? o->only && strcmp(o->only, p->name) == 0 : part(o, p->name);
    return asked && (!p->applies || p->applies(o, t));
}

/* The parts of one technique that --only asks for; its error printed, and
 * its wall time where a part ran (where a step's minutes go). */
static bool bench_technique(const Options *o, const Technique *t)
{
    Subject sj;
    Error err;
    double t0 = timer_now_s();
    bool ok = subject_init(o, t, &sj, &err), ran = false;
    for (int i = 0; ok && i < NUM_PARTS; i++) {
        if (!part_runs(o, &PARTS[i], t)) continue;
        ran = true;
        ok = PARTS[i].run(o, &sj, &err);
    }
    if (sj.refused) printf("%s: %d growth point(s) REFUSED (growth.csv's note column says why)\n", t->name, sj.refused);
    if (!ok) fprintf(stderr, "techniques: %s: FAILED: %s\n", t->name, err.msg);
    if (ran) printf("%s: %.1f s wall, builds included\n", t->name, timer_now_s() - t0);
    return ok;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o) || (o.only && !part_named(o.only))) {
        char usage[512] = "techniques [--only ";
        for (int i = 0; i < NUM_PARTS; i++) {
            strcat(usage, PARTS[i].name);
            strcat(usage, i + 1 < NUM_PARTS ? "|" : "] ");
        }
        strcat(usage, "[-t TECH]... [-p NAME=VALUE]... [--sweep NAME=V1,V2,...] [--samples N] [--threads N] "
                      "[--repeat R] [--quick] [-o DIR] [SCENE]");
        return bench_usage(usage);
    }
    omp_set_num_threads(o.c.threads);
    rt_set_threads(o.c.threads);
    int failed = 0, run = 0;
    if (part(&o, "threads") && wanted(&o, "reference")) {
        Subject ref = {.t = NULL, .settings = "samples=64"};
        Error err;
        run++;
        if (!scaling(&o, &ref, &err)) {
            fprintf(stderr, "techniques: reference: FAILED: %s\n", err.msg);
            failed++;
        }
    }
    for (int i = 0; i < tech_count(); i++) {
        if (!wanted(&o, tech_at(i)->name)) continue;
        run++;
        failed += !bench_technique(&o, tech_at(i));
    }
    if (failed) fprintf(stderr, "techniques: %d of %d FAILED (the others' rows are written)\n", failed, run);
    return failed ? 1 : 0;
}
