/* sweep_reuse.c -- what a sweep reuses (issue 8, item 4).
 *   K sweep: 10 values of K of `pcf` and of `vsm` (prefilter=sat) in one Lab:
 *     the sweep's wall time against one build of its resources plus 10
 *     evaluations (target <= 1.1), and the resource log: one build, then
 *     reuse (vsm's SAT serves every K).
 *   light-radius sweep: references for 5 radii computed into a fresh disk
 *     cache, then the same sweep again in new Labs: every reference must be
 *     a cache hit (no ray traced) and the second pass's reference time is
 *     reported against the first's.
 * Rows: DIR/sweep_reuse.csv. Usage: sweep_reuse [--threads N] [-o DIR] [SCENE] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "bench.h"
#include "core/fsutil.h"
#include "core/timer.h"
#include "lab/compare.h"

#define NUM_K 10
#define NUM_RADII 5
#define REUSE_BOUND 1.1
#define HEADER "sweep,technique,points,sweep_ms,one_build_ms,evals_ms,ratio,bound,builds,reuses,within," \
               BENCH_TAIL_HEADER "\n"

typedef struct Options {
    const char *scene, *dir;
    int threads;
} Options;

typedef struct SweepResult {
    double sweep_s, build_s, evals_s;
    int builds, reuses;
} SweepResult;

static bool write_row(const Options *o, const char *sweep, const char *tech, int points, const SweepResult *r,
                      double ratio, bool within, Error *err)
{
    char row[1024], tail[512], path[4096];
    bench_tail(tail, sizeof tail, o->threads);
    snprintf(row, sizeof row, "%s,%s,%d,%.3f,%.3f,%.3f,%.3f,%.1f,%d,%d,%s,%s\n", sweep, tech, points,
             r->sweep_s * 1e3, r->build_s * 1e3, r->evals_s * 1e3, ratio, REUSE_BOUND, r->builds, r->reuses,
             within ? "yes" : "no", tail);
    snprintf(path, sizeof path, "%s/sweep_reuse.csv", o->dir);
    return bench_csv_append(path, HEADER, row, err);
}

/* K = 1, 3, ..., 19 of one technique in one Lab, each point one timed
 * evaluation, as a Lua sweep runs it. */
static bool k_sweep(Lab *lab, const char *name, const char *setting, SweepResult *r, Error *err)
{
    const Technique *t = tech_find(name, err);
    double params[TECH_MAX_PARAMS];
    if (!t) return false;
    tech_params_default(t, params);
    if (setting && !tech_param_parse(t, setting, params, err)) return false;
    *r = (SweepResult){0};
    double t0 = timer_now_s();
    for (int i = 0; i < NUM_K; i++) {
        params[tech_param_index(t, "K")] = 2 * i + 1;
        RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
        RenderResult res;
        if (!lab_render(lab, &req, &res, err)) return false;
        for (int k = 0; k < res.num_tech_resources; k++) {
            r->builds += res.tech_resources[k].built;
            r->reuses += !res.tech_resources[k].built;
        }
        if (i == 0) r->build_s = res.tech_build_s;
        r->evals_s += res.eval_median_s;
        render_result_free(&res);
    }
    r->sweep_s = timer_now_s() - t0;
    return true;
}

static bool bench_k(const Options *o, const char *name, const char *setting, Error *err)
{
    Lab *lab = lab_open(o->scene, NULL, 0, err);
    if (!lab) return false;
    /* The view samples and classes are the engine's, not the sweep's: made first. */
    ResourceManager *rm = lab_resources(lab);
    bool ok = res_view_samples(rm, lab_scene(lab), err) && res_classes(rm, lab_scene(lab), 0, err);
    SweepResult r;
    ok = ok && k_sweep(lab, name, setting, &r, err);
    lab_close(lab);
    if (!ok) return false;
    double ratio = r.sweep_s / (r.build_s + r.evals_s);
    printf("  K sweep of %s (%d points): %.1f ms against one build %.1f ms + evaluations %.1f ms: %.3f (bound %.1f); "
           "%d builds, %d reuses\n",
           name, NUM_K, r.sweep_s * 1e3, r.build_s * 1e3, r.evals_s * 1e3, ratio, REUSE_BOUND, r.builds, r.reuses);
    return write_row(o, "K", name, NUM_K, &r, ratio, ratio <= REUSE_BOUND, err);
}

/* One pass of references over the radii; counts cache hits and rays. */
static bool radius_pass(const Options *o, const char *cache, int *hits, long long *rays, double *seconds, Error *err)
{
    static const double radii[NUM_RADII] = {0.05, 0.1, 0.2, 0.4, 0.8};
    *hits = 0;
    *rays = 0;
    *seconds = 0.0;
    for (int i = 0; i < NUM_RADII; i++) {
        char ov[64];
        snprintf(ov, sizeof ov, "lights[1].radius=%g", radii[i]);
        const char *ovs[] = {ov, "camera.width=240", "camera.height=180"};
        Lab *lab = lab_open(o->scene, ovs, 3, err);
        if (!lab) return false;
        CompareRequest req = {.light_index = 0, .reference = true,
                              .ref = {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1, false}, .cache_dir = cache};
        CompareResult res;
        bool ok = lab_compare(lab, &req, &res, err);
        if (ok) {
            *hits += res.ref_info.origin == REF_CACHE_HIT;
            *rays += res.ref_info.origin == REF_CACHE_HIT ? 0 : res.ref->rays;
            *seconds += res.ref_info.seconds;
            compare_result_free(&res);
        }
        lab_close(lab);
        if (!ok) return false;
    }
    return true;
}

static bool bench_radius(const Options *o, Error *err)
{
    char cache[] = "/tmp/shadowlab-bench-cache-XXXXXX";
    if (!mkdtemp(cache)) return error_set(err, "cannot make a temporary cache folder");
    int hits1, hits2;
    long long rays1, rays2;
    double s1, s2;
    bool ok = radius_pass(o, cache, &hits1, &rays1, &s1, err) && radius_pass(o, cache, &hits2, &rays2, &s2, err);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", cache);
    if (system(cmd) != 0) fprintf(stderr, "sweep_reuse: note: could not remove %s\n", cache);
    if (!ok) return false;
    bool within = hits2 == NUM_RADII && rays2 == 0;
    printf("  light-radius sweep (%d radii): first pass %lld rays in %.1f ms, second pass %d cache hits, %lld rays, "
           "%.1f ms%s\n",
           NUM_RADII, rays1, s1 * 1e3, hits2, rays2, s2 * 1e3, within ? "" : "  RETRACED");
    SweepResult r = {s2, s1, 0.0, NUM_RADII - hits2, hits2};
    return write_row(o, "light_radius_cached_reference", "reference", NUM_RADII, &r, s2 / s1, within, err);
}

int main(int argc, char **argv)
{
    Options o = {"scenes/sphere-on-plane.lua", "reports/bench", omp_get_max_threads()};
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--threads") == 0 && bench_parse_int(v, 1, 256, &o.threads)) i++;
        else if (strcmp(argv[i], "-o") == 0 && v) o.dir = argv[++i];
        else if (argv[i][0] != '-') o.scene = argv[i];
        else {
            fprintf(stderr, "usage: sweep_reuse [--threads N] [-o DIR] [SCENE]\n");
            return 2;
        }
    }
    omp_set_num_threads(o.threads);
    rt_set_threads(o.threads);
    Error err;
    if (!bench_k(&o, "pcf", NULL, &err) || !bench_k(&o, "vsm", "prefilter=sat", &err) || !bench_radius(&o, &err)) {
        fprintf(stderr, "sweep_reuse: %s\n", err.msg);
        return 1;
    }
    return 0;
}
