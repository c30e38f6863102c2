/* stability.c -- `shadowlab stability [-t TECH] [-o DIR]`: every registered
 * technique (or one) on every extreme case of the suite (lab/stability.h),
 * one line per run as it finishes, then the closing count; with -o the
 * report (stability.{json,csv,md}) and every case's scene file. Exit status
 * 0 when every applicable run passed, 1 otherwise, 2 on a usage error. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <unistd.h>
#include "cli/cli.h"
#include "core/array.h"
#include "core/progress.h"
#include "lab/stability.h"

static const CliAccept stability_options[] = {
    {OPT_TECHNIQUE, "only this technique (engine input cases are then skipped)"},
    {OPT_OUT, "write DIR/stability.{json,csv,md} and DIR/scenes/<case>-<light>/scene.lua\n"
              "(parameter rows: DIR/scenes/params-<light>/scene.lua)"},
    {OPT_CASE, "only cases whose name contains TEXT; TEXT,TEXT: any of them; !TEXT: not those\n"
               "(--case '!image_4096': every case but that one)"},
    {OPT_QUICK, "make test's matrix: 40 x 30 views, 16 reference samples (none for heavy\n"
                "cases), map sizes capped at 128 texels except in their own probes, one row\n"
                "per parameter for all its probes; every case runs"},
    {OPT_SAMPLE, "only the runs whose hash of (technique, case, light) falls in class K of M: every\n"
                 "technique keeps about 1/M of its rows (make test's sanitized pass); !K/M: every\n"
                 "class but K (make test's optimised pass)"},
    {OPT_TIMEOUT, NULL},
    {OPT_THREADS, "threads per run (default: the cores divided among --jobs)"},
    {OPT_JOBS, NULL},
    {OPT_LIST, "list the cases and exit (takes no other option)"},
    {OPT_END, NULL}};

static const CliCommand stability_cmd = {
    "stability", "[-t TECH] [-o DIR] [options]", false, stability_options,
    "every technique of the registry (or -t TECH) on every extreme case that applies to it:\n"
    "output finite and in [0,1], documented limits, refusals of invalid input; each run in\n"
    "its own process with a time bound, forked from one that built what the runs on a case\n"
    "share (scene, BVH, view samples, reference)\n"};

typedef struct Rows {
    StabResult *rows;
    int n, cap;
    bool oom;
    Progress *progress; /* "stability 12 done, 40.2 s" on a terminal */
} Rows;

static void print_row(const StabResult *r)
{
    progress_clear();
    char err[64] = "";
    if (isfinite(r->mae)) snprintf(err, sizeof err, "MAE %.4f max %.3f", r->mae, r->max_abs);
    printf("%-4s %-10s %-34s %-13s %-24s %6.2f s  %s\n", stab_status_name(r->status), r->technique, r->case_name,
           r->light, err, r->seconds, r->detail);
    fflush(stdout);
}

static void on_row(const StabResult *r, void *user)
{
    Rows *rs = user;
    print_row(r);
    progress_add(rs->progress, 1);
    StabResult *rows = array_room(rs->rows, rs->n, &rs->cap, sizeof *rows, 256);
    if (!rows) {
        rs->oom = true;
        return;
    }
    rs->rows = rows;
    rs->rows[rs->n++] = *r;
}

static void list_cases(void)
{
    for (int i = 0; i < stab_case_count(); i++) printf("%-34s %s\n", stab_case_name(i), stab_case_doc(i));
    printf("%-34s %s\n", "param_NAME", "--quick: every probe below of the parameter in one row");
    printf("%-34s %s\n", "param_NAME_{min,min_plus_1,max}", "each parameter at its bounds: finite output in [0,1]");
    printf("%-34s %s\n", "param_NAME_at_{42,44.36,88.72}",
           "floats whose range holds float32's exponential limits (EVSM 42, exp(2c), exp(c)): finite output");
    printf("%-34s %s\n", "param_NAME_{below_min,above_max}", "just outside: refused naming the parameter and its range");
    printf("%-34s %s\n", "param_NAME_nonfinite", "NaN and +-Inf refused, also when handed raw to lab_render");
}

/* Run the suite into rows; the scratch folder lives only for the run. */
static bool run_suite(const CliOptions *c, const Technique *t, Rows *rows, Error *err)
{
    char work[] = "/tmp/shadowlab-stability-XXXXXX", scenes[1100];
    if (!mkdtemp(work)) return error_set(err, "cannot create a scratch folder in /tmp");
    snprintf(scenes, sizeof scenes, "%s/scenes", c->out_dir ? c->out_dir : "");
    StabOptions o = {.quick = c->quick, .timeout_s = c->timeout_s, .threads = c->threads, .only = c->case_filter,
                     .work_dir = work, .scene_dir = c->out_dir ? scenes : NULL, .jobs = c->jobs,
                     .sample_k = c->sample_k, .sample_m = c->sample_m, .sample_invert = c->sample_invert};
    const Technique *one[1] = {t};
    Progress prog; /* no heartbeat: stab_run forks, so this process stays single-threaded */
    progress_begin(&prog, "stability", 0);
    rows->progress = &prog;
    bool ok = stab_run(t ? one : NULL, t ? 1 : 0, t == NULL, &o, on_row, rows, err);
    progress_end(&prog);
    rmdir(work);
    if (ok && rows->oom) ok = error_set(err, "out of memory for the rows");
    if (ok && c->out_dir) ok = stab_report_write(c->out_dir, rows->rows, rows->n, &o, err);
    return ok;
}

int cmd_stability(int argc, char **argv)
{
    CliOptions c;
    Error err;
    bool ok = cli_parse(&stability_cmd, argc, argv, &c, &err);
    if (ok && c.list && c.given != 1ull << OPT_LIST) ok = error_set(&err, "--list takes no other option");
    if (!ok) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (c.help) {
        cli_print_help(&stability_cmd, stdout);
        return EXIT_OK;
    }
    if (c.list) {
        list_cases();
        return EXIT_OK;
    }
    const Technique *t = c.technique ? tech_find(c.technique, &err) : NULL;
    if (c.technique && !t) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_USAGE;
    }
    Rows rows = {0};
    ok = run_suite(&c, t, &rows, &err);
    StabCounts n = stab_count(rows.rows, rows.n);
    free(rows.rows);
    if (!ok) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_RUNTIME;
    }
    if (c.out_dir) printf("report: %s/stability.{json,csv,md}\n", c.out_dir);
    printf("not applicable: %d\n", n.na);
    printf("known limitations (documented, not counted as passed): %d\n", n.known);
    printf("stability: %d passed, %d failed\n", n.pass, n.fail);
    return n.fail ? EXIT_RUNTIME : EXIT_OK;
}
