/* nanmath.h -- min, max and clamp that keep NaN. C's fmin/fmax return the
 * other operand when one is NaN (C11 F.10.9.2-3), so a NaN depth or moment
 * run through them becomes a plausible value (lit, the near plane, 0) that
 * no NaN counter sees. These return NaN when an operand is NaN, so an
 * unknown intermediate reaches the output as NaN (issue 13 §1). */
#ifndef SL_NANMATH_H
#define SL_NANMATH_H

static inline double nan_min(double a, double b) { return a < b || a != a ? a : b; }
static inline double nan_max(double a, double b) { return a > b || a != a ? a : b; }
static inline float nan_minf(float a, float b) { return a < b || a != a ? a : b; }
static inline float nan_maxf(float a, float b) { return a > b || a != a ? a : b; }
/* x in [lo, hi]; NaN stays NaN (both comparisons are false). */
static inline double nan_clamp(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

#endif
