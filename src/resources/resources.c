/* resources.c -- keyed resource cache with a per-run log and scopes (see
 * resources.h). A linear table: runs hold tens of resources, not thousands.
 * Each entry remembers the entries acquired while it was built, so a scope
 * can name a reused resource's dependencies, and its own build time net of
 * those nested builds; each build frame knows the category it builds for,
 * which is what the resources acquired inside it are for too. */
#include "resources/resources.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/array.h"
#include "core/progress.h"
#include "core/timer.h"

#define RM_MAX_DEPTH 16

typedef struct IntList { int *v; int n, cap; } IntList;

typedef struct Entry {
    const ResourceKind *kind;
    uint64_t key;
    void *res;
    double build_s;  /* wall time of its build, nested builds included */
    double own_s;    /* build_s less the builds nested inside it */
    size_t bytes;
    char desc[160];
    IntList deps;    /* entries acquired while it was built */
    int builds;      /* build_s and own_s are medians of this many builds */
    double cold_own_s;
    WorkCounters work; /* of its first build, less the builds nested inside it */
} Entry;

/* A build in progress: what it acquires, how long its nested builds took and
 * the category they are acquired for. */
typedef struct BuildFrame {
    IntList deps;
    double nested_s;
    WorkCounters nested_work;
    ResourceCategory context;
} BuildFrame;

/* A growable list of events, deduplicated by (kind, key). */
typedef struct EventList { ResourceEvent *ev; int n, cap; } EventList;

struct ResourceManager {
    Entry *entries;
    int count, cap;
    EventList log;
    BuildFrame frames[RM_MAX_DEPTH];
    int depth;
    bool scoping;
    int builds;      /* of each frame resource built in the scope (rm_scope_begin) */
    double budget_s; /* > 0: and no more once they took this long */
    double scope_build_s;
    WorkCounters scope_work; /* of the builds inside the scope, as scope_build_s */
    EventList scope;
    ResourceBuiltFn on_build; /* rm_on_build */
    void *on_build_user;
};

const char *resource_category_name(ResourceCategory c)
{
    static const char *const names[] = {"frame", "gbuffer", "setup", "evaluation"};
    return names[c];
}

ResourceManager *rm_create(void) { return calloc(1, sizeof(ResourceManager)); }

/* Destroy the entries, newest first, but the set-up tables when keep_setup;
 * a kept table forgets its dependencies (it is made from its key alone). */
static void drop_entries(ResourceManager *rm, bool keep_setup)
{
    for (int i = rm->count - 1; i >= 0; i--) {
        Entry *e = &rm->entries[i];
        free(e->deps.v);
        e->deps = (IntList){NULL, 0, 0};
        if (keep_setup && e->kind->category == RES_SETUP) continue;
        e->kind->destroy(e->res);
        e->res = NULL;
    }
    int kept = 0;
    for (int i = 0; i < rm->count; i++)
        if (rm->entries[i].res) rm->entries[kept++] = rm->entries[i];
    rm->count = kept;
    rm->log.n = 0;
    rm->scope.n = 0;
}

void rm_clear(ResourceManager *rm) { drop_entries(rm, true); }

void rm_destroy(ResourceManager *rm)
{
    if (!rm) return;
    drop_entries(rm, false);
    for (int d = 0; d < RM_MAX_DEPTH; d++) free(rm->frames[d].deps.v);
    free(rm->entries);
    free(rm->log.ev);
    free(rm->scope.ev);
    free(rm);
}

/* Bookkeeping lists: a failed allocation drops the item, never the run. */
static void int_list_add_unique(IntList *l, int v)
{
    for (int i = 0; i < l->n; i++)
        if (l->v[i] == v) return;
    int *values = array_room(l->v, l->n, &l->cap, sizeof *values, 8);
    if (!values) return;
    l->v = values;
    l->v[l->n++] = v;
}

/* A resource acquired for a G-buffer, set-up or evaluation build is for that
 * too; for a frame build it is of its own kind's category. */
static ResourceCategory category_in(ResourceCategory context, const ResourceKind *kind)
{
    return context != RES_FRAME ? context : kind->category;
}

static ResourceCategory current_context(const ResourceManager *rm)
{
    return rm->depth > 0 ? rm->frames[rm->depth - 1].context : RES_FRAME;
}

/* One event per resource per list: later requests add nothing, but a frame
 * that needs what it had seen only as another's dependency pays for it.
 * True when the event is new or became a frame one. */
static bool event_add(EventList *l, const Entry *e, const char *desc, bool built, ResourceCategory category)
{
    for (int i = 0; i < l->n; i++) {
        ResourceEvent *ev = &l->ev[i];
        if (ev->key != e->key || strcmp(ev->kind, e->kind->name) != 0) continue;
        if (category != RES_FRAME || ev->category == RES_FRAME) return false;
        ev->category = RES_FRAME;
        return true;
    }
    ResourceEvent *events = array_room(l->ev, l->n, &l->cap, sizeof *events, 16);
    if (!events) return false;
    l->ev = events;
    ResourceEvent *ev = &l->ev[l->n++];
    ev->kind = e->kind->name;
    snprintf(ev->desc, sizeof ev->desc, "%s", desc);
    ev->key = e->key;
    ev->built = built;
    ev->build_s = e->build_s;
    ev->own_s = e->own_s;
    ev->bytes = e->bytes;
    ev->category = category;
    ev->builds = e->builds;
    ev->cold_own_s = e->cold_own_s;
    ev->work = e->work;
    return true;
}

/* Record entry `i` in the open scope with, when newly recorded, the entries
 * it was built from (reused here even if this run never asked for them), as
 * needed for what `i` is needed for. */
static void scope_add(ResourceManager *rm, int i, bool built, ResourceCategory category)
{
    const Entry *e = &rm->entries[i];
    if (!event_add(&rm->scope, e, e->desc, built, category)) return;
    for (int d = 0; d < e->deps.n; d++) {
        int j = e->deps.v[d];
        scope_add(rm, j, false, category_in(category, rm->entries[j].kind));
    }
}

static int find(const ResourceManager *rm, const ResourceKind *kind, uint64_t key)
{
    for (int i = 0; i < rm->count; i++)
        if (rm->entries[i].kind == kind && rm->entries[i].key == key) return i;
    return -1;
}

/* One build in a new frame, timed and counted: the resource (NULL + err on
 * failure), its wall time and its own time and work net of the builds nested
 * inside it. The frame stays readable (its deps) until the next build at
 * this depth. */
static void *timed_build(ResourceManager *rm, const ResourceKind *kind, ResourceCategory category,
                         ResourceBuildFn build, const void *args, double *wall_s, double *own_s,
                         WorkCounters *own_work, Error *err)
{
    if (rm->depth == RM_MAX_DEPTH) {
        error_set(err, "resources nested more than %d deep (building %s)", RM_MAX_DEPTH, kind->name);
        return NULL;
    }
    BuildFrame *f = &rm->frames[rm->depth++];
    f->deps.n = 0;
    f->nested_s = 0;
    f->nested_work = (WorkCounters){0};
    f->context = category;
    Progress prog; /* "... > shadow_map, 2.1 s" on a terminal (core/progress.h) */
    progress_begin(&prog, kind->name, 0);
    WorkCounters w0, w1;
    work_snapshot(&w0);
    double t0 = timer_now_s();
    void *res = build(args, err);
    *wall_s = timer_now_s() - t0;
    work_snapshot(&w1);
    progress_end(&prog);
    *own_s = *wall_s > f->nested_s ? *wall_s - f->nested_s : 0.0;
    WorkCounters wall_work = work_diff(&w1, &w0);
    *own_work = work_diff(&wall_work, &f->nested_work);
    rm->depth--;
    return res;
}

/* Store a built resource; its index, or -1 with err set (and res destroyed). */
static int store_entry(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc, void *res,
                       double wall_s, double own_s, int builds, double cold_own_s, const WorkCounters *own_work,
                       Error *err)
{
    Entry *entries = array_room(rm->entries, rm->count, &rm->cap, sizeof *entries, 16);
    if (!entries) {
        kind->destroy(res);
        error_set(err, "out of memory in the resource manager");
        return -1;
    }
    rm->entries = entries;
    Entry *e = &rm->entries[rm->count];
    *e = (Entry){kind, key, res, wall_s, own_s, kind->bytes(res), "", {NULL, 0, 0}, builds, cold_own_s, *own_work};
    snprintf(e->desc, sizeof e->desc, "%s", desc);
    const IntList *deps = &rm->frames[rm->depth].deps; /* the build's frame, just popped */
    for (int i = 0; i < deps->n; i++) int_list_add_unique(&e->deps, deps->v[i]);
    return rm->count++;
}

/* Builds 2 .. rm->builds of a frame resource (fewer past the budget), each
 * replacing the one before: that one is destroyed first, so its buffers
 * serve the next build (core/bufpool.h) and only the first build pays its
 * pages' first touch, as a renderer that allocates its maps once. *res is
 * the last build (NULL with err set when one fails); *wall_s and *own_s
 * come in as the first build's times and leave as the medians of all of
 * them, *builds their count. Where the first takes budget_s or more, it is
 * the only one. */
static void rebuild_for_median(ResourceManager *rm, const ResourceKind *kind, ResourceBuildFn build, const void *args,
                               void **res, double *wall_s, double *own_s, int *builds, Error *err)
{
    double *walls = malloc(2 * sizeof(double) * (size_t)rm->builds);
    if (!walls) {
        kind->destroy(*res);
        *res = NULL;
        error_set(err, "out of memory timing %d builds of %s", rm->builds, kind->name);
        return;
    }
    double *owns = walls + rm->builds;
    walls[0] = *wall_s;
    owns[0] = *own_s;
    double total_s = walls[0];
    int n = 1;
    for (; *res && n < rm->builds && (rm->budget_s <= 0 || total_s < rm->budget_s); n++) {
        WorkCounters work; /* the first build's again: the entry keeps that */
        kind->destroy(*res);
        *res = timed_build(rm, kind, RES_FRAME, build, args, &walls[n], &owns[n], &work, err);
        total_s += walls[n];
    }
    *wall_s = timer_median(walls, n);
    *own_s = timer_median(owns, n);
    *builds = n;
    free(walls);
}

/* Build, time and store a new entry (a frame one inside a scope rm->builds
 * times, the entry keeping the last build and the first's work and time as
 * cold_own_s); its index, or -1 with err set. Its whole time and work,
 * rebuilds included, are nested in the build around it and built in the
 * scope. */
static int build_entry(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                       ResourceBuildFn build, const void *args, Error *err)
{
    ResourceCategory category = category_in(current_context(rm), kind);
    WorkCounters w0, w1, own_work;
    work_snapshot(&w0);
    double t0 = timer_now_s(), wall_s, own_s;
    void *res = timed_build(rm, kind, category, build, args, &wall_s, &own_s, &own_work, err);
    double cold_own_s = own_s;
    int builds = 1;
    if (res && rm->scoping && category == RES_FRAME && rm->builds > 1)
        rebuild_for_median(rm, kind, build, args, &res, &wall_s, &own_s, &builds, err);
    int i = res ? store_entry(rm, kind, key, desc, res, wall_s, own_s, builds, cold_own_s, &own_work, err) : -1;
    double dt = timer_now_s() - t0;
    work_snapshot(&w1);
    WorkCounters dw = work_diff(&w1, &w0);
    if (rm->depth > 0) {
        rm->frames[rm->depth - 1].nested_s += dt;
        work_add(&rm->frames[rm->depth - 1].nested_work, &dw);
    } else if (rm->scoping) {
        rm->scope_build_s += dt;
        work_add(&rm->scope_work, &dw);
    }
    return i;
}

void *rm_acquire(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                 ResourceBuildFn build, const void *args, Error *err)
{
    int i = find(rm, kind, key);
    bool built = i < 0;
    ResourceCategory category = category_in(current_context(rm), kind);
    if (built && (i = build_entry(rm, kind, key, desc, build, args, err)) < 0) return NULL;
    if (built && rm->on_build) rm->on_build(kind->name, rm->entries[i].res, rm->on_build_user);
    event_add(&rm->log, &rm->entries[i], desc, built, category);
    if (rm->depth > 0) int_list_add_unique(&rm->frames[rm->depth - 1].deps, i);
    if (rm->scoping) scope_add(rm, i, built, category);
    return rm->entries[i].res;
}

void rm_on_build(ResourceManager *rm, ResourceBuiltFn fn, void *user)
{
    rm->on_build = fn;
    rm->on_build_user = user;
}

int rm_log_count(const ResourceManager *rm) { return rm->log.n; }
const ResourceEvent *rm_log_event(const ResourceManager *rm, int i) { return &rm->log.ev[i]; }
void rm_log_reset(ResourceManager *rm) { rm->log.n = 0; }

/* Once per event: a resource acquired again (every build of a scope's
 * frame, every repeat) notes the same thing again. */
void rm_log_note(ResourceManager *rm, const char *kind, uint64_t key, const char *note)
{
    char suffix[sizeof rm->log.ev[0].desc];
    snprintf(suffix, sizeof suffix, " (%s)", note);
    for (int i = 0; i < rm->log.n; i++) {
        ResourceEvent *ev = &rm->log.ev[i];
        if (ev->key != key || strcmp(ev->kind, kind) != 0 || strstr(ev->desc, suffix)) continue;
        size_t n = strlen(ev->desc);
        snprintf(ev->desc + n, sizeof ev->desc - n, "%s", suffix);
    }
}

void rm_scope_begin(ResourceManager *rm, int builds, double budget_s)
{
    rm->scoping = true;
    rm->builds = builds > 1 ? builds : 1;
    rm->budget_s = budget_s;
    rm->scope_build_s = 0;
    rm->scope_work = (WorkCounters){0};
    rm->scope.n = 0;
}
void rm_scope_end(ResourceManager *rm) { rm->scoping = false; }
int rm_scope_count(const ResourceManager *rm) { return rm->scope.n; }
const ResourceEvent *rm_scope_event(const ResourceManager *rm, int i) { return &rm->scope.ev[i]; }
double rm_scope_build_s(const ResourceManager *rm) { return rm->scope_build_s; }
WorkCounters rm_scope_work(const ResourceManager *rm) { return rm->scope_work; }

size_t rm_bytes(const ResourceManager *rm)
{
    size_t b = 0;
    for (int i = 0; i < rm->count; i++) b += rm->entries[i].bytes;
    return b;
}

int rm_count(const ResourceManager *rm) { return rm->count; }
