/* progress.h -- the one progress line on stderr. Work is a stack of nested
 * stages (a command, a resource build, the evaluations, the reference's
 * rows), drawn as "compare pcf > shadow_map, 3.2 s" or "... > reference
 * 120/480, 4.0 s (about 12 s left)" once the outermost stage has run longer
 * than a second, only when stderr is a terminal, at most five times a second,
 * and erased when the outermost stage ends.
 *
 * Stages are begun and ended on one thread, innermost first; any thread may
 * call progress_add. The line is redrawn on those calls, and, with the
 * heartbeat on, by a thread of its own while a stage is open, so a step that
 * reports nothing (a BVH build) still shows its elapsed time. A process that
 * forks must stay single-threaded (the stability suite): it leaves the
 * heartbeat off and calls progress_tick while it waits. A forked child never
 * draws. */
#ifndef SL_PROGRESS_H
#define SL_PROGRESS_H
#include <stdatomic.h>
#include <stdbool.h>

#define PROGRESS_LABEL_MAX 48

typedef struct Progress {
    char label[PROGRESS_LABEL_MAX];
    long total;            /* items; 0: unknown (only the count done is shown) */
    atomic_long done;
    double start_s;
    struct Progress *outer;
} Progress;

/* Open a stage inside the innermost open one (label is copied). */
void progress_begin(Progress *p, const char *label, long total);
void progress_add(Progress *p, long n);
/* Close p, the innermost stage; the outermost one erases the line. */
void progress_end(Progress *p);
/* Erase the line now (before writing other text to the terminal); it is
 * drawn again at the next update. */
void progress_clear(void);
/* Whether a heartbeat thread redraws the line while a stage is open (default off). */
void progress_set_heartbeat(bool on);
/* Redraw the line if it is due: for a loop that waits (poll) in a process
 * that must stay single-threaded, so its line still shows the time passing. */
void progress_tick(void);

#endif
