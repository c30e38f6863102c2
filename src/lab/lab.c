/* lab.c -- scene + resource manager, and the render stage: view samples and
 * classes from the manager, the technique's prepare, then `repeat` timed
 * evaluations in parallel over rows. Samples that are not lit candidates get
 * the reference's convention (0, or 1 on non-receivers) after evaluation. */
#include "lab/lab.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "core/progress.h"
#include "core/timer.h"

#define EVAL_GRABS_PER_THREAD 16 /* evaluate_all's runs of rows per thread */

struct Lab {
    Scene scene;
    ResourceManager *rm;
    bool owns_rm;
    double load_s;
    char **overrides; /* the scene overrides as given ("lights[1].radius=0.1"), for records */
    int num_overrides;
};

static bool keep_overrides(Lab *lab, const char *const *overrides, int n)
{
    lab->overrides = n > 0 ? calloc((size_t)n, sizeof *lab->overrides) : NULL;
    if (n > 0 && !lab->overrides) return false;
    for (int i = 0; i < n; i++) {
        lab->overrides[i] = strdup(overrides[i]);
        if (!lab->overrides[i]) return false;
        lab->num_overrides = i + 1;
    }
    return true;
}

Lab *lab_open_shared(const char *scene_path, const char *const *overrides, int num_overrides, ResourceManager *rm,
                     Error *err)
{
    Lab *lab = calloc(1, sizeof *lab);
    if (!lab) { error_set(err, "out of memory"); return NULL; }
    double t0 = timer_now_s();
    if (!scene_load(scene_path, overrides, num_overrides, &lab->scene, err)) {
        free(lab);
        return NULL;
    }
    lab->load_s = timer_now_s() - t0;
    lab->owns_rm = rm == NULL;
    lab->rm = rm ? rm : rm_create();
    if (!lab->rm || !keep_overrides(lab, overrides, num_overrides)) {
        lab_close(lab);
        error_set(err, "out of memory");
        return NULL;
    }
    return lab;
}

Lab *lab_open(const char *scene_path, const char *const *overrides, int num_overrides, Error *err)
{
    return lab_open_shared(scene_path, overrides, num_overrides, NULL, err);
}

void lab_close(Lab *lab)
{
    if (!lab) return;
    if (lab->owns_rm) rm_destroy(lab->rm);
    scene_free(&lab->scene);
    for (int i = 0; i < lab->num_overrides; i++) free(lab->overrides[i]);
    free(lab->overrides);
    free(lab);
}

const Scene *lab_scene(const Lab *lab) { return &lab->scene; }
ResourceManager *lab_resources(Lab *lab) { return lab->rm; }
double lab_scene_load_seconds(const Lab *lab) { return lab->load_s; }

int lab_overrides(const Lab *lab, const char *const **overrides)
{
    *overrides = (const char *const *)lab->overrides;
    return lab->num_overrides;
}

bool lab_light_index(const Lab *lab, int number, int *index, Error *err)
{
    if (number < 1 || number > lab->scene.num_lights)
        return error_set(err, "--light %d outside [1, %d] (the scene's lights)", number, lab->scene.num_lights);
    *index = number - 1;
    return true;
}

/* One evaluation's times: wall clock, and the CPU seconds its threads ran
 * inside the loop, all of them together and the busiest one. */
typedef struct EvalTimes {
    double wall_s, cpu_s, busiest_s;
} EvalTimes;

/* One timed evaluation of every row, in parallel: runs of `grab` rows to
 * whichever thread is free (rows differ in cost), EVAL_GRABS_PER_THREAD runs
 * a thread on average. One row a grab cost a hand-over of the loop's shared
 * counter per row: on two vCPUs far apart (bench/README.md, step 8) that
 * made shadow_volume's 0.3 ms evaluation 1.12-1.16x faster on 2 threads
 * instead of 1.93-2.13x; a run of rows keeps the imbalance at the end under
 * one run's cost. Its work into *work (counted by the shared readers in
 * every thread, core/counters.h). Each thread reads its own CPU clock
 * around its share of the rows. */
static EvalTimes evaluate_all(const Technique *t, const void *state, const TechContext *ctx, Image *out,
                              WorkCounters *work)
{
    const ViewSamples *vs = ctx->vs;
    WorkCounters w0, w1;
    work_snapshot(&w0);
    double cpu_s = 0.0, busiest_s = 0.0;
    double t0 = timer_now_s();
#pragma omp parallel reduction(+ : cpu_s) reduction(max : busiest_s)
    {
        double c0 = timer_thread_cpu_s();
        int grab = vs->height / (omp_get_num_threads() * EVAL_GRABS_PER_THREAD);
#pragma omp for schedule(dynamic, grab > 1 ? grab : 1) nowait
        for (int y = 0; y < vs->height; y++) {
            int begin = y * vs->width;
            t->evaluate(state, ctx, begin, begin + vs->width, out->data + (size_t)begin * (size_t)ctx->channels);
        }
        double own_s = timer_thread_cpu_s() - c0;
        cpu_s += own_s;
        busiest_s = own_s; /* this thread's copy; the reduction keeps the largest */
    }
    EvalTimes et = {timer_now_s() - t0, cpu_s, busiest_s};
    work_snapshot(&w1);
    *work = work_diff(&w1, &w0);
    return et;
}

/* Convention for samples outside the evaluated class; broadcast a 1-channel
 * technique to the reference's 3 channels. */
static void finish_image(Image *img, int tech_channels, const uint8_t *cls)
{
    int nc = img->channels;
    long count = (long)img->width * img->height;
    for (long s = count - 1; s >= 0; s--) {
        float *px = img->data + s * nc;
        float v = tech_channels == 1 ? img->data[s * tech_channels] : px[0];
        if (cls[s] != SAMPLE_LIT_CANDIDATE) v = cls[s] == SAMPLE_NOT_RECEIVER ? 1.0f : 0.0f;
        if (tech_channels == 1 || cls[s] != SAMPLE_LIT_CANDIDATE)
            for (int c = 0; c < nc; c++) px[c] = v;
    }
}

/* Warm-ups, then timed repeats (see RenderTiming); sets repeat and warmup to
 * the counts that ran, and the medians of the timed ones' times. */
static bool run_evaluations(const RenderRequest *req, const RenderTiming *timing, const void *state,
                            const TechContext *ctx, RenderResult *out)
{
    double *times = malloc(sizeof(double) * 3 * (size_t)req->repeat);
    if (!times) return false;
    double *cpu = times + req->repeat, *busiest = cpu + req->repeat;
    int n = 0;
    double total = 0;
    Progress prog; /* the progress line's "evaluate 3/10" (core/progress.h) */
    progress_begin(&prog, "evaluate", timing->warmup + req->repeat);
    for (out->warmup = 0; out->warmup < timing->warmup; out->warmup++) {
        EvalTimes et = evaluate_all(req->tech, state, ctx, &out->visibility, &out->eval_work);
        progress_add(&prog, 1);
        if (timing->budget_s > 0 && et.wall_s >= timing->budget_s) {
            /* long enough that caches cannot matter: it is the timed one */
            times[0] = total = et.wall_s, cpu[0] = et.cpu_s, busiest[0] = et.busiest_s, n = 1;
            break;
        }
    }
    while (n < req->repeat && (n == 0 || timing->budget_s <= 0 || total < timing->budget_s)) {
        EvalTimes et = evaluate_all(req->tech, state, ctx, &out->visibility, &out->eval_work);
        times[n] = et.wall_s, cpu[n] = et.cpu_s, busiest[n] = et.busiest_s;
        total += times[n++];
        progress_add(&prog, 1);
    }
    progress_end(&prog);
    out->repeat = n;
    out->eval_median_s = timer_median(times, n); /* sorts: min and max at the ends */
    out->eval_min_s = times[0];
    out->eval_max_s = times[n - 1];
    out->eval_cpu_s = timer_median(cpu, n);
    out->eval_busiest_s = timer_median(busiest, n);
    free(times);
    return true;
}

/* The prepare's scope: its resources and their own build times summed by
 * category (the frame's, the G-buffer's, the set-up's); the frame ones'
 * own work and bytes. */
static void collect_tech_resources(const ResourceManager *rm, RenderResult *out)
{
    for (int i = 0; i < rm_scope_count(rm); i++) {
        const ResourceEvent *ev = rm_scope_event(rm, i);
        if (ev->category == RES_FRAME) {
            out->tech_build_s += ev->own_s;
            work_add(&out->frame_work, &ev->work);
            out->frame_bytes += ev->bytes;
        }
        if (ev->category == RES_GBUFFER) out->gbuffer_s += ev->own_s;
        if (ev->category == RES_SETUP) out->setup_s += ev->own_s;
        if (i < RENDER_MAX_TECH_RESOURCES) out->tech_resources[out->num_tech_resources++] = *ev;
    }
}

bool lab_render(Lab *lab, const RenderRequest *req, RenderResult *out, Error *err)
{
    RenderTiming untimed_warmup_none = {0, 0.0};
    return lab_render_timed(lab, req, &untimed_warmup_none, out, err);
}

bool lab_render_timed(Lab *lab, const RenderRequest *req, const RenderTiming *timing, RenderResult *out, Error *err)
{
    memset(out, 0, sizeof *out);
    const Scene *sc = &lab->scene;
    if (req->repeat < 1 || req->repeat > 10000) return error_set(err, "--repeat %d outside [1, 10000]", req->repeat);
    if (timing->warmup < 0 || timing->warmup > 1000)
        return error_set(err, "--warmup %d outside [0, 1000]", timing->warmup);
    if (!(timing->budget_s >= 0 && timing->budget_s <= 1e6))
        return error_set(err, "time budget %g s outside [0, 1e6]", timing->budget_s);
    if (!tech_params_check(req->tech, req->params, err)) return false;
    if (!tech_check_light(req->tech, &sc->lights[req->light_index], req->light_index + 1, err)) return false;
    double t0 = timer_now_s();
    const ViewSamples *vs = res_view_samples(lab->rm, sc, err);
    const uint8_t *cls = vs ? res_classes(lab->rm, sc, req->light_index, err) : NULL;
    if (!cls) return false;
    out->view_s = timer_now_s() - t0;
    int ref_channels = reference_channels(sc, req->light_index, MEASURE_VISIBILITY);
    TechContext ctx = {sc, req->light_index, &sc->lights[req->light_index], vs, cls, lab->rm, req->params,
                       req->tech->rgb ? ref_channels : 1, NULL};
    if (!image_init(&out->visibility, vs->width, vs->height, ref_channels, err)) return false;
    int num_aux = tech_aux_count(req->tech);
    if (num_aux > 0) {
        if (!image_init(&out->aux, vs->width, vs->height, num_aux, err)) {
            image_free(&out->visibility);
            return false;
        }
        ctx.aux = out->aux.data;
    }
    void *state = NULL;
    rm_scope_begin(lab->rm, req->repeat, timing->budget_s); /* frame resources built here: `repeat` times */
    Progress prog;
    progress_begin(&prog, "prepare", 0);
    WorkCounters w0, w1;
    work_snapshot(&w0);
    t0 = timer_now_s();
    bool prepared = req->tech->prepare(&ctx, &state, err);
    out->prepare_s = timer_now_s() - t0;
    work_snapshot(&w1);
    progress_end(&prog);
    rm_scope_end(lab->rm);
    if (!prepared) {
        render_result_free(out);
        return error_prefix(err, "%s: ", req->tech->name);
    }
    collect_tech_resources(lab->rm, out);
    double own_s = out->prepare_s - rm_scope_build_s(lab->rm);
    out->prepare_own_s = own_s > 0.0 ? own_s : 0.0;
    WorkCounters prepare_work = work_diff(&w1, &w0), built = rm_scope_work(lab->rm),
                 prepare_own_work = work_diff(&prepare_work, &built);
    bool ok = run_evaluations(req, timing, state, &ctx, out);
    out->frame_s = out->tech_build_s + out->prepare_own_s + out->eval_median_s;
    work_add(&out->frame_work, &prepare_own_work);
    work_add(&out->frame_work, &out->eval_work);
    for (long s = 0; s < (long)vs->width * vs->height; s++) out->lit_candidates += cls[s] == SAMPLE_LIT_CANDIDATE;
    if (req->tech->release) req->tech->release(state);
    if (!ok) {
        render_result_free(out);
        return error_set(err, "out of memory");
    }
    finish_image(&out->visibility, ctx.channels, cls);
    return true;
}

void render_result_free(RenderResult *r)
{
    image_free(&r->visibility);
    image_free(&r->aux);
}
