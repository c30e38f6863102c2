/* lab.h -- one comparison's pipeline behind an opaque handle (Embree-style:
 * open, use, close). A Lab holds a loaded scene and a resource manager;
 * renders, references and metrics reuse whatever the manager already holds,
 * so a sweep in one process builds each resource once. The CLI and the Lua
 * bindings are thin layers over this. */
#ifndef SL_LAB_H
#define SL_LAB_H
#include "metrics/metrics.h"
#include "resources/standard.h"
#include "techniques/registry.h"

typedef struct Lab Lab;

Lab *lab_open(const char *scene_path, const char *const *overrides, int num_overrides, Error *err);
/* The same on a resource manager shared by several labs (the caller keeps it
 * alive longer than them): resources are keyed by content, so variants of a
 * scene (a light radius, a camera) reuse the BVH, view samples, maps and
 * references their keys say they share. NULL: the lab makes its own. */
Lab *lab_open_shared(const char *scene_path, const char *const *overrides, int num_overrides, ResourceManager *rm,
                     Error *err);
void lab_close(Lab *lab);
const Scene *lab_scene(const Lab *lab);
/* The scene overrides the Lab was opened with, as given ("key.path=value"). */
int lab_overrides(const Lab *lab, const char *const **overrides);
ResourceManager *lab_resources(Lab *lab);
double lab_scene_load_seconds(const Lab *lab);
/* Check a 1-based light number against the scene; returns the 0-based index. */
bool lab_light_index(const Lab *lab, int light_number, int *index, Error *err);

typedef struct RenderRequest {
    const Technique *tech;
    const double *params; /* tech->num_params values */
    int light_index;
    int repeat;           /* evaluations timed; >= 1 */
} RenderRequest;

#define RENDER_MAX_TECH_RESOURCES 16

typedef struct RenderResult {
    Image visibility;      /* per view sample, 1 or 3 channels */
    Image aux;             /* the technique's auxiliary channels (Technique.aux); empty when none */
    double view_s;         /* view samples + classes (0 when reused) */
    double prepare_s;      /* the technique's resource acquisition and set-up */
    double eval_median_s, eval_min_s, eval_max_s; /* over the timed evaluations */
    /* CPU seconds the evaluation loop ran (each thread's CLOCK_THREAD_CPUTIME_ID
     * over its share of the rows; medians over the timed evaluations): on all
     * its threads together, and on the busiest. What other programs take of
     * the machine is in neither, so a 1-thread run's eval_cpu_s over a k-thread
     * run's eval_busiest_s is the speed-up k cores of its own would give, and
     * eval_cpu_s growing with k is contention (shared caches, memory). */
    double eval_cpu_s, eval_busiest_s;
    int repeat;
    int warmup;
    /* What the technique's prepare depends on (a resources.h scope: what it
     * acquired and what those were built from, each with its category; the
     * first RENDER_MAX_TECH_RESOURCES listed, all counted below). */
    ResourceEvent tech_resources[RENDER_MAX_TECH_RESOURCES];
    int num_tech_resources;
    double tech_build_s;   /* sum of the frame ones' own build times (medians of `repeat` builds), also when reused */
    double gbuffer_s;      /* sum of the G-buffer ones' (view samples, classes, their BVH): left out */
    double setup_s;        /* sum of the set-up ones' (constant tables, built once): left out */
    double prepare_own_s;  /* prepare_s net of the builds inside it, every repeat and category */
    /* Frame time: what one frame costs a renderer that rebuilds the
     * technique's resources every frame (a shadow map is re-rendered each
     * frame) = tech_build_s + prepare_own_s + eval_median_s. A reduction the
     * map's fit makes over the view samples (fit=view's bounds, SDSM's
     * min/max) is in the map's own build time. It leaves out the G-buffer,
     * the set-up tables and the reference, and is the same whether this run
     * built the resources or reused them. */
    double frame_s;
    /* Machine-independent work (core/counters.h), counted like the times:
     * eval_work is one evaluation's (the last; each does the same work),
     * frame_work the frame's = the frame resources' own builds' (also when
     * reused) + the prepare's own + eval_work; frame_bytes the frame
     * resources' bytes. lit_candidates: the samples evaluated, what the
     * record's per-sample counts divide by. */
    WorkCounters eval_work, frame_work;
    size_t frame_bytes;
    long lit_candidates;
} RenderResult;

bool lab_render(Lab *lab, const RenderRequest *req, RenderResult *out, Error *err);
/* How evaluations are timed: `warmup` untimed ones first (caches, page
 * faults), in [0, 1000]; with budget_s > 0 the timed repeats stop once they
 * have taken budget_s seconds (at least one runs), and a warm-up that alone
 * takes budget_s counts as the one timed evaluation (caches cannot matter at
 * that length). RenderResult's repeat and warmup say how many ran. */
typedef struct RenderTiming {
    int warmup;
    double budget_s; /* 0: exactly req->repeat timed evaluations */
} RenderTiming;
bool lab_render_timed(Lab *lab, const RenderRequest *req, const RenderTiming *timing, RenderResult *out, Error *err);
void render_result_free(RenderResult *r);

#endif
