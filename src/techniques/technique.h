/* technique.h -- what a shadow technique declares: the single declaration of
 * its name, family, source section, typed parameters (default, range, unit,
 * one-line doc), the resource kinds it may acquire, and a per-view-sample
 * evaluation returning visibility in [0,1] (or RGB). The CLI, `list`, the Lua
 * layer, the tests and the docs all read these declarations through the
 * registry (registry.h); nothing lists techniques or parameters elsewhere. */
#ifndef SL_TECHNIQUE_H
#define SL_TECHNIQUE_H
#include <stdint.h>
#include "resources/resources.h"
#include "rt/view.h"

typedef enum ParamType { PARAM_INT, PARAM_FLOAT, PARAM_ENUM, PARAM_BOOL } ParamType;

typedef struct ParamDesc {
    const char *name;
    ParamType type;
    double def, min, max;        /* closed range; enums: index range; bools: [0, 1] */
    const char *unit;            /* "world units", "texels", "radians", "" */
    const char *doc;             /* one line */
    const char *const *choices;  /* PARAM_ENUM: NULL-terminated names, value = index */
} ParamDesc;

#define TECH_MAX_PARAMS 64

/* When a parameter acts, read against the technique's own values: outside
 * it the parameter changes nothing, so `list` and the docs print it and the
 * configuration key leaves the parameter out (registry.h). `when` holds
 * alternatives joined by " or ", each clauses joined by " and ", each clause
 * NAME=V or NAME!=V with V one value or several joined by '|' (enum names,
 * true/false, numbers), e.g. "sampling=poisson|regular". */
typedef struct ParamCondition {
    const char *param;
    const char *when;
} ParamCondition;

/* Light kinds a technique handles, as a bit set of LightKind. */
#define LIGHT_BIT(kind) (1u << (kind))
#define LIGHTS_DELTA (LIGHT_BIT(LIGHT_POINT) | LIGHT_BIT(LIGHT_SPOT) | LIGHT_BIT(LIGHT_DIRECTIONAL))
#define LIGHTS_AREA \
    (LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_TEXTURED_RECT))
#define LIGHTS_ALL (LIGHTS_DELTA | LIGHTS_AREA)

/* Everything an evaluation may read. Samples whose class is not
 * SAMPLE_LIT_CANDIDATE may be skipped: the engine overwrites them. */
typedef struct TechContext {
    const Scene *scene;
    int light_index;
    const Light *light;
    const ViewSamples *vs;
    const uint8_t *cls;          /* SampleClass per view sample */
    ResourceManager *rm;
    const double *params;        /* values in declaration order */
    int channels;                /* 1, or 3 for RGB visibility (textured lights) */
    /* Auxiliary per-sample outputs (Technique.aux), aux[(size_t)s * n + k] for
     * sample s and the k-th of the n names; NULL when the technique has none. */
    float *aux;
} TechContext;

typedef struct Technique {
    const char *name;
    const char *family;          /* "ray traced", "shadow map", "filtered", "soft", ... */
    const char *source;          /* seed section it implements, e.g. "course §2.1" */
    const char *summary;         /* one line */
    const ParamDesc *params;
    int num_params;
    const char *const *resources;/* resource kinds it may acquire, NULL-terminated */
    bool rgb;                    /* evaluates 3 channels when ctx->channels == 3 */
    unsigned lights;             /* LIGHT_BIT set of the light kinds it handles; others are refused */
    const char *main_param;      /* the knob sweeps vary first (a kernel, layers, terms); NULL: none */
    /* Parameters that act only under a condition, ended by {NULL, NULL};
     * NULL: none. The shared map parameters' own (smap.h) apply to every
     * technique whose table starts with them. */
    const ParamCondition *conditions;
    /* Acquire resources and build per-run state (may be NULL on success). */
    bool (*prepare)(const TechContext *ctx, void **state, Error *err);
    /* Visibility of samples [begin, end) into out[(s - begin) * channels + c];
     * called in parallel on disjoint ranges. */
    void (*evaluate)(const void *state, const TechContext *ctx, int begin, int end, float *out);
    void (*release)(void *state);
    /* Names of auxiliary per-sample channels evaluate writes (NULL-terminated,
     * or NULL for none), e.g. seed 001's subdivision level: the EXR stores
     * them as aux.NAME, the record summarises them over the lit candidates. */
    const char *const *aux;
} Technique;

/* Number of auxiliary channels a technique declares. */
static inline int tech_aux_count(const Technique *t)
{
    int n = 0;
    while (t->aux && t->aux[n]) n++;
    return n;
}

/* Store one visibility for sample s in an evaluate's output (all channels). */
static inline void tech_store(const TechContext *ctx, float *out, int begin, int s, float v)
{
    for (int c = 0; c < ctx->channels; c++) out[(size_t)(s - begin) * (size_t)ctx->channels + c] = v;
}

#endif
