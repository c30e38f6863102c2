/* aliasing_report.h -- the outputs of a sampling-error analysis
 * (resources/analysis/aliasing.h): a float EXR of the per-sample readings, a
 * colour-mapped PNG of m (Lloyd's scale: blue oversampled, green at m = 1,
 * through yellow and red to dark red at m >= 10), a PNG of the cascade
 * each sample uses (course Figs. 3.10-3.12), the histogram and the profile
 * along view depth as CSV, the error along the view axis (Fig. 3.7's
 * quantity), and a JSON summary; printed for people too. */
#ifndef SL_ALIASING_REPORT_H
#define SL_ALIASING_REPORT_H
#include <stdio.h>
#include "resources/analysis/aliasing.h"

typedef struct AliasingReport {
    const Scene *scene;
    const char *technique;          /* whose map parameters were analysed */
    const char *params_text;        /* "name=value ..." of those parameters */
    const ShadowMap *map;
    const AliasingMap *samples;     /* over the view samples */
    const AliasingSummary *frustum; /* Lloyd's storage factor over the view frustum, or NULL */
    const AliasingPoint *axis;      /* along the view axis (aliasing_on_axis), face -1 where not measured */
    int num_axis;
    double seconds;                 /* the analysis's own time */
} AliasingReport;

/* DIR/STEM.exr, STEM.png, STEM-cascade.png, STEM-hist.csv, STEM-depth.csv,
 * STEM-axis.csv, STEM.json; on failure none of them is left. `png` false
 * skips the PNGs. */
bool aliasing_report_write(const AliasingReport *r, const char *dir, const char *stem, bool png, Error *err);
void aliasing_report_print(const AliasingReport *r, FILE *fp);
/* Colour of m on the scale above (linear RGB in [0, 1]). */
void aliasing_color(double m, float rgb[3]);

#endif
