/* docgen.h -- the documents generated from the technique registry (make docs,
 * scripts/docs.sh): docs/techniques.md (`shadowlab list --markdown`) and the
 * README's block of the technique table and the shared map parameters
 * (`shadowlab list --readme`). Nothing lists techniques by hand twice. */
#ifndef SL_DOCGEN_H
#define SL_DOCGEN_H
#include <stdio.h>
#include "techniques/technique.h"

void docgen_techniques_md(FILE *fp);
void docgen_readme_block(FILE *fp);

/* The map techniques (smap_has_map_params) in registry order, at most max,
 * and in *shared the number of leading parameters they all declare by name
 * (the shared map and bias block), listed once by `list` and the README. */
int docgen_map_techniques(const Technique **maps, int max, int *shared);
/* How many of t's leading parameters are base's first `shared`, by name
 * (where t's own parameters begin, when it is less than `shared`). */
int docgen_shared_prefix(const Technique *base, const Technique *t, int shared);
/* How technique t's shared parameter k differs from base's: "default X",
 * "range R", "not taken", or "" when it does not. */
void docgen_param_difference(const Technique *base, const Technique *t, int k, char *out, size_t n);

#endif
