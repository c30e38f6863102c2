/* stability_proc.h -- the stability suite's forked processes: a child with
 * its stderr in a log streams StabResults back through a pipe under a time
 * bound, and how it ended (exit, crash, hang, sanitizer report) becomes
 * text for the row. Two levels use it: the suite forks one process per case,
 * which prepares what the case's runs share and forks one child per run. */
#ifndef SL_STABILITY_PROC_H
#define SL_STABILITY_PROC_H
#include <sys/types.h>
#include "lab/stability.h"

typedef struct StabProc {
    pid_t pid;
    int fd;                    /* read end of its results; -1 once it has ended */
    char log_path[1100];       /* its stderr; removed once it has ended */
    double started_s;
    double deadline_s;         /* killed when this passes */
    double bound_s;            /* the time bound the deadline stands for (for the message) */
    double extend_s;           /* each result moves the deadline to now + this; 0: fixed */
    StabResult msg;            /* the last whole result */
    StabResult partial;
    size_t got;                /* bytes of `partial` read */
    int results;               /* whole results received */
    char why[STAB_DETAIL_MAX]; /* once ended: "" if it exited cleanly, else what happened */
} StabProc;

/* The child's work: results go to `fd` with stab_proc_send. */
typedef void (*StabBody)(void *arg, int fd);

/* Fork a child running body(arg, fd) with stderr in log_path; it is killed
 * after bound_s seconds (then extend_s after each result, if > 0), and it
 * dies with this process. `close_fd` (-1: none) is closed in the child: the
 * caller's own pipe to the level above, so that only the caller holds it.
 * The child leaves with exit(0), so atexit handlers and LeakSanitizer run. */
bool stab_proc_spawn(StabProc *p, const char *log_path, double bound_s, double extend_s, int close_fd,
                     StabBody body, void *arg, char *err, size_t n);
bool stab_proc_send(int fd, const StabResult *r);

typedef enum StabEvent { STAB_EV_RESULT, STAB_EV_ENDED } StabEvent;
/* Wait until one of ps[0, n) has delivered a whole result (STAB_EV_RESULT,
 * in its msg) or has ended (STAB_EV_ENDED: reaped, killed first if its
 * deadline passed, `why` set). Returns its index. */
int stab_proc_next(StabProc *const *ps, int n, StabEvent *ev);

/* This process's threads: forking is safe only while there is one. */
int stab_thread_count(void);

#endif
