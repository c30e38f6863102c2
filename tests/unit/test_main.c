/* test_main.c -- runs every registered TEST; an argument filters by name
 * substring, --jobs N runs them on N forked processes. Prints one line per
 * test and the closing "N passed, N failed". */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include <poll.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "core/timer.h"

#define MAX_TESTS 1024

static struct { const char *name; TestFn fn; } tests[MAX_TESTS];
static int num_tests, current_failed;
static char tmpdir[256];

void test_register(const char *name, TestFn fn)
{
    if (num_tests < MAX_TESTS) {
        tests[num_tests].name = name;
        tests[num_tests].fn = fn;
        num_tests++;
    }
}

void test_fail(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stdout, "    %s:%d: ", file, line);
    vfprintf(stdout, fmt, ap);
    fprintf(stdout, "\n");
    va_end(ap);
    current_failed = 1;
}

const char *test_tmpdir(void)
{
    if (!tmpdir[0]) {
        snprintf(tmpdir, sizeof tmpdir, "/tmp/shadowlab-test-XXXXXX");
        if (!mkdtemp(tmpdir)) { perror("mkdtemp"); exit(1); }
    }
    return tmpdir;
}

static void remove_tmpdir(void)
{
    if (!tmpdir[0]) return;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    tmpdir[0] = '\0';
}

/* Runs test i: its lines, then "ok"/"FAIL", name and seconds. Returns 1 if it failed. */
static int run_test(int i)
{
    current_failed = 0;
    double t0 = timer_now_s();
    tests[i].fn();
    remove_tmpdir();
    printf("%s %s (%.2f s)\n", current_failed ? "FAIL" : "ok  ", tests[i].name, timer_now_s() - t0);
    fflush(stdout);
    return current_failed;
}

/* ---- running on several processes (--jobs N) ------------------------------
 * The parent puts every selected test's index into a pipe; each forked worker
 * takes the next one (a 4-byte read from a pipe is whole: the indices were
 * written 4 bytes at a time), runs it with its stdout in a scratch file, and
 * sends the parent one record: the index, whether it failed, and the output.
 * The parent prints each test's lines and verdict as one block, in the order
 * they finish, and counts. A worker that dies (a crash, a sanitizer report at
 * exit: ASan's exit code 86) fails the test it was running, or the run, and
 * its exit status becomes the run's, so no report is lost. */
typedef struct { int index, failed; long bytes; } TestRecord;

static bool write_all(int fd, const void *p, size_t n)
{
    for (const char *c = p; n > 0;) {
        ssize_t w = write(fd, c, n);
        if (w <= 0) return false;
        c += w, n -= (size_t)w;
    }
    return true;
}

static bool read_all(int fd, void *p, size_t n)
{
    for (char *c = p; n > 0;) {
        ssize_t r = read(fd, c, n);
        if (r <= 0) return false;
        c += r, n -= (size_t)r;
    }
    return true;
}

/* A worker: runs tests from work_fd until it is empty, records to out_fd. */
static int worker(int work_fd, int out_fd)
{
    int i;
    while (read(work_fd, &i, sizeof i) == (ssize_t)sizeof i) {
        TestRecord rec = {.index = i, .failed = 0, .bytes = -1};
        if (!write_all(out_fd, &rec, sizeof rec)) return 1; /* started: bytes -1 */
        FILE *capture = tmpfile();
        int stdout_fd = dup(STDOUT_FILENO);
        if (!capture || stdout_fd < 0) { perror("test_unit: worker output"); return 1; }
        fflush(stdout);
        dup2(fileno(capture), STDOUT_FILENO);
        rec.failed = run_test(i);
        dup2(stdout_fd, STDOUT_FILENO);
        close(stdout_fd);
        rec.bytes = ftell(capture);
        char *text = malloc(rec.bytes > 0 ? (size_t)rec.bytes : 1);
        rewind(capture);
        bool sent = text && fread(text, 1, (size_t)rec.bytes, capture) == (size_t)rec.bytes &&
                    write_all(out_fd, &rec, sizeof rec) && write_all(out_fd, text, (size_t)rec.bytes);
        free(text);
        fclose(capture);
        if (!sent) return 1;
    }
    return 0;
}

typedef struct { pid_t pid; int fd, running; bool open; } Worker;

/* Reads one record from w; false once the worker closed its pipe. */
static bool take_record(Worker *w, int *passed, int *failed)
{
    TestRecord rec;
    if (!read_all(w->fd, &rec, sizeof rec)) return false;
    if (rec.bytes < 0) { w->running = rec.index; return true; }
    char *text = malloc((size_t)rec.bytes + 1);
    if (!text || !read_all(w->fd, text, (size_t)rec.bytes)) { free(text); return false; }
    fwrite(text, 1, (size_t)rec.bytes, stdout);
    fflush(stdout);
    free(text);
    w->running = -1;
    if (rec.failed) (*failed)++; else (*passed)++;
    return true;
}

/* Waits for w; a death while running a test fails that test. Returns its exit status. */
static int reap(Worker *w, int *failed)
{
    int status = 0;
    waitpid(w->pid, &status, 0);
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code && w->running >= 0) {
        printf("FAIL %s (its worker exited with status %d while running it)\n", tests[w->running].name, code);
        (*failed)++;
    } else if (code) {
        printf("FAIL the worker %d exited with status %d between tests\n", (int)w->pid, code);
        (*failed)++;
    }
    return code;
}

static int run_parallel(const int *selected, int n, int jobs, int *passed, int *failed)
{
    int work[2];
    if (pipe(work) != 0) { perror("test_unit: pipe"); return 1; }
    for (int k = 0; k < n; k++) write_all(work[1], &selected[k], sizeof selected[k]);
    close(work[1]);
    Worker ws[16];
    int open = 0;
    fflush(stdout);
    for (int j = 0; j < jobs; j++) {
        int out[2];
        ws[j] = (Worker){.pid = -1, .fd = -1, .running = -1, .open = false};
        if (pipe(out) != 0) { perror("test_unit: pipe"); continue; }
        pid_t pid = fork();
        if (pid == 0) {
            close(out[0]);
            for (int k = 0; k < j; k++)
                if (ws[k].open) close(ws[k].fd);
            int code = worker(work[0], out[1]);
            close(out[1]);
            exit(code); /* through atexit: LeakSanitizer checks the worker */
        }
        close(out[1]);
        if (pid < 0) { perror("test_unit: fork"); close(out[0]); continue; }
        ws[j] = (Worker){.pid = pid, .fd = out[0], .running = -1, .open = true};
        open++;
    }
    close(work[0]);
    int status = open > 0 ? 0 : 1; /* no worker started: nothing ran */
    while (open > 0) {
        struct pollfd fds[16];
        for (int j = 0; j < jobs; j++) fds[j] = (struct pollfd){.fd = ws[j].open ? ws[j].fd : -1, .events = POLLIN};
        if (poll(fds, (nfds_t)jobs, -1) < 0) continue;
        for (int j = 0; j < jobs; j++) {
            if (!ws[j].open || !(fds[j].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            if (take_record(&ws[j], passed, failed)) continue;
            close(ws[j].fd);
            ws[j].open = false, open--;
            int code = reap(&ws[j], failed);
            if (code && !status) status = code;
        }
    }
    return status;
}

static void usage(void)
{
    fprintf(stderr, "usage: test_unit [--jobs N] [NAME]: the tests whose name contains NAME (all: none),\n"
                    "on N processes (1 ... 16; default 1)\n");
    exit(2);
}

int main(int argc, char **argv)
{
    const char *filter = NULL;
    int jobs = 1;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--jobs") == 0 && a + 1 < argc) {
            char *end;
            long j = strtol(argv[++a], &end, 10);
            if (*end || j < 1 || j > 16) usage();
            jobs = (int)j;
        } else if (argv[a][0] == '-' || filter) {
            usage();
        } else {
            filter = argv[a];
        }
    }
    static int selected[MAX_TESTS];
    int n = 0, passed = 0, failed = 0, status = 0;
    for (int i = 0; i < num_tests; i++)
        if (!filter || strstr(tests[i].name, filter)) selected[n++] = i;
    if (jobs > n) jobs = n > 0 ? n : 1;
    if (jobs == 1) {
        for (int k = 0; k < n; k++) {
            if (run_test(selected[k])) failed++; else passed++;
        }
    } else {
        status = run_parallel(selected, n, jobs, &passed, &failed);
    }
    printf("unit: %d passed, %d failed\n", passed, failed);
    return status ? status : failed ? 1 : 0;
}
