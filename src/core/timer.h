/* timer.h -- the one timing helper: monotonic wall-clock seconds, the CPU
 * seconds the calling thread has run, and the median of repeated timings
 * (sorts them in place; n >= 1). */
#ifndef SL_TIMER_H
#define SL_TIMER_H
double timer_now_s(void);
/* CLOCK_THREAD_CPUTIME_ID: only while this thread ran, so what other
 * programs take of the machine is not in it (differences only). */
double timer_thread_cpu_s(void);
double timer_median(double *samples, int n);
#endif
