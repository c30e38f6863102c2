/* report.h -- the outputs of a run: a float EXR with named channels and the
 * run's parameters in its header, PNG previews (shaded, visibility, signed
 * error on a stated diverging scale), a JSON record, and the metrics table
 * printed for people. A RunReport gathers what one run produced; fields that
 * a command does not produce are NULL (no technique for `reference`, no
 * reference for `render`). */
#ifndef SL_REPORT_H
#define SL_REPORT_H
#include <stdio.h>
#include "lab/lab.h"

typedef struct RunReport {
    const char *command;        /* "render", "reference", "compare" */
    Lab *lab;
    int light_index;
    const Technique *tech;      /* NULL for reference */
    const double *params;
    const RenderResult *render; /* NULL for reference */
    const Reference *ref;       /* NULL for render */
    const RefInfo *ref_info;
    const Metrics *metrics;     /* compare only */
    const Image *signed_error;  /* compare only */
    double error_scale;         /* |error| mapped to full colour in the error PNG */
    double metrics_s, output_s;
    int threads;
} RunReport;

/* Stem of the output files: the technique name, or "reference". */
const char *report_stem(const RunReport *r);
/* 1-2-5 scale at or above max_abs (>= 0.01). */
double report_error_scale(double max_abs);

/* Writes DIR/STEM.exr, DIR/STEM*.png and DIR/STEM.json; on failure nothing
 * of this run is left in DIR. `png` false skips the previews (and OIIO). */
bool report_write_all(RunReport *r, const char *dir, bool png, Error *err);
bool report_write_exr(const RunReport *r, const char *path, Error *err);
bool report_write_previews(const RunReport *r, const char *dir, Error *err);
bool report_write_record(const RunReport *r, const char *path, Error *err);
/* The same record onto an open stream (the Lua lab reads it from memory). */
void report_write_record_fp(const RunReport *r, FILE *fp);
/* The table for people: report_print_header's line (what runs on what),
 * then the timings, metrics and resources. The CLI prints the header as
 * soon as the scene is loaded and the rest when the run is done. */
void report_print_header(const Lab *lab, const Technique *tech, int light_index, FILE *fp);
void report_print_body(const RunReport *r, FILE *fp);
void report_print(const RunReport *r, FILE *fp);

#endif
