/* docgen.h -- the documents generated from the technique registry (make docs,
 * scripts/docs.sh): docs/techniques.md (`shadowlab list --markdown`) and the
 * README's block of the technique table and the shared map parameters
 * (`shadowlab list --readme`). Nothing lists techniques by hand twice. */
#ifndef SL_DOCGEN_H
#define SL_DOCGEN_H
#include <stdio.h>

void docgen_techniques_md(FILE *fp);
void docgen_readme_block(FILE *fp);

#endif
