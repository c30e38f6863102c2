/* timer.h -- the one timing helper: monotonic wall-clock seconds. */
#ifndef SL_TIMER_H
#define SL_TIMER_H
double timer_now_s(void);
#endif
