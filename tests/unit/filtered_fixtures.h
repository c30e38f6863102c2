/* filtered_fixtures.h -- what the tests of the prefiltered shadow maps
 * (test_filtered*.c) share: a project scene on a small view, a technique's
 * parameters and render from a space-separated "name=value ..." list over
 * its defaults, and the registry's prefiltered techniques (those that
 * acquire moment maps), so no test lists them by hand. */
#ifndef SL_FILTERED_FIXTURES_H
#define SL_FILTERED_FIXTURES_H
#include "lab/lab.h"

/* A scene file (path from the repository root) at width x height. */
Lab *filtered_open(const char *scene, int width, int height);
bool filtered_params(const Technique *t, const char *list, double *values);
/* Render on light 1; false (the error printed) on failure. */
bool filtered_render(Lab *lab, const char *tech, const char *list, RenderResult *out);
bool filtered_acquires_moments(const Technique *t);

#endif
