/* stability.h -- the stability suite: every technique on every extreme case
 * that applies to it (issue 7). Cases are data (stability_cases.c); the
 * techniques come from the registry or from the caller, so a technique is
 * covered the day it is registered. Each run happens in a forked child with a
 * time bound, so a crash, hang or sanitizer report is one failed row, not the
 * end of the suite; runs on one case share its scene, BVH, view samples and
 * reference, built once in the process they are forked from. Asserted: output finite and in [0,1] on every lit
 * candidate, the documented limit where one exists, and refusals of invalid
 * input that name the parameter or key and its range. */
#ifndef SL_STABILITY_H
#define SL_STABILITY_H
#include "techniques/registry.h"

/* STAB_KNOWN: finite and in [0, 1], but short of the case's documented
 * limit in exactly the quantities an entry for its technique and light kind
 * lists, for a reason its paper states (stability_cases.c's known limits);
 * neither passed nor failed, and a failure once it meets the limit or
 * misses other quantities. */
typedef enum StabStatus { STAB_PASS, STAB_FAIL, STAB_NOT_APPLICABLE, STAB_KNOWN } StabStatus;
const char *stab_status_name(StabStatus s);

typedef struct StabOptions {
    bool quick;            /* reduced sizes (STAB_QUICK_*), one row per parameter (make test); every case still runs */
    double timeout_s;      /* per run; 0: 120 s. A case's shared preparation gets 3 times this */
    int threads;           /* per run; 0: the cores divided among the concurrent runs */
    const char *only;      /* NULL: all cases; else comma-separated terms: the cases whose name contains
                            * any TEXT term (all if there is none), less those containing a !TEXT term */
    const char *work_dir;  /* existing scratch folder for scene files and child logs */
    const char *scene_dir; /* if set, every case's scene file is kept there (to reproduce a row) */
    int jobs;              /* runs at once; 0: 1 */
    int sample_k, sample_m; /* sample_m > 1: only the runs whose FNV-1a hash of "technique case light"
                             * is K modulo M, a deterministic sample; every technique keeps ~1/M */
    bool sample_invert;     /* the runs of every class but K instead */
} StabOptions;

/* Quick runs: view size, reference light samples, and the cap on integer
 * parameters counted in texels (map resolutions) except in their own
 * probes; the full matrix keeps every default. */
#define STAB_QUICK_WIDTH 40
#define STAB_QUICK_HEIGHT 30
#define STAB_QUICK_REF_SAMPLES 16
#define STAB_QUICK_TEXELS 128

#define STAB_NAME_MAX 80
#define STAB_DETAIL_MAX 640

/* One row of the matrix: a technique (or "-" for engine input cases) on one
 * case with one light kind. Error fields are NAN where no reference was made. */
typedef struct StabResult {
    char technique[STAB_NAME_MAX];
    char case_name[STAB_NAME_MAX];
    char light[24];              /* light kind used; "" when none */
    StabStatus status;
    char detail[STAB_DETAIL_MAX];/* why it failed or does not apply; notes on a pass */
    long samples;                /* lit-candidate samples checked */
    long nonfinite, out_of_range;
    double mae, rmse, max_abs;   /* against the reference */
    double noise_rms;            /* the reference's own noise */
    int ref_samples;             /* light samples of that reference */
    double seconds;              /* wall time of the run, child start to exit */
    double prep_seconds;         /* the case's shared preparation (scene, BVH, view samples, reference) */
    int order;                   /* position in the matrix (technique-major); rows arrive as runs finish */
} StabResult;

typedef void (*StabRowFn)(const StabResult *row, void *user);

/* Run the suite for `techs` (n entries; NULL: every registered technique),
 * calling `row` after each run, in the order runs finish. Engine input cases run once, with technique
 * "-", unless `engine_cases` is false. Children are forked, so the calling
 * process must not have started threads yet (no Embree device, no OpenMP
 * region): this is checked. Returns false (err set) only when the suite
 * cannot run at all; failed rows are results, not errors. */
bool stab_run(const Technique *const *techs, int n, bool engine_cases, const StabOptions *o, StabRowFn row,
              void *user, Error *err);

/* The static cases, for --help and docs. */
int stab_case_count(void);
const char *stab_case_name(int i);
const char *stab_case_doc(int i);

/* Rows by status: what the CLI prints and the report heads with. */
typedef struct StabCounts { int pass, fail, na, known; } StabCounts;
StabCounts stab_count(const StabResult *rows, int n);

/* Write DIR/stability.{json,csv,md} atomically: the matrix (rows in their
 * `order`) with counts, errors and times, and the options it ran with. */
bool stab_report_write(const char *dir, const StabResult *rows, int n, const StabOptions *o, Error *err);

#endif
