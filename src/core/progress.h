/* progress.h -- a one-line progress report on stderr for work that takes
 * longer than a second, only when stderr is a terminal. Thread-safe: workers
 * call progress_add; one of them redraws at most five times a second. */
#ifndef SL_PROGRESS_H
#define SL_PROGRESS_H
#include <stdatomic.h>

typedef struct Progress {
    const char *label;
    long total;
    atomic_long done;
    atomic_flag drawing;
    double start_s, last_draw_s;
    int enabled, drawn;
} Progress;

void progress_begin(Progress *p, const char *label, long total);
void progress_add(Progress *p, long n);
void progress_end(Progress *p);

#endif
