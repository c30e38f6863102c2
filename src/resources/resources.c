/* resources.c -- keyed resource cache with a per-run log and scopes (see
 * resources.h). A linear table: runs hold tens of resources, not thousands.
 * Each entry remembers the entries acquired while it was built, so a scope
 * can name a reused resource's dependencies, and its own build time net of
 * those nested builds. */
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
} Entry;

/* A build in progress: what it acquires and how long its nested builds took. */
typedef struct BuildFrame { IntList deps; double nested_s; } BuildFrame;

/* A growable list of events, deduplicated by (kind, key). */
typedef struct EventList { ResourceEvent *ev; int n, cap; } EventList;

struct ResourceManager {
    Entry *entries;
    int count, cap;
    EventList log;
    BuildFrame frames[RM_MAX_DEPTH];
    int depth;
    bool scoping;
    EventList scope;
};

ResourceManager *rm_create(void) { return calloc(1, sizeof(ResourceManager)); }

void rm_clear(ResourceManager *rm)
{
    for (int i = rm->count - 1; i >= 0; i--) {
        rm->entries[i].kind->destroy(rm->entries[i].res);
        free(rm->entries[i].deps.v);
    }
    rm->count = 0;
    rm->log.n = 0;
    rm->scope.n = 0;
}

void rm_destroy(ResourceManager *rm)
{
    if (!rm) return;
    rm_clear(rm);
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

/* One event per resource per list: later requests add nothing. */
static bool event_add(EventList *l, const Entry *e, const char *desc, bool built)
{
    for (int i = 0; i < l->n; i++)
        if (l->ev[i].key == e->key && strcmp(l->ev[i].kind, e->kind->name) == 0) return false;
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
    return true;
}

/* Record entry `i` in the open scope with, when newly recorded, the entries
 * it was built from (reused here even if this run never asked for them). */
static void scope_add(ResourceManager *rm, int i, bool built)
{
    const Entry *e = &rm->entries[i];
    if (!event_add(&rm->scope, e, e->desc, built)) return;
    for (int d = 0; d < e->deps.n; d++) scope_add(rm, e->deps.v[d], false);
}

static int find(const ResourceManager *rm, const ResourceKind *kind, uint64_t key)
{
    for (int i = 0; i < rm->count; i++)
        if (rm->entries[i].kind == kind && rm->entries[i].key == key) return i;
    return -1;
}

/* Build, time and store a new entry; its index, or -1 with err set. */
static int build_entry(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                       ResourceBuildFn build, const void *args, Error *err)
{
    if (rm->depth == RM_MAX_DEPTH) {
        error_set(err, "resources nested more than %d deep (building %s)", RM_MAX_DEPTH, kind->name);
        return -1;
    }
    BuildFrame *f = &rm->frames[rm->depth++];
    f->deps.n = 0;
    f->nested_s = 0;
    Progress prog; /* "... > shadow_map, 2.1 s" on a terminal (core/progress.h) */
    progress_begin(&prog, kind->name, 0);
    double t0 = timer_now_s();
    void *res = build(args, err);
    double dt = timer_now_s() - t0;
    progress_end(&prog);
    rm->depth--;
    if (!res) return -1;
    Entry *entries = array_room(rm->entries, rm->count, &rm->cap, sizeof *entries, 16);
    if (!entries) {
        kind->destroy(res);
        error_set(err, "out of memory in the resource manager");
        return -1;
    }
    rm->entries = entries;
    Entry *e = &rm->entries[rm->count];
    *e = (Entry){kind, key, res, dt, dt > f->nested_s ? dt - f->nested_s : 0.0, kind->bytes(res), "", {NULL, 0, 0}};
    snprintf(e->desc, sizeof e->desc, "%s", desc);
    for (int i = 0; i < f->deps.n; i++) int_list_add_unique(&e->deps, f->deps.v[i]);
    if (rm->depth > 0) rm->frames[rm->depth - 1].nested_s += dt;
    return rm->count++;
}

void *rm_acquire(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                 ResourceBuildFn build, const void *args, Error *err)
{
    int i = find(rm, kind, key);
    bool built = i < 0;
    if (built && (i = build_entry(rm, kind, key, desc, build, args, err)) < 0) return NULL;
    event_add(&rm->log, &rm->entries[i], desc, built);
    if (rm->depth > 0) int_list_add_unique(&rm->frames[rm->depth - 1].deps, i);
    if (rm->scoping) scope_add(rm, i, built);
    return rm->entries[i].res;
}

int rm_log_count(const ResourceManager *rm) { return rm->log.n; }
const ResourceEvent *rm_log_event(const ResourceManager *rm, int i) { return &rm->log.ev[i]; }
void rm_log_reset(ResourceManager *rm) { rm->log.n = 0; }

void rm_log_note(ResourceManager *rm, const char *kind, uint64_t key, const char *note)
{
    for (int i = 0; i < rm->log.n; i++) {
        ResourceEvent *ev = &rm->log.ev[i];
        if (ev->key != key || strcmp(ev->kind, kind) != 0) continue;
        size_t n = strlen(ev->desc);
        snprintf(ev->desc + n, sizeof ev->desc - n, " (%s)", note);
    }
}

void rm_scope_begin(ResourceManager *rm)
{
    rm->scoping = true;
    rm->scope.n = 0;
}
void rm_scope_end(ResourceManager *rm) { rm->scoping = false; }
int rm_scope_count(const ResourceManager *rm) { return rm->scope.n; }
const ResourceEvent *rm_scope_event(const ResourceManager *rm, int i) { return &rm->scope.ev[i]; }
size_t rm_bytes(const ResourceManager *rm)
{
    size_t b = 0;
    for (int i = 0; i < rm->count; i++) b += rm->entries[i].bytes;
    return b;
}

int rm_count(const ResourceManager *rm) { return rm->count; }
