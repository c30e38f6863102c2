/* stability.c -- `shadowlab stability [-t TECH] [-o DIR]`: every registered
 * technique (or one) on every extreme case of the suite (lab/stability.h),
 * one line per run as it finishes, then the closing count; with -o the
 * report (stability.{json,csv,md}) and every case's scene file. Exit status
 * 0 when every applicable run passed, 1 otherwise, 2 on a usage error. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli/cli.h"
#include "lab/stability.h"

static const char *const stability_help =
    "usage: shadowlab stability [-t TECH] [-o DIR] [options]\n"
    "  every technique of the registry (or -t TECH) on every extreme case that applies to it:\n"
    "  output finite and in [0,1], documented limits, refusals of invalid input; each run in\n"
    "  its own process with a time bound, forked from one that built what the runs on a case\n"
    "  share (scene, BVH, view samples, reference)\n"
    "  -t, --technique NAME   only this technique (engine input cases are then skipped)\n"
    "  -o, --out DIR          write DIR/stability.{json,csv,md} and DIR/scenes/<case>-<light>/scene.lua\n"
    "                         (parameter rows: DIR/scenes/params-<light>/scene.lua)\n"
    "  --case TEXT            only cases whose name contains TEXT\n"
    "  --quick                make test's matrix: 40 x 30 views, 16 reference samples (none for heavy\n"
    "                         cases), map sizes capped at 128 texels except in their own probes, one row\n"
    "                         per parameter for all its probes; every case runs\n"
    "  --timeout S            per-run time bound in seconds (default 120)\n"
    "  --threads N            threads per run (default: the cores divided among --jobs)\n"
    "  --jobs N               runs at once (default 1)\n"
    "  --list                 list the cases and exit\n";

typedef struct StabCli {
    const char *tech, *out, *only;
    bool quick, list, help;
    double timeout_s;
    int threads, jobs;
} StabCli;

static bool parse_number(const char *opt, const char *s, double lo, double hi, double *out, Error *err)
{
    char *end;
    double v = s ? strtod(s, &end) : NAN;
    if (!s || end == s || *end || !(v >= lo && v <= hi))
        return error_set(err, "%s expects a number in [%g, %g], got '%s'", opt, lo, hi, s ? s : "(nothing)");
    *out = v;
    return true;
}

static bool parse_args(int argc, char **argv, StabCli *c, Error *err)
{
    memset(c, 0, sizeof *c);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        double num;
        if (!strcmp(a, "--quick")) c->quick = true;
        else if (!strcmp(a, "--list")) c->list = true;
        else if (!strcmp(a, "--help") || !strcmp(a, "-h")) c->help = true;
        else if (!v) return error_set(err, "%s: unknown option, or it expects a value", a);
        else if (!strcmp(a, "-t") || !strcmp(a, "--technique")) c->tech = argv[++i];
        else if (!strcmp(a, "-o") || !strcmp(a, "--out")) c->out = argv[++i];
        else if (!strcmp(a, "--case")) c->only = argv[++i];
        else if (!strcmp(a, "--timeout")) {
            if (!parse_number(a, argv[++i], 1, 86400, &c->timeout_s, err)) return false;
        } else if (!strcmp(a, "--threads")) {
            if (!parse_number(a, argv[++i], 1, 1024, &num, err) || num != floor(num))
                return error_set(err, "--threads expects an integer in [1, 1024], got '%s'", argv[i]);
            c->threads = (int)num;
        } else if (!strcmp(a, "--jobs")) {
            if (!parse_number(a, argv[++i], 1, 16, &num, err) || num != floor(num))
                return error_set(err, "--jobs expects an integer in [1, 16], got '%s'", argv[i]);
            c->jobs = (int)num;
        } else return error_set(err, "unknown option '%s'", a);
    }
    return true;
}

typedef struct Rows {
    StabResult *rows;
    int n, cap;
    bool oom;
} Rows;

static void print_row(const StabResult *r)
{
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
    if (rs->n == rs->cap) {
        int cap = rs->cap ? 2 * rs->cap : 256;
        StabResult *p = realloc(rs->rows, sizeof *p * (size_t)cap);
        if (!p) {
            rs->oom = true;
            return;
        }
        rs->rows = p;
        rs->cap = cap;
    }
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
static bool run_suite(const StabCli *c, const Technique *t, Rows *rows, Error *err)
{
    char work[] = "/tmp/shadowlab-stability-XXXXXX", scenes[1100];
    if (!mkdtemp(work)) return error_set(err, "cannot create a scratch folder in /tmp");
    snprintf(scenes, sizeof scenes, "%s/scenes", c->out ? c->out : "");
    StabOptions o = {.quick = c->quick, .timeout_s = c->timeout_s, .threads = c->threads, .only = c->only,
                     .work_dir = work, .scene_dir = c->out ? scenes : NULL, .jobs = c->jobs};
    const Technique *one[1] = {t};
    bool ok = stab_run(t ? one : NULL, t ? 1 : 0, t == NULL, &o, on_row, rows, err);
    rmdir(work);
    if (ok && rows->oom) ok = error_set(err, "out of memory for the rows");
    if (ok && c->out) ok = stab_report_write(c->out, rows->rows, rows->n, &o, err);
    return ok;
}

int cmd_stability(int argc, char **argv)
{
    StabCli c;
    Error err;
    if (!parse_args(argc, argv, &c, &err)) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (c.help) {
        printf("%s", stability_help);
        return EXIT_OK;
    }
    if (c.list) {
        list_cases();
        return EXIT_OK;
    }
    const Technique *t = c.tech ? tech_find(c.tech, &err) : NULL;
    if (c.tech && !t) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_USAGE;
    }
    Rows rows = {0};
    bool ok = run_suite(&c, t, &rows, &err);
    int failed = 0, passed = 0, na = 0;
    for (int i = 0; i < rows.n; i++) {
        failed += rows.rows[i].status == STAB_FAIL;
        passed += rows.rows[i].status == STAB_PASS;
        na += rows.rows[i].status == STAB_NOT_APPLICABLE;
    }
    free(rows.rows);
    if (!ok) {
        fprintf(stderr, "shadowlab stability: %s\n", err.msg);
        return EXIT_RUNTIME;
    }
    if (c.out) printf("report: %s/stability.{json,csv,md}\n", c.out);
    printf("not applicable: %d\n", na);
    printf("stability: %d passed, %d failed\n", passed, failed);
    return failed ? EXIT_RUNTIME : EXIT_OK;
}
