/* stability_proc.c -- forked children that stream StabResults through a pipe
 * under a deadline (see stability_proc.h): fork with stderr in a log, a poll
 * loop over the children running at once, and the verdict on how each one
 * ended, from its exit status and the line of its log that says most. */
#define _POSIX_C_SOURCE 200809L
#include "lab/stability_proc.h"
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif
#include "core/fsutil.h"
#include "core/progress.h"
#include "core/timer.h"

#define MAX_AT_ONCE 64

int stab_thread_count(void)
{
    DIR *d = opendir("/proc/self/task");
    if (!d) return 1;
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

bool stab_proc_spawn(StabProc *p, const char *log_path, double bound_s, double extend_s, int close_fd,
                     StabBody body, void *arg, char *err, size_t n)
{
    memset(p, 0, sizeof *p);
    p->fd = -1;
    snprintf(p->log_path, sizeof p->log_path, "%s", log_path);
    int fds[2];
    if (pipe(fds) != 0) {
        snprintf(err, n, "pipe: %s", strerror(errno));
        return false;
    }
    fflush(NULL);
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(err, n, "fork: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return false;
    }
    if (pid == 0) {
        close(fds[0]);
        if (close_fd >= 0) close(close_fd);
#ifdef __linux__
        prctl(PR_SET_PDEATHSIG, SIGKILL); /* a killed parent takes its runs with it */
#endif
        if (getppid() != parent) _exit(1);
        if (!freopen(log_path, "w", stderr)) _exit(1);
        body(arg, fds[1]);
        close(fds[1]);
        exit(0); /* atexit handlers run, so LeakSanitizer checks the run */
    }
    close(fds[1]);
    p->pid = pid;
    p->fd = fds[0];
    p->started_s = timer_now_s();
    p->bound_s = bound_s;
    p->deadline_s = p->started_s + bound_s;
    p->extend_s = extend_s;
    return true;
}

bool stab_proc_send(int fd, const StabResult *r)
{
    size_t done = 0;
    while (done < sizeof *r) {
        ssize_t k = write(fd, (const char *)r + done, sizeof *r - done);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return false;
        done += (size_t)k;
    }
    return true;
}

/* ---- how a child ended ------------------------------------------------------ */

/* The line of a child's stderr that says most: a sanitizer's error line,
 * else any sanitizer line, else the last one. */
static void log_excerpt(const char *log_path, char *out, size_t n)
{
    out[0] = '\0';
    char *text = file_read_all(log_path, NULL, NULL);
    if (!text) return;
    char *error = NULL, *sanitizer = NULL, *last = NULL;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (!error && (strstr(line, "ERROR: ") || strstr(line, "runtime error"))) error = line;
        if (!sanitizer && strstr(line, "Sanitizer")) sanitizer = line;
        if (line[strspn(line, " \t")]) last = line;
    }
    const char *best = error ? error : sanitizer ? sanitizer : last;
    if (best) snprintf(out, n, "%.300s", best);
    free(text);
}

/* Wait for the child until its deadline (it may still be in its atexit
 * handlers after closing the pipe), then kill it. */
static int reap(StabProc *p, bool *killed)
{
    int status = 0;
    for (;;) {
        pid_t w = waitpid(p->pid, &status, *killed ? 0 : WNOHANG);
        if (w == p->pid) return status;
        if (w < 0 && errno != EINTR) return 0;
        if (!*killed && timer_now_s() > p->deadline_s) {
            kill(p->pid, SIGKILL);
            *killed = true;
        } else if (!*killed) {
            usleep(2000);
        }
    }
}

static void judge(StabProc *p, bool killed, int status)
{
    char excerpt[320];
    log_excerpt(p->log_path, excerpt, sizeof excerpt);
    bool sanitizer = strstr(excerpt, "Sanitizer") || strstr(excerpt, "runtime error");
    bool caught_signal = strstr(excerpt, "DEADLYSIGNAL") || strstr(excerpt, "SEGV on");
    size_t n = sizeof p->why;
    p->why[0] = '\0';
    if (killed && p->results > 0 && p->extend_s <= 0)
        snprintf(p->why, n, "did not exit within %.0f s of its start, after its result %s", p->bound_s, excerpt);
    else if (killed) snprintf(p->why, n, "no result within %.0f s (hang?) %s", p->bound_s, excerpt);
    else if (WIFSIGNALED(status))
        snprintf(p->why, n, "crashed: signal %d (%s) %s", WTERMSIG(status), strsignal(WTERMSIG(status)), excerpt);
    else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
    else if (caught_signal) snprintf(p->why, n, "crashed (signal caught by the sanitizer): %s", excerpt);
    else if (sanitizer) snprintf(p->why, n, "sanitizer report%s: %s", p->results ? " after the run" : "", excerpt);
    else snprintf(p->why, n, "exit status %d: %s", WEXITSTATUS(status), excerpt);
}

static void end(StabProc *p, bool killed)
{
    if (killed) kill(p->pid, SIGKILL);
    close(p->fd);
    p->fd = -1;
    int status = reap(p, &killed);
    judge(p, killed, status);
    remove(p->log_path);
}

/* ---- waiting for the next event -------------------------------------------------- */

/* Read what is there; true when a whole result or the end arrived. */
static bool take(StabProc *p, StabEvent *ev)
{
    ssize_t k = read(p->fd, (char *)&p->partial + p->got, sizeof p->partial - p->got);
    if (k < 0 && (errno == EINTR || errno == EAGAIN)) return false;
    if (k <= 0) {
        end(p, false);
        *ev = STAB_EV_ENDED;
        return true;
    }
    p->got += (size_t)k;
    if (p->got < sizeof p->partial) return false;
    p->msg = p->partial;
    p->got = 0;
    p->results++;
    if (p->extend_s > 0) {
        p->deadline_s = timer_now_s() + p->extend_s;
        p->bound_s = p->extend_s;
    }
    *ev = STAB_EV_RESULT;
    return true;
}

int stab_proc_next(StabProc *const *ps, int n, StabEvent *ev)
{
    if (n > MAX_AT_ONCE) n = MAX_AT_ONCE;
    for (;;) {
        double now = timer_now_s(), wait_s = 1.0;
        for (int i = 0; i < n; i++) {
            if (now >= ps[i]->deadline_s) {
                end(ps[i], true);
                *ev = STAB_EV_ENDED;
                return i;
            }
            wait_s = fmin(wait_s, ps[i]->deadline_s - now);
        }
        struct pollfd pf[MAX_AT_ONCE];
        for (int i = 0; i < n; i++) pf[i] = (struct pollfd){ps[i]->fd, POLLIN, 0};
        progress_tick(); /* the caller's progress line shows the time passing (at most each wait_s <= 1 s) */
        if (poll(pf, (nfds_t)n, (int)ceil(wait_s * 1000.0)) <= 0) continue; /* timeout or EINTR */
        for (int i = 0; i < n; i++)
            if (pf[i].revents && take(ps[i], ev)) return i;
    }
}
