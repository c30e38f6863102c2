/* resources.c -- keyed resource cache with a per-run log (see resources.h).
 * A linear table: runs hold tens of resources, not thousands. */
#include "resources/resources.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/timer.h"

typedef struct Entry {
    const ResourceKind *kind;
    uint64_t key;
    void *res;
    double build_s;
    size_t bytes;
} Entry;

struct ResourceManager {
    Entry *entries;
    int count, cap;
    ResourceEvent *log;
    int log_count, log_cap;
};

ResourceManager *rm_create(void) { return calloc(1, sizeof(ResourceManager)); }

void rm_destroy(ResourceManager *rm)
{
    if (!rm) return;
    for (int i = rm->count - 1; i >= 0; i--) rm->entries[i].kind->destroy(rm->entries[i].res);
    free(rm->entries);
    free(rm->log);
    free(rm);
}

/* One line per resource per run: later requests in the same run add nothing. */
static void log_event(ResourceManager *rm, const Entry *e, const char *desc, bool built)
{
    for (int i = 0; i < rm->log_count; i++)
        if (rm->log[i].key == e->key && strcmp(rm->log[i].kind, e->kind->name) == 0) return;
    if (rm->log_count == rm->log_cap) {
        int cap = rm->log_cap ? 2 * rm->log_cap : 16;
        ResourceEvent *nl = realloc(rm->log, sizeof *nl * (size_t)cap);
        if (!nl) return; /* the log is bookkeeping: a full log drops events, never the run */
        rm->log = nl;
        rm->log_cap = cap;
    }
    ResourceEvent *ev = &rm->log[rm->log_count++];
    ev->kind = e->kind->name;
    snprintf(ev->desc, sizeof ev->desc, "%s", desc);
    ev->key = e->key;
    ev->built = built;
    ev->build_s = e->build_s;
    ev->bytes = e->bytes;
}

static Entry *find(ResourceManager *rm, const ResourceKind *kind, uint64_t key)
{
    for (int i = 0; i < rm->count; i++)
        if (rm->entries[i].kind == kind && rm->entries[i].key == key) return &rm->entries[i];
    return NULL;
}

void *rm_acquire(ResourceManager *rm, const ResourceKind *kind, uint64_t key, const char *desc,
                 ResourceBuildFn build, const void *args, Error *err)
{
    Entry *e = find(rm, kind, key);
    if (e) {
        log_event(rm, e, desc, false);
        return e->res;
    }
    if (rm->count == rm->cap) {
        int cap = rm->cap ? 2 * rm->cap : 16;
        Entry *ne = realloc(rm->entries, sizeof *ne * (size_t)cap);
        if (!ne) { error_set(err, "out of memory in the resource manager"); return NULL; }
        rm->entries = ne;
        rm->cap = cap;
    }
    double t0 = timer_now_s();
    void *res = build(args, err);
    if (!res) return NULL;
    e = &rm->entries[rm->count++];
    *e = (Entry){kind, key, res, timer_now_s() - t0, kind->bytes(res)};
    log_event(rm, e, desc, true);
    return res;
}

int rm_log_count(const ResourceManager *rm) { return rm->log_count; }
const ResourceEvent *rm_log_event(const ResourceManager *rm, int i) { return &rm->log[i]; }
void rm_log_reset(ResourceManager *rm) { rm->log_count = 0; }

void rm_log_note(ResourceManager *rm, const char *kind, uint64_t key, const char *note)
{
    for (int i = 0; i < rm->log_count; i++) {
        ResourceEvent *ev = &rm->log[i];
        if (ev->key != key || strcmp(ev->kind, kind) != 0) continue;
        size_t n = strlen(ev->desc);
        snprintf(ev->desc + n, sizeof ev->desc - n, " (%s)", note);
    }
}

size_t rm_bytes(const ResourceManager *rm)
{
    size_t b = 0;
    for (int i = 0; i < rm->count; i++) b += rm->entries[i].bytes;
    return b;
}

int rm_count(const ResourceManager *rm) { return rm->count; }
