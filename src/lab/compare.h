/* compare.h -- one comparison: the pipeline behind `shadowlab render |
 * reference | compare` and the Lua lab's render/reference/compare. The
 * technique's render (lab.h), the reference (the Lab's resources or the disk
 * cache), metrics and the signed error, then the outputs (report.h) from the
 * same result. Each call starts a fresh resource log on the Lab, so in a sweep
 * the record of every comparison says what it built and what it reused. */
#ifndef SL_COMPARE_H
#define SL_COMPARE_H
#include "lab/report.h"

typedef struct CompareRequest {
    const Technique *tech;  /* NULL: reference only */
    const double *params;   /* tech->num_params values */
    int light_index;
    int repeat, warmup;     /* timed and untimed evaluations (lab.h) */
    bool reference;         /* compute or load the reference; with tech, also the metrics */
    ReferenceParams ref;
    const char *cache_dir;  /* NULL: no disk cache */
    double time_budget_s;   /* > 0: stop timed repeats after this long (lab.h RenderTiming) */
    double error_scale;     /* > 0: |error| at full colour in the error PNG, fixed so a sweep's images
                               compare; 0: the largest |error| rounded up to 1, 2 or 5 x 10^k */
} CompareRequest;

typedef struct CompareResult {
    const Technique *tech;  /* NULL: reference only */
    double params[TECH_MAX_PARAMS];
    int light_index;
    RenderResult render;    /* when tech is set */
    const Reference *ref;   /* owned by the Lab's resource manager; NULL without reference */
    RefInfo ref_info;
    bool compared;          /* metrics and signed_error are filled */
    Metrics metrics;
    Image signed_error;
    double error_scale;     /* |error| at full colour in the error PNG */
    double metrics_s;
} CompareResult;

bool lab_compare(Lab *lab, const CompareRequest *req, CompareResult *out, Error *err);
void compare_result_free(CompareResult *r);

/* The RunReport of a result (for report_write_* and report_print); valid
 * while the Lab and the result live, and until the Lab's next comparison
 * (the record reads its resource log). */
RunReport compare_report(Lab *lab, const CompareResult *r, const char *command, int threads);

/* Stable key of a configuration: a hash of the scene's content hash, the
 * light, the technique's name and every parameter that acts under the
 * others (name and value; tech_param_acts), so a sweep over a parameter
 * outside its condition records one row, not duplicates. */
uint64_t lab_config_key(const Lab *lab, const Technique *t, const double *params, int light_index);

#endif
