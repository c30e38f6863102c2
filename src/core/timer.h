/* timer.h -- the one timing helper: monotonic wall-clock seconds, and the
 * median of repeated timings (sorts them in place; n >= 1). */
#ifndef SL_TIMER_H
#define SL_TIMER_H
double timer_now_s(void);
double timer_median(double *samples, int n);
#endif
