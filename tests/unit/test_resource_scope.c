/* test_resource_scope.c -- resource scopes (resources.h): a scope names what
 * a stage depends on, also when it reuses a resource whose dependencies it
 * never asks for again, and the own build times of those resources add up to
 * the cost of building them from nothing; a technique's frame time (lab.h)
 * is the same whether its resources were built in this run or reused; a time
 * budget stops the timed repeats and the result says how many ran. */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "fixtures.h"
#include "lab/compare.h"
#include "test.h"

/* A fake resource: sleeps `ms`, then optionally acquires a dependency. */
typedef struct Fake { int id; } Fake;
typedef struct FakeArgs { ResourceManager *rm; int id; int ms; int dep_id; int dep_ms; } FakeArgs;

static size_t fake_bytes(const void *r) { (void)r; return sizeof(Fake); }
static void fake_destroy(void *r) { free(r); }
static const ResourceKind kind_fake = {"fake", fake_bytes, fake_destroy};

static void sleep_ms(int ms)
{
    struct timespec ts = {0, (long)ms * 1000000L};
    nanosleep(&ts, NULL);
}

static const Fake *acquire_fake(ResourceManager *rm, int id, int ms, int dep_id, int dep_ms, Error *err);

static void *build_fake(const void *args, Error *err)
{
    const FakeArgs *a = args;
    sleep_ms(a->ms);
    if (a->dep_id >= 0 && !acquire_fake(a->rm, a->dep_id, a->dep_ms, -1, 0, err)) return NULL;
    Fake *f = malloc(sizeof *f);
    if (f) f->id = a->id;
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
    rm_scope_begin(rm);
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
    rm_scope_begin(rm);
    CHECK(acquire_fake(rm, 2, 30, 1, 20, &err));
    rm_scope_end(rm);
    CHECK(rm_scope_count(rm) == 2);
    CHECK(!scope_find(rm, 2)->built && !scope_find(rm, 1)->built);
    CHECK_NEAR(scope_find(rm, 2)->own_s + scope_find(rm, 1)->own_s, cost_built, 1e-12);
    /* Acquisitions outside a scope are not recorded in it. */
    rm_scope_begin(rm);
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
    CompareRequest rq = {hard, params, 0, 2, 1, false, {MEASURE_VISIBILITY, 16, SAMPLING_R2, 1}, NULL, 0.0};
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
