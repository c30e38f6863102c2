/* progress.c -- terminal progress line (see progress.h). */
#include "core/progress.h"
#include <stdio.h>
#include <unistd.h>
#include "core/timer.h"

void progress_begin(Progress *p, const char *label, long total)
{
    p->label = label;
    p->total = total > 0 ? total : 1;
    atomic_init(&p->done, 0);
    atomic_flag_clear(&p->drawing);
    p->start_s = p->last_draw_s = timer_now_s();
    p->enabled = isatty(STDERR_FILENO);
    p->drawn = 0;
}

void progress_add(Progress *p, long n)
{
    long done = atomic_fetch_add(&p->done, n) + n;
    if (!p->enabled || atomic_flag_test_and_set(&p->drawing)) return;
    double now = timer_now_s();
    if (now - p->start_s > 1.0 && now - p->last_draw_s > 0.2) {
        double frac = (double)done / (double)p->total;
        double eta = frac > 0 ? (now - p->start_s) * (1.0 - frac) / frac : 0.0;
        fprintf(stderr, "\r%s: %5.1f%% (%.0f s left)   ", p->label, 100.0 * frac, eta);
        fflush(stderr);
        p->last_draw_s = now;
        p->drawn = 1;
    }
    atomic_flag_clear(&p->drawing);
}

void progress_end(Progress *p)
{
    if (p->drawn) fprintf(stderr, "\r%s: done in %.1f s            \n", p->label, timer_now_s() - p->start_s);
}
