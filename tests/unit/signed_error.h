/* signed_error.h -- per-sample errors against a cheap Embree reference, for
 * tests that count where an estimate breaks a bound or darkens too much
 * (the metrics give means and maxima only). */
#ifndef SL_SIGNED_ERROR_H
#define SL_SIGNED_ERROR_H
#include "lab/lab.h"

/* Metrics of `v` on light 1 against a `samples`-sample stratified reference
 * (seed 1, no disk cache), and the signed error estimate - reference per
 * sample and channel into `e` (0 off the lit candidates); free with image_free. */
bool signed_error(Lab *lab, const Image *v, int samples, Metrics *m, Image *e);

/* Values of an estimate that are not finite in [0, 1] (every sample and channel). */
long outside_unit_range(const Image *v);

/* Lit candidates where some channel's error is above `above` or below
 * `below` (pass -INFINITY / +INFINITY to leave one side out). */
long signed_error_count(const Image *e, double below, double above);

#endif
