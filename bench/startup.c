/* startup.c -- start-up cost of the CLI (issue 8, item 7): sweeps driven from
 * the shell start the program thousands of times. For `shadowlab list` and
 * a small `render` that writes only EXR (--no-png), and `render --help` (the
 * start-up alone, since render prints its first line once it has rendered):
 * the time from fork to the first line on stdout (median of --repeat starts), and whether the run
 * loaded OpenImageIO or its plugin (one more start with LD_DEBUG=files,
 * whose loader log names every library mapped). Target: no OpenImageIO,
 * under 20 ms to the first line. Rows: DIR/startup.csv.
 * Usage: startup SHADOWLAB [--repeat R] [-o DIR] */
#include <fcntl.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bench.h"
#include "core/timer.h"

#define FIRST_LINE_BOUND_MS 20.0
#define HEADER "command,first_line_ms,exit_ms,loads_openimageio,bound_ms,within," BENCH_TAIL_HEADER "\n"
#define MAX_ARGS 24

typedef struct Start {
    double first_line_s, exit_s;
    bool oiio; /* only with trace */
} Start;

/* Run argv with stdout (and, when tracing, stderr) on a pipe. */
static bool run_once(char *const *argv, bool trace, Start *st, Error *err)
{
    int fd[2];
    if (pipe(fd) != 0) return error_set(err, "pipe failed");
    double t0 = timer_now_s();
    pid_t pid = fork();
    if (pid < 0) return error_set(err, "fork failed");
    if (pid == 0) {
        dup2(fd[1], STDOUT_FILENO);
        int devnull = open("/dev/null", O_WRONLY);
        dup2(trace ? fd[1] : devnull, STDERR_FILENO);
        close(fd[0]);
        if (trace) setenv("LD_DEBUG", "files", 1);
        execv(argv[0], argv);
        _exit(127);
    }
    close(fd[1]);
    *st = (Start){0};
    char buf[4096], carry[64] = "";
    ssize_t n;
    while ((n = read(fd[0], buf, sizeof buf - 1)) > 0) {
        buf[n] = '\0';
        if (st->first_line_s == 0.0 && memchr(buf, '\n', (size_t)n)) st->first_line_s = timer_now_s() - t0;
        /* a library name split across reads: keep the tail of the last one */
        char both[sizeof carry + sizeof buf];
        snprintf(both, sizeof both, "%s%s", carry, buf);
        st->oiio = st->oiio || strstr(both, "OpenImageIO") || strstr(both, "shadowlab_oiio");
        snprintf(carry, sizeof carry, "%s", n > 48 ? buf + n - 48 : buf);
    }
    close(fd[0]);
    int status;
    waitpid(pid, &status, 0);
    st->exit_s = timer_now_s() - t0;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return error_set(err, "'%s %s' exited with status %d", argv[0], argv[1], WEXITSTATUS(status));
    return true;
}

static bool bench_command(const char *label, char *const *argv, int repeat, const char *dir, Error *err)
{
    Start traced, st;
    double *first = malloc(sizeof *first * 2 * (size_t)repeat);
    if (!first) return error_set(err, "out of memory");
    bool ok = run_once(argv, true, &traced, err) && run_once(argv, false, &st, err); /* trace, then warm the page cache */
    for (int i = 0; ok && i < repeat; i++) {
        ok = run_once(argv, false, &st, err);
        first[i] = st.first_line_s;
        first[repeat + i] = st.exit_s;
    }
    double f = ok ? bench_median(first, repeat) * 1e3 : 0.0, e = ok ? bench_median(first + repeat, repeat) * 1e3 : 0.0;
    free(first);
    if (!ok) return false;
    bool within = !traced.oiio && f < FIRST_LINE_BOUND_MS;
    printf("  %-26s first line %7.2f ms, exit %7.2f ms (median of %d), OpenImageIO %s%s\n", label, f, e, repeat,
           traced.oiio ? "LOADED" : "not loaded", within ? "" : "  OVER");
    char row[1024], tail[512], path[4096], name[128];
    bench_tail(tail, sizeof tail, 1);
    bench_csv_field(name, sizeof name, label);
    snprintf(row, sizeof row, "%s,%.3f,%.3f,%s,%.0f,%s,%s\n", name, f, e, traced.oiio ? "yes" : "no",
             FIRST_LINE_BOUND_MS, within ? "yes" : "no", tail);
    snprintf(path, sizeof path, "%s/startup.csv", dir);
    return bench_csv_append(path, HEADER, row, err);
}

int main(int argc, char **argv)
{
    const char *dir = "reports/bench", *bin = NULL;
    int repeat = 21;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--repeat") == 0 && bench_parse_int(v, 1, 1000, &repeat)) i++;
        else if (strcmp(argv[i], "-o") == 0 && v) dir = argv[++i];
        else if (argv[i][0] != '-' && !bin) bin = argv[i];
        else bin = NULL, i = argc;
    }
    if (!bin) {
        fprintf(stderr, "usage: startup SHADOWLAB [--repeat R] [-o DIR]\n");
        return 2;
    }
    char out[] = "/tmp/shadowlab-bench-startup-XXXXXX";
    if (!mkdtemp(out)) {
        fprintf(stderr, "startup: cannot make a temporary folder\n");
        return 1;
    }
    char *list[] = {(char *)bin, "list", NULL}, *help[] = {(char *)bin, "render", "--help", NULL};
    char *render[MAX_ARGS] = {(char *)bin, "render", "scenes/sphere-on-plane.lua", "-t", "hard", "--no-png",
                              "--threads", "1", "-s", "camera.width=32", "-s", "camera.height=24",
                              "-o", out, NULL};
    Error err;
    bool ok = bench_command("list", list, repeat, dir, &err) && bench_command("render --help", help, repeat, dir, &err) &&
              bench_command("render --no-png (32x24, EXR)", render, repeat, dir, &err);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", out);
    if (system(cmd) != 0) fprintf(stderr, "startup: note: could not remove %s\n", out);
    if (!ok) {
        fprintf(stderr, "startup: %s\n", err.msg);
        return 1;
    }
    return 0;
}
