/* fixtures.h -- helpers shared by the engine tests: scene files written into
 * the test's scratch folder, and a Lab opened on them. */
#ifndef SL_FIXTURES_H
#define SL_FIXTURES_H
#include "lab/lab.h"

/* Write `text` to test_tmpdir()/name and return the path (static buffer per call site). */
const char *fixture_file(const char *name, const char *text);
/* Open a Lab on a scene text; NULL (with the error printed) on failure. */
Lab *fixture_lab(const char *name, const char *scene_text);

#endif
