/* progress.c -- the progress line (see progress.h): the stage stack under one
 * mutex, the line composed from it, and the optional heartbeat thread. Fork
 * handlers keep the mutex consistent across fork() and silence the child. */
#define _POSIX_C_SOURCE 200809L
#include "core/progress.h"
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>
#include "core/timer.h"

#define DELAY_S 1.0     /* nothing is drawn before the outermost stage has run this long */
#define INTERVAL_S 0.2  /* at most five draws a second */
#define MAX_DEPTH 16    /* innermost stages shown */
#define LINE_MAX_CHARS 400

static struct {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    Progress *inner, *outermost; /* the open stages: innermost, and the bottom of its chain */
    atomic_bool enabled;         /* drawing, for the open outermost stage */
    bool heartbeat, ticking, forked_child;
    pthread_t ticker;
    double last_draw_s;
    int drawn_len;               /* columns the line covers on screen; 0: none drawn */
    int width;                   /* terminal columns */
} g = {.lock = PTHREAD_MUTEX_INITIALIZER, .wake = PTHREAD_COND_INITIALIZER};

static pthread_once_t fork_handlers_once = PTHREAD_ONCE_INIT;

static void before_fork(void) { pthread_mutex_lock(&g.lock); }
static void after_fork_parent(void) { pthread_mutex_unlock(&g.lock); }
static void after_fork_child(void)
{
    g.forked_child = true; /* the parent owns the terminal line */
    atomic_store(&g.enabled, false);
    g.ticking = false;     /* the heartbeat thread is not copied */
    g.drawn_len = 0;
    pthread_mutex_unlock(&g.lock);
}
static void register_fork_handlers(void) { pthread_atfork(before_fork, after_fork_parent, after_fork_child); }

/* One stage's text: its label (unless its outer stage has the same one) and its count. */
static size_t stage_text(const Progress *p, const Progress *outer, bool first, char *out, size_t n)
{
    size_t used = 0;
    long done = atomic_load(&p->done);
    if (!outer || strcmp(outer->label, p->label) != 0)
        used += (size_t)snprintf(out, n, "%s%s", first ? "" : " > ", p->label);
    if (used < n && p->total > 0) used += (size_t)snprintf(out + used, n - used, " %ld/%ld", done, p->total);
    else if (used < n && done > 0) used += (size_t)snprintf(out + used, n - used, " %ld done", done);
    return used < n ? used : n - 1;
}

/* "a > b 3/10 > c, 4.2 s (about 9 s left)": every open stage, outermost
 * first, the time since the outermost began, and the innermost counted
 * stage's estimate of what is left. */
static void compose(double now, char *line, size_t n)
{
    const Progress *chain[MAX_DEPTH];
    int depth = 0;
    for (const Progress *p = g.inner; p && depth < MAX_DEPTH; p = p->outer) chain[depth++] = p;
    size_t used = 0;
    const Progress *counted = NULL;
    for (int i = depth - 1; i >= 0 && used < n - 1; i--) {
        used += stage_text(chain[i], i + 1 < depth ? chain[i + 1] : NULL, i == depth - 1, line + used, n - used);
        if (chain[i]->total > 0 && atomic_load(&chain[i]->done) > 0) counted = chain[i];
    }
    if (used < n - 1) used += (size_t)snprintf(line + used, n - used, ", %.1f s", now - g.outermost->start_s);
    if (counted && used < n - 1) {
        long done = atomic_load(&counted->done);
        double left_s = (now - counted->start_s) * (double)(counted->total - done) / (double)done;
        if (left_s >= 0.5) snprintf(line + used, n - used, " (about %.0f s left)", left_s);
    }
}

static void erase_locked(void)
{
    if (g.drawn_len > 0) fprintf(stderr, "\r%*s\r", g.drawn_len, "");
    g.drawn_len = 0;
}

static void draw_locked(double now)
{
    if (!atomic_load(&g.enabled) || !g.outermost || now - g.outermost->start_s < DELAY_S) return;
    if (now - g.last_draw_s < INTERVAL_S) return;
    char line[LINE_MAX_CHARS + 1];
    compose(now, line, sizeof line);
    int len = (int)strlen(line);
    if (len > g.width - 1) len = g.width - 1; /* a wrapped line could not be redrawn in place */
    line[len] = '\0';
    fprintf(stderr, "\r%s%*s", line, g.drawn_len > len ? g.drawn_len - len : 0, "");
    fflush(stderr);
    if (len > g.drawn_len) g.drawn_len = len;
    g.last_draw_s = now;
}

static void *heartbeat(void *unused)
{
    (void)unused;
    pthread_mutex_lock(&g.lock);
    while (g.ticking) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        long ns = until.tv_nsec + (long)(INTERVAL_S * 1e9);
        until.tv_sec += ns / 1000000000L;
        until.tv_nsec = ns % 1000000000L;
        pthread_cond_timedwait(&g.wake, &g.lock, &until);
        if (g.ticking) draw_locked(timer_now_s());
    }
    pthread_mutex_unlock(&g.lock);
    return NULL;
}

static void start_outermost(Progress *p)
{
    g.outermost = p;
    g.drawn_len = 0;
    g.last_draw_s = -1e9;
    bool tty = !g.forked_child && isatty(STDERR_FILENO);
    atomic_store(&g.enabled, tty);
    struct winsize ws;
    g.width = tty && ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
    if (g.width > LINE_MAX_CHARS) g.width = LINE_MAX_CHARS;
    g.ticking = tty && g.heartbeat && pthread_create(&g.ticker, NULL, heartbeat, NULL) == 0;
}

void progress_begin(Progress *p, const char *label, long total)
{
    pthread_once(&fork_handlers_once, register_fork_handlers);
    snprintf(p->label, sizeof p->label, "%s", label);
    p->total = total > 0 ? total : 0;
    atomic_init(&p->done, 0);
    p->start_s = timer_now_s();
    pthread_mutex_lock(&g.lock);
    p->outer = g.inner;
    g.inner = p;
    if (!p->outer) start_outermost(p);
    else draw_locked(p->start_s);
    pthread_mutex_unlock(&g.lock);
}

void progress_add(Progress *p, long n)
{
    atomic_fetch_add(&p->done, n);
    if (!atomic_load_explicit(&g.enabled, memory_order_relaxed) || pthread_mutex_trylock(&g.lock) != 0) return;
    draw_locked(timer_now_s());
    pthread_mutex_unlock(&g.lock);
}

/* Take p out of the chain (it is the innermost unless a caller erred). */
static void unlink_locked(Progress *p)
{
    Progress **link = &g.inner;
    while (*link && *link != p) link = &(*link)->outer;
    if (*link) *link = p->outer;
}

void progress_end(Progress *p)
{
    bool join = false;
    pthread_t ticker;
    pthread_mutex_lock(&g.lock);
    unlink_locked(p);
    if (g.inner) {
        draw_locked(timer_now_s());
    } else {
        erase_locked();
        g.outermost = NULL;
        atomic_store(&g.enabled, false);
        join = g.ticking;
        ticker = g.ticker;
        g.ticking = false;
        pthread_cond_signal(&g.wake);
    }
    pthread_mutex_unlock(&g.lock);
    if (join) pthread_join(ticker, NULL);
}

void progress_clear(void)
{
    pthread_mutex_lock(&g.lock);
    erase_locked();
    pthread_mutex_unlock(&g.lock);
}

void progress_set_heartbeat(bool on)
{
    pthread_mutex_lock(&g.lock);
    g.heartbeat = on;
    pthread_mutex_unlock(&g.lock);
}

void progress_tick(void)
{
    if (!atomic_load_explicit(&g.enabled, memory_order_relaxed)) return;
    pthread_mutex_lock(&g.lock);
    draw_locked(timer_now_s());
    pthread_mutex_unlock(&g.lock);
}
