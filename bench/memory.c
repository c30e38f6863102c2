/* memory.c -- peak resident memory against the resources' bytes (issue 8,
 * item 6): every registered technique that acquires a shadow_map (its
 * Technique.resources), at map_size = 4096, one face (projection=perspective),
 * rendered once in a child process of its own, on the scene as it is where
 * the technique handles light 1's kind, else with light 1 replaced by one of
 * a kind it handles (bench_lab_open; the row's light column says which). The
 * child's peak RSS (getrusage's ru_maxrss) against the bytes the resource
 * manager reports holding (rm_bytes: what the records list, the BVH, view
 * samples and classes included), target <= 1.2. The RSS before the scene is
 * loaded (the program and its libraries) is reported beside it. Where a
 * technique refuses the map size (a resource over its cap) it is measured at
 * the first of half, a quarter, ... (down to 256) it accepts, the row's note
 * saying what was refused; a technique that fails otherwise is reported and
 * the others still run (exit status 1 at the end).
 * Rows: DIR/memory.csv.
 * Usage: memory [-t TECH]... [--res R] [--threads N] [-o DIR] [SCENE] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bench.h"

#define MAX_ITEMS 32
#define MEMORY_BOUND 1.2
#define HEADER "technique,map_res,peak_rss_mib,resources_mib,ratio,bound,within,baseline_rss_mib,note,scene,light," \
               BENCH_TAIL_HEADER "\n"

typedef struct Options {
    const char *scene, *dir, *techs[MAX_ITEMS];
    int num_techs, res, threads;
} Options;

/* What a child reports back. */
typedef struct Usage {
    double peak_kib, baseline_kib, resources_bytes;
    BenchLight light;
    char error[256];
} Usage;

static double peak_kib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss; /* KiB on Linux */
}

/* In the child: load, render once, measure. */
static Usage child_run(const Options *o, const Technique *t, int res)
{
    Usage u = {.baseline_kib = peak_kib()};
    Error err = {0};
    double params[TECH_MAX_PARAMS];
    tech_params_default(t, params);
    int size = tech_param_index(t, "map_size"), proj = tech_param_index(t, "projection");
    if (size < 0) {
        snprintf(u.error, sizeof u.error, "no map_size parameter to set to %d", res);
        return u;
    }
    params[size] = res;
    if (proj >= 0 && t->params[proj].max >= MAP_PROJ_PERSPECTIVE) /* one face: a sphere light's default may be a cube */
        params[proj] = MAP_PROJ_PERSPECTIVE;
    Lab *lab = bench_lab_open(o->scene, t, NULL, 0, &u.light, &err);
    RenderRequest req = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    RenderResult r;
    if (lab && lab_render(lab, &req, &r, &err)) {
        u.resources_bytes = (double)rm_bytes(lab_resources(lab));
        u.peak_kib = peak_kib();
        render_result_free(&r);
    } else {
        snprintf(u.error, sizeof u.error, "%s", err.msg);
    }
    lab_close(lab);
    return u;
}

/* One child at map size `res`; false with *refused set where the technique
 * refused the render (its message in u->error), unset where the child failed. */
static bool measure(const Options *o, const Technique *t, int res, Usage *u, bool *refused, Error *err)
{
    int fd[2];
    if (pipe(fd) != 0) return error_set(err, "pipe failed");
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) return error_set(err, "fork failed");
    if (pid == 0) {
        close(fd[0]);
        Usage c = child_run(o, t, res);
        ssize_t w = write(fd[1], &c, sizeof c);
        _exit(w == (ssize_t)sizeof c ? 0 : 1);
    }
    close(fd[1]);
    ssize_t n = read(fd[0], u, sizeof *u);
    close(fd[0]);
    int status;
    waitpid(pid, &status, 0);
    *refused = false;
    if (n != (ssize_t)sizeof *u || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return error_set(err, "%s: the measuring child failed", t->name);
    *refused = u->error[0] != '\0';
    return !*refused || error_set(err, "%s", u->error);
}

/* The technique at --res, or where it refuses that, at the first of half,
 * a quarter, ... (down to 256) that it accepts. */
static bool bench_tech(const Options *o, const Technique *t, Error *err)
{
    Usage u;
    bool refused;
    char note[400] = "";
    int res = o->res;
    while (!measure(o, t, res, &u, &refused, err)) {
        if (!refused || res / 2 < 256) return false;
        if (!note[0]) bench_csv_field(note, sizeof note, err->msg);
        printf("  %-16s %d^2 REFUSED (%s); trying %d^2\n", t->name, res, err->msg, res / 2);
        res /= 2;
    }
    double peak = u.peak_kib / 1024.0, bytes = u.resources_bytes / 1048576.0, ratio = peak / bytes;
    bool within = ratio <= MEMORY_BOUND;
    printf("  %-16s %d^2 (light 1: %s): peak RSS %8.1f MiB, resources %8.1f MiB, ratio %.3f (bound %.1f; %.1f MiB "
           "before loading)%s\n", t->name, res, u.light.text, peak, bytes, ratio, MEMORY_BOUND,
           u.baseline_kib / 1024.0, within ? "" : "  OVER");
    char row[2048], tail[512], path[4096], light[200], scene[300];
    bench_tail(tail, sizeof tail, o->threads);
    bench_csv_field(light, sizeof light, u.light.text);
    bench_csv_field(scene, sizeof scene, o->scene);
    snprintf(row, sizeof row, "%s,%d,%.2f,%.2f,%.3f,%.1f,%s,%.2f,%s,%s,%s,%s\n", t->name, res, peak, bytes, ratio,
             MEMORY_BOUND, within ? "yes" : "no", u.baseline_kib / 1024.0, note, scene, light, tail);
    snprintf(path, sizeof path, "%s/memory.csv", o->dir);
    return bench_csv_append(path, HEADER, row, err);
}

/* A map technique (one that acquires a shadow_map) that -t selects. */
static bool wanted(const Options *o, const Technique *t)
{
    if (!tech_acquires(t, "shadow_map")) return false;
    for (int i = 0; i < o->num_techs; i++)
        if (strcmp(o->techs[i], t->name) == 0) return true;
    return o->num_techs == 0;
}

int main(int argc, char **argv)
{
    Options o = {.scene = "scenes/sphere-on-plane.lua", .dir = "reports/bench", .res = 4096,
                 .threads = omp_get_max_threads()};
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = true;
        if (strcmp(argv[i], "-t") == 0 && v && o.num_techs < MAX_ITEMS) o.techs[o.num_techs++] = argv[++i];
        else if (strcmp(argv[i], "--res") == 0) ok = bench_parse_int(v, 16, 16384, &o.res) && ++i;
        else if (strcmp(argv[i], "--threads") == 0) ok = bench_parse_int(v, 1, 256, &o.threads) && ++i;
        else if (strcmp(argv[i], "-o") == 0 && v) o.dir = argv[++i];
        else if (argv[i][0] != '-') o.scene = argv[i];
        else ok = false;
        if (!ok) {
            fprintf(stderr, "usage: memory [-t TECH]... [--res R] [--threads N] [-o DIR] [SCENE]\n");
            return 2;
        }
    }
    omp_set_num_threads(o.threads);
    rt_set_threads(o.threads);
    int failed = 0, run = 0;
    for (int i = 0; i < tech_count(); i++) {
        Error err;
        if (!wanted(&o, tech_at(i))) continue;
        run++;
        if (bench_tech(&o, tech_at(i), &err)) continue;
        fprintf(stderr, "memory: %s: FAILED: %s\n", tech_at(i)->name, err.msg);
        failed++;
    }
    if (failed) fprintf(stderr, "memory: %d of %d FAILED (the others' rows are written)\n", failed, run);
    return failed ? 1 : 0;
}
