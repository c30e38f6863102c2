/* test_resource_scope.c -- resource scopes (resources.h): a scope names what
 * a stage depends on, also when it reuses a resource whose dependencies it
 * never asks for again, and the own build times of those resources add up to
 * the cost of building them from nothing; a technique's frame time (lab.h)
 * is the same whether its resources were built in this run or reused; a time
 * budget stops the timed repeats and the result says how many ran. Frame
 * time on map techniques: fit=view charges the fit's reduction, not the view
 * samples (the G-buffer); a constant table is set-up, built once across a
 * sweep; the frame resources' builds are repeated with the evaluations and
 * their median reported; the evaluation's CPU time sums every thread's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <omp.h>
#include "core/bufpool.h"
#include "fixtures.h"
#include "lab/compare.h"
#include "test.h"

/* A fake resource: sleeps `ms`, then optionally acquires a dependency;
 * builds and destroys are counted, and per id (below FAKE_IDS) the most
 * builds alive at once. */
#define FAKE_IDS 8
typedef struct Fake { int id; } Fake;
typedef struct FakeArgs { ResourceManager *rm; int id; int ms; int dep_id; int dep_ms; } FakeArgs;
static int fake_builds, fake_destroys, fake_alive[FAKE_IDS], fake_most_alive[FAKE_IDS];

static size_t fake_bytes(const void *r) { (void)r; return sizeof(Fake); }
static void fake_destroy(void *r)
{
    fake_destroys++;
    fake_alive[((Fake *)r)->id]--;
    free(r);
}
static const ResourceKind kind_fake = {"fake", fake_bytes, fake_destroy, RES_FRAME};

static void sleep_ms(int ms)
{
    struct timespec ts = {0, (long)ms * 1000000L};
    nanosleep(&ts, NULL);
}

static const Fake *acquire_fake(ResourceManager *rm, int id, int ms, int dep_id, int dep_ms, Error *err);

static void *build_fake(const void *args, Error *err)
{
    const FakeArgs *a = args;
    fake_builds++;
    sleep_ms(a->ms);
    if (a->dep_id >= 0 && !acquire_fake(a->rm, a->dep_id, a->dep_ms, -1, 0, err)) return NULL;
    Fake *f = malloc(sizeof *f);
    if (!f) return NULL;
    f->id = a->id;
    if (++fake_alive[f->id] > fake_most_alive[f->id]) fake_most_alive[f->id] = fake_alive[f->id];
    return f;
}

static const Fake *acquire_fake(ResourceManager *rm, int id, int ms, int dep_id, int dep_ms, Error *err)
{
    FakeArgs a = {rm, id, ms, dep_id, dep_ms};
    char desc[32];
    snprintf(desc, sizeof desc, "fake %d", id);
    return rm_acquire(rm, &kind_fake, (uint64_t)id, desc, build_fake, &a, err);
}

static const ResourceEvent *scope_find(const ResourceManager *rm, uint64_t key)
{
    for (int i = 0; i < rm_scope_count(rm); i++)
        if (rm_scope_event(rm, i)->key == key) return rm_scope_event(rm, i);
    return NULL;
}

TEST(test_scope_names_dependencies_of_reused_resources)
{
    Error err;
    ResourceManager *rm = rm_create();
    /* Stage 1 builds 2, which builds its dependency 1 inside its own build. */
    rm_scope_begin(rm, 1, 0.0);
    CHECK(acquire_fake(rm, 2, 30, 1, 20, &err));
    rm_scope_end(rm);
    CHECK(rm_scope_count(rm) == 2);
    const ResourceEvent *outer = scope_find(rm, 2), *inner = scope_find(rm, 1);
    CHECK(outer && inner && outer->built && inner->built);
    /* own time excludes the nested build; inclusive time does not */
    CHECK_MSG(outer->build_s >= inner->build_s + outer->own_s - 1e-9, "build_s %g own %g inner %g", outer->build_s,
              outer->own_s, inner->build_s);
    CHECK_MSG(outer->own_s > 0.02 && outer->own_s < outer->build_s - 0.015, "own_s %g build_s %g", outer->own_s,
              outer->build_s);
    double cost_built = outer->own_s + inner->own_s;
    /* Stage 2 reuses 2 and never asks for 1: the scope still lists 1. */
    rm_scope_begin(rm, 1, 0.0);
    CHECK(acquire_fake(rm, 2, 30, 1, 20, &err));
    rm_scope_end(rm);
    CHECK(rm_scope_count(rm) == 2);
    CHECK(!scope_find(rm, 2)->built && !scope_find(rm, 1)->built);
    CHECK_NEAR(scope_find(rm, 2)->own_s + scope_find(rm, 1)->own_s, cost_built, 1e-12);
    /* Acquisitions outside a scope are not recorded in it. */
    rm_scope_begin(rm, 1, 0.0);
    rm_scope_end(rm);
    CHECK(acquire_fake(rm, 3, 0, -1, 0, &err));
    CHECK(rm_scope_count(rm) == 0);
    rm_destroy(rm);
}

static const char *const scope_scene =
    "return {\n"
    "  camera = { position = {0, 3, 5}, target = {0, 0.4, 0}, width = 48, height = 36 },\n"
    "  lights = { { type = 'sphere', position = {1, 4, 1}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane', size = {8, 8} }, { shape = 'sphere', radius = 0.5, translate = {0, 0.8, 0} } },\n"
    "}\n";

TEST(test_frame_time_counts_reused_technique_resources)
{
    Error err;
    Lab *lab = fixture_lab("scope.lua", scope_scene);
    CHECK(lab);
    const Technique *hard = tech_find("hard", &err);
    CHECK(hard);
    double params[TECH_MAX_PARAMS];
    tech_params_default(hard, params);
    CompareRequest rq = {hard, params, 0, 2, 1, false, {MEASURE_VISIBILITY, 16, SAMPLING_R2, 1, false}, NULL, 0.0, 0.0};
    CompareResult first, second;
    CHECK(lab_compare(lab, &rq, &first, &err));
    CHECK(lab_compare(lab, &rq, &second, &err));
    /* hard needs the casters' BVH; the view samples built it first (every
     * object casts: one key), the second run reuses it: both count it. */
    CHECK(first.render.num_tech_resources == 1 && second.render.num_tech_resources == 1);
    CHECK(strcmp(second.render.tech_resources[0].kind, "embree_bvh") == 0);
    CHECK(!second.render.tech_resources[0].built);
    CHECK(second.render.tech_build_s > 0);
    CHECK_NEAR(first.render.tech_build_s, second.render.tech_build_s, 1e-12);
    CHECK(second.render.frame_s >= second.render.tech_build_s + second.render.eval_median_s);
    CHECK(second.render.warmup == 1 && second.render.repeat == 2);
    /* the second run's log is its own: everything reused */
    for (int i = 0; i < rm_log_count(lab_resources(lab)); i++) CHECK(!rm_log_event(lab_resources(lab), i)->built);
    compare_result_free(&first);
    compare_result_free(&second);
    lab_close(lab);
}

TEST(test_config_key_depends_on_every_parameter)
{
    Error err;
    Lab *lab = fixture_lab("key.lua", scope_scene);
    CHECK(lab);
    const Technique *hard = tech_find("hard", &err);
    double a[TECH_MAX_PARAMS], b[TECH_MAX_PARAMS];
    tech_params_default(hard, a);
    tech_params_default(hard, b);
    CHECK(lab_config_key(lab, hard, a, 0) == lab_config_key(lab, hard, b, 0));
    b[0] = 2.0;
    CHECK(lab_config_key(lab, hard, a, 0) != lab_config_key(lab, hard, b, 0));
    lab_close(lab);
}

TEST(test_time_budget_stops_timed_repeats_and_says_how_many_ran)
{
    Error err;
    Lab *lab = fixture_lab("budget.lua", scope_scene);
    CHECK(lab);
    const Technique *hard = tech_find("hard", &err);
    double params[TECH_MAX_PARAMS];
    tech_params_default(hard, params);
    RenderRequest rq = {hard, params, 0, 5};
    RenderResult unlimited, tiny;
    RenderTiming none = {1, 0.0}, budget = {1, 1e-9};
    CHECK(lab_render_timed(lab, &rq, &none, &unlimited, &err));
    CHECK(unlimited.repeat == 5 && unlimited.warmup == 1);
    /* every evaluation takes longer than 1 ns: the warm-up is the one timed evaluation */
    CHECK(lab_render_timed(lab, &rq, &budget, &tiny, &err));
    CHECK_MSG(tiny.repeat == 1 && tiny.warmup == 0, "repeat %d warmup %d", tiny.repeat, tiny.warmup);
    CHECK(tiny.eval_min_s == tiny.eval_median_s);
    render_result_free(&unlimited);
    render_result_free(&tiny);
    RenderTiming negative = {1, -1.0};
    CHECK(!lab_render_timed(lab, &rq, &negative, &tiny, &err) && strstr(err.msg, "budget"));
    lab_close(lab);
}

/* The evaluation's CPU seconds (lab.h) sum every thread's share and name the
 * busiest: one thread's are both its own, two threads' busiest is within the
 * sum, and no thread ran longer than the evaluation took. */
TEST(test_evaluation_cpu_time_sums_every_thread_and_names_the_busiest)
{
    Error err;
    Lab *lab = fixture_lab("cpu.lua", scope_scene);
    CHECK(lab);
    const Technique *hard = tech_find("hard", &err);
    double params[TECH_MAX_PARAMS];
    tech_params_default(hard, params);
    RenderRequest rq = {hard, params, 0, 3};
    RenderTiming warm = {1, 0.0};
    int threads = omp_get_max_threads();
    for (int n = 1; n <= 2; n++) {
        RenderResult r;
        omp_set_num_threads(n);
        CHECK(lab_render_timed(lab, &rq, &warm, &r, &err));
        CHECK_MSG(r.eval_busiest_s > 0.0 && r.eval_busiest_s <= r.eval_cpu_s, "%d threads: busiest %g s, all %g s", n,
                  r.eval_busiest_s, r.eval_cpu_s);
        CHECK_MSG(r.eval_busiest_s <= r.eval_max_s && r.eval_cpu_s <= n * r.eval_max_s,
                  "%d threads: CPU %g s (busiest %g s) over a %g s evaluation", n, r.eval_cpu_s, r.eval_busiest_s,
                  r.eval_max_s);
        if (n == 1) CHECK(r.eval_cpu_s == r.eval_busiest_s);
        render_result_free(&r);
    }
    omp_set_num_threads(threads);
    lab_close(lab);
}

TEST(test_scope_builds_frame_resources_repeatedly_and_reports_the_median)
{
    Error err;
    ResourceManager *rm = rm_create();
    fake_builds = fake_destroys = 0;
    memset(fake_most_alive, 0, sizeof fake_most_alive);
    /* 2 builds its dependency 1: each is built 3 times, 1 inside 2's first build */
    rm_scope_begin(rm, 3, 0.0);
    const Fake *f = acquire_fake(rm, 2, 1, 1, 1, &err);
    rm_scope_end(rm);
    CHECK(f && f->id == 2);
    CHECK_MSG(fake_builds == 6 && fake_destroys == 4, "builds %d destroys %d", fake_builds, fake_destroys);
    CHECK(scope_find(rm, 2)->builds == 3 && scope_find(rm, 1)->builds == 3);
    CHECK(scope_find(rm, 2)->category == RES_FRAME);
    /* each rebuild after the one before is destroyed (its buffers serve the next) */
    CHECK_MSG(fake_most_alive[1] == 1 && fake_most_alive[2] == 1, "alive at once: %d, %d", fake_most_alive[1],
              fake_most_alive[2]);
    /* the cached value is the last build's; a later scope reuses it and its medians */
    rm_scope_begin(rm, 3, 0.0);
    CHECK(acquire_fake(rm, 2, 1, 1, 1, &err) == f);
    rm_scope_end(rm);
    CHECK(fake_builds == 6 && scope_find(rm, 2)->builds == 3 && !scope_find(rm, 2)->built);
    /* one build per resource with builds = 1, and outside a scope */
    rm_scope_begin(rm, 1, 0.0);
    CHECK(acquire_fake(rm, 3, 0, -1, 0, &err));
    rm_scope_end(rm);
    CHECK(acquire_fake(rm, 4, 0, -1, 0, &err));
    CHECK(fake_builds == 8 && scope_find(rm, 3)->builds == 1);
    /* a budget every build exceeds (1 ns): the first build is the one timed */
    rm_scope_begin(rm, 5, 1e-9);
    CHECK(acquire_fake(rm, 5, 0, -1, 0, &err));
    rm_scope_end(rm);
    CHECK(fake_builds == 9 && scope_find(rm, 5)->builds == 1);
    rm_destroy(rm);
}

static bool set_params(const Technique *t, const char *const *assignments, double *params, Error *err)
{
    tech_params_default(t, params);
    for (; *assignments; assignments++)
        if (!tech_param_parse(t, *assignments, params, err)) return false;
    return true;
}

static bool compare_tech(Lab *lab, const char *name, const char *const *assignments, int repeat, CompareResult *out)
{
    Error err;
    static double params[TECH_MAX_PARAMS];
    const Technique *t = tech_find(name, &err);
    if (!t || !set_params(t, assignments, params, &err)) return false;
    CompareRequest rq = {t, params, 0, repeat, 0, false, {MEASURE_VISIBILITY, 16, SAMPLING_R2, 1, false}, NULL, 0.0, 0.0};
    return lab_compare(lab, &rq, out, &err);
}

static const ResourceEvent *tech_event(const RenderResult *r, const char *kind)
{
    for (int i = 0; i < r->num_tech_resources; i++)
        if (strcmp(r->tech_resources[i].kind, kind) == 0) return &r->tech_resources[i];
    return NULL;
}

/* frame = frame resources' own builds + the prepare's own set-up + median evaluation (lab.h) */
static bool frame_adds_up(const RenderResult *r)
{
    double frame = 0, gbuffer = 0, setup = 0;
    for (int i = 0; i < r->num_tech_resources; i++) {
        const ResourceEvent *ev = &r->tech_resources[i];
        frame += ev->category == RES_FRAME ? ev->own_s : 0.0;
        gbuffer += ev->category == RES_GBUFFER ? ev->own_s : 0.0;
        setup += ev->category == RES_SETUP ? ev->own_s : 0.0;
    }
    return fabs(frame - r->tech_build_s) < 1e-12 && fabs(gbuffer - r->gbuffer_s) < 1e-12 &&
           fabs(setup - r->setup_s) < 1e-12 &&
           fabs(r->frame_s - (r->tech_build_s + r->prepare_own_s + r->eval_median_s)) < 1e-12;
}

TEST(test_fit_view_frame_time_charges_the_reduction_not_the_view_samples)
{
    Lab *lab = fixture_lab("fitview.lua", scope_scene);
    CHECK(lab);
    const char *const fit_view[] = {"fit=view", "map_size=128", NULL};
    CompareResult c;
    CHECK(compare_tech(lab, "sm", fit_view, 1, &c));
    const RenderResult *r = &c.render;
    /* the map reads the view samples, their classes and (through them) the BVH: a renderer's G-buffer */
    const char *const gbuffer[] = {"view_samples", "sample_classes", "embree_bvh"};
    for (int i = 0; i < 3; i++) {
        const ResourceEvent *ev = tech_event(r, gbuffer[i]);
        CHECK_MSG(ev && ev->category == RES_GBUFFER, "%s: %s", gbuffer[i], ev ? resource_category_name(ev->category) : "absent");
    }
    /* the fit (the reduction over the visible samples) and the map are the frame's */
    const ResourceEvent *view = tech_event(r, "light_view"), *map = tech_event(r, "shadow_map");
    CHECK(view && view->built && view->category == RES_FRAME);
    CHECK(map && map->built && map->category == RES_FRAME);
    CHECK(r->gbuffer_s > 0 && frame_adds_up(r));
    compare_result_free(&c);
    lab_close(lab);
}

TEST(test_constant_tables_are_set_up_built_once_across_a_sweep)
{
    Lab *lab = fixture_lab("tables.lua", scope_scene);
    CHECK(lab);
    ResourceManager *rm = lab_resources(lab);
    const char *const k3[] = {"kernel=poisson", "samples=64", "K=3", "map_size=128", NULL};
    const char *const k5[] = {"kernel=poisson", "samples=64", "K=5", "map_size=128", NULL};
    const char *const map_size[] = {"kernel=poisson", "samples=64", "K=5", "map_size=64", NULL};
    CompareResult c;
    for (int run = 0; run < 3; run++) {
        if (run == 2) rm_clear(rm); /* a sweep dropping its resources between techniques */
        CHECK(compare_tech(lab, "pcf", run == 0 ? k3 : run == 1 ? k5 : map_size, 1, &c));
        const ResourceEvent *disk = tech_event(&c.render, "point_table");
        CHECK_MSG(disk && disk->category == RES_SETUP && disk->built == (run == 0), "run %d: disk %s", run,
                  disk ? (disk->built ? "built" : "reused") : "absent");
        CHECK(c.render.setup_s > 0 && frame_adds_up(&c.render));
        int logged = 0; /* the run's resource log says the same */
        for (int i = 0; i < rm_log_count(rm); i++) {
            const ResourceEvent *ev = rm_log_event(rm, i);
            if (strcmp(ev->kind, "point_table") == 0) logged += ev->built == (run == 0) ? 1 : 100;
        }
        CHECK(logged == 1);
        compare_result_free(&c);
    }
    /* pcss's search and filter patterns (16 Poisson taps each): one set-up table of its own generator */
    const char *const pcss[] = {"map_size=64", NULL};
    CHECK(compare_tech(lab, "pcss", pcss, 1, &c));
    int tables = 0;
    for (int i = 0; i < c.render.num_tech_resources; i++) {
        const ResourceEvent *ev = &c.render.tech_resources[i];
        if (strcmp(ev->kind, "point_table") == 0) tables += ev->category == RES_SETUP && ev->built ? 1 : 100;
    }
    CHECK(tables == 1 && frame_adds_up(&c.render));
    compare_result_free(&c);
    lab_close(lab);
}

TEST(test_frame_builds_are_repeated_with_the_evaluations)
{
    Lab *lab = fixture_lab("repeat.lua", scope_scene);
    CHECK(lab);
    const char *const fit_view[] = {"fit=view", "map_size=64", NULL};
    const char *const fit_view_other[] = {"fit=view", "map_size=32", NULL};
    CompareResult c;
    CHECK(compare_tech(lab, "sm", fit_view, 3, &c));
    const ResourceEvent *map = tech_event(&c.render, "shadow_map"), *view = tech_event(&c.render, "light_view");
    CHECK(map && view && map->builds == 3 && view->builds == 3 && c.render.repeat == 3);
    CHECK(tech_event(&c.render, "view_samples")->builds == 1); /* the G-buffer is not rebuilt */
    CHECK(frame_adds_up(&c.render));
    compare_result_free(&c);
    /* --repeat 1: one build, its time reported */
    CHECK(compare_tech(lab, "sm", fit_view_other, 1, &c));
    map = tech_event(&c.render, "shadow_map");
    CHECK(map && map->built && map->builds == 1 && map->own_s == map->cold_own_s);
    compare_result_free(&c);
    lab_close(lab);
}

/* The system's buffers (bufpool.h) taken by a render whose frame resources
 * are built `repeat` times, the pool emptied first. */
static long system_buffers_of(const char *file, int repeat)
{
    Lab *lab = fixture_lab(file, scope_scene);
    if (!lab) return -1;
    const char *const cube[] = {"map_size=512", NULL}; /* six 512^2 faces: a 6 MiB depth buffer */
    bufpool_release();
    long before = bufpool_stats().allocated;
    CompareResult c;
    bool ok = compare_tech(lab, "sm", cube, repeat, &c);
    long taken = bufpool_stats().allocated - before;
    if (ok) compare_result_free(&c);
    lab_close(lab);
    return ok ? taken : -1;
}

/* A map built three times for its median takes its buffers from the system
 * once, as a renderer allocates its shadow map once: only the first build
 * pays their pages' first touch (bench/README.md, step 11). */
TEST(test_repeated_builds_take_the_buffers_of_the_one_before)
{
    long once = system_buffers_of("pool1.lua", 1), thrice = system_buffers_of("pool3.lua", 3);
    CHECK_MSG(once >= 1 && thrice == once, "buffers from the system: 1 build %ld, 3 builds %ld", once, thrice);
}
