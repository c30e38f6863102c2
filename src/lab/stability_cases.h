/* stability_cases.h -- internal interface between the stability runner
 * (stability.c) and its case table (stability_cases.c). A case is a scene
 * built as Lua text from a base (camera, one light of a kind the runner
 * picks, objects, extra files such as meshes and light images), how its
 * light kinds are chosen, and what is asserted beyond finite output in
 * [0,1]: a documented limit, or the words a refusal must contain. */
#ifndef SL_STABILITY_CASES_H
#define SL_STABILITY_CASES_H
#include <stddef.h>
#include "metrics/metrics.h"
#include "lab/lab.h"
#include "lab/stability.h"
#include "scene/scene.h"

#define STAB_MAX_FILES 4
#define STAB_FILE_MAX 8192

/* A file the scene needs next to it: bytes, or a 4x4 RGB EXR light image
 * whose texel (1, 2) holds `exr_texel` (others a gradient in [0.2, 1]). */
typedef struct StabFile {
    char name[64];
    bool exr;
    float exr_texel;
    char data[STAB_FILE_MAX];
    size_t size;
} StabFile;

/* Everything a case's scene text is made from. Lengths in world units,
 * angles in degrees, as in scene files. */
typedef struct SceneSpec {
    double cam_pos[3], cam_target[3], cam_up[3];
    double fov_deg, near_d, far_d;
    int width, height;
    double light_pos[3], light_aim[3]; /* directional: direction = aim - pos */
    double light_size;                 /* sphere, disk: radius; rect: half width and height */
    char light_extra[256];             /* Lua text replacing the generated light, if set */
    char objects[8192];                /* Lua text of the objects list's entries */
    StabFile files[STAB_MAX_FILES];
    int num_files;
} SceneSpec;

/* Sizes of a run: the view and the reference's light samples. */
typedef struct StabSettings {
    bool quick;
    int width, height;
    int ref_samples;
} StabSettings;

/* What a case's limit reads: the metrics over every lit candidate, and over
 * the hard shadow's band (stability_exec.c): the lit candidates where the
 * reference or `hard` is below metrics.h's lit bound, and every lit
 * candidate within STAB_BAND_PX view pixels of one. */
#define STAB_BAND_PX 2
typedef struct StabMeasure {
    Metrics all;
    Metrics band;
} StabMeasure;

/* What a limit measures, as bits: the quantities a row missed, and those a
 * known entry expects it to miss. */
typedef enum StabQuantity {
    STAB_Q_BAND_RMSE = 1u << 0,          /* RMSE over the hard shadow's band */
    STAB_Q_BAND_MISCLASSIFIED = 1u << 1, /* the band's share misclassified (|e| > 0.5) */
    STAB_Q_MISCLASSIFIED = 1u << 2,      /* the share of all lit candidates misclassified */
    STAB_Q_UMBRA_COUNT = 1u << 3,        /* lit candidates outside the reference's umbra */
    STAB_Q_UMBRA_LEAK = 1u << 4,         /* mean light leaked over the umbra */
    STAB_Q_UMBRA_LIT = 1u << 5,          /* the umbra's share estimated lit (> 0.5) */
    STAB_Q_BACKFACING = 1u << 6,         /* back-facing samples (none: the limit is missed) */
    STAB_Q_GEOMETRY = 1u << 7,           /* samples that hit geometry */
    STAB_Q_TERMINATOR = 1u << 8,         /* samples flagged terminator (none: the limit is missed) */
    STAB_Q_COUNT = 9
} StabQuantity;
/* The names of the quantities in `q`, joined by " and ". */
void stab_quantity_names(unsigned q, char *out, size_t n);

typedef enum CaseGroup { GROUP_LIGHT, GROUP_GEOMETRY, GROUP_CAMERA, GROUP_INPUT } CaseGroup;

/* Which of the technique's light kinds a case runs with. */
typedef enum LightPlan {
    PLAN_EACH,      /* every kind of the case the technique handles */
    PLAN_TWO,       /* the first delta kind and the first area kind it handles */
    PLAN_ONE,       /* the first kind it handles (heavy cases) */
    PLAN_NONE,      /* engine input cases: the scene must be refused */
} LightPlan;

typedef struct StabCase {
    const char *name;
    CaseGroup group;
    const char *doc;               /* one line: what it checks and what is asserted */
    unsigned lights;               /* LIGHT_BIT set the case is meaningful for */
    LightPlan plan;
    bool heavy;                    /* reduced reference samples */
    bool may_refuse;               /* a technique may refuse it with a clear message */
    bool full_sizes;               /* its limit is stated at the full matrix's sizes (view, reference
                                    * samples, maps): quick runs keep them */
    void (*build)(SceneSpec *s, LightKind kind, const StabSettings *st);
    /* Documented limit on the measurements against the reference; NULL:
     * none. Returns the StabQuantity bits it missed (0: met), the figures
     * in `why`. */
    unsigned (*limit)(const StabMeasure *m, char *why, size_t n);
    const char *refusal[3];        /* PLAN_NONE: words the refusal must contain */
    const struct KnownLimit *known;/* techniques known to miss `limit` here; ends at a NULL reason */
} StabCase;

/* A technique that misses a case's limit under the given light kinds, in
 * exactly the quantities `misses` (StabQuantity bits), for a reason its
 * source states: its rows are STAB_KNOWN; a row that meets the limit or
 * misses other quantities is STAB_FAIL. */
typedef struct KnownLimit {
    const char *technique;
    unsigned lights;
    unsigned misses;
    const char *reason;
} KnownLimit;
const KnownLimit *stab_known_limit(const StabCase *c, const Technique *t, LightKind kind);

/* Probes generated from each ParamDesc of a technique. */
typedef enum ParamProbe {
    PROBE_NONE,
    PROBE_AT_MIN, PROBE_MIN_PLUS_ONE, PROBE_AT_MAX, /* render at the value */
    PROBE_FP32_EVSM, PROBE_FP32_EXP2, PROBE_FP32_EXP, /* floats: render at float32's exponential limits */
    PROBE_BELOW_MIN, PROBE_ABOVE_MAX,                /* refused naming the parameter and its range */
    PROBE_NONFINITE,                                 /* NaN and +-Inf refused, also raw in lab_render */
    PROBE_ALL,                                       /* quick runs: every probe above in one run */
    PROBE_COUNT
} ParamProbe;

/* One run: a technique (NULL for engine input cases) on a case, or on a
 * parameter probe (c == NULL) over the base scene, with one light kind. */
typedef struct StabJob {
    const Technique *tech;
    const StabCase *c;
    int param;
    ParamProbe probe;
    LightKind kind;
    StabSettings st;
    int threads;
    int order;                  /* the row's position in the matrix */
    char name[STAB_NAME_MAX];   /* the row's case name */
} StabJob;

/* What every run on one scene shares, built once in the process the runs
 * are forked from (copy on write): the loaded scene and its BVH, the view
 * samples, classes and reference in the Lab's resource manager. Built on
 * one thread, so that forking it is safe. lab is NULL for engine input
 * cases, whose runs load (and must be refused) the scene themselves. */
typedef struct StabShared {
    Lab *lab;
    const char *scene_path;
} StabShared;

/* Open the scene of `c` (NULL: the base scene of parameter probes) and build
 * the shared resources; false with the reason in r->detail. */
bool stab_prepare(const StabCase *c, const StabSettings *st, const char *scene_path, StabShared *sh, StabResult *r);
void stab_shared_release(StabShared *sh);

/* The value a render probe sets, or the refused value of BELOW/ABOVE. */
double stab_probe_value(const ParamDesc *p, ParamProbe probe);
const char *stab_probe_suffix(ParamProbe probe);
bool stab_probe_applies(const ParamDesc *p, ParamProbe probe);
/* Runs in the forked child: the job on the shared scene, results into r. */
void stab_job_execute(const StabJob *j, const StabShared *sh, StabResult *r);

int stab_cases_count(void);
const StabCase *stab_cases_at(int i);

/* The base scene every case starts from (also used by parameter probes). */
void stab_base_scene(SceneSpec *s, const StabSettings *st);
/* The scene's Lua text with a light of `kind` (ignored when light_extra is set). */
bool stab_scene_text(const SceneSpec *s, LightKind kind, char *out, size_t n);
/* Append Lua text to s->objects. */
void stab_objects_add(SceneSpec *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* A file next to the scene; returns it for filling. */
StabFile *stab_file_add(SceneSpec *s, const char *name);

#endif
