/* stability.c -- the stability runner: expands the case table and every
 * technique's parameter declarations into runs, groups the runs by the scene
 * they need, and for each scene forks a case process (stability_proc.c)
 * that builds what its runs share once, on one thread, then forks each run
 * from it under a time bound, `jobs` at once. A crash, a hang or a
 * sanitizer report is one failed row with its cause; this process never
 * starts a thread. The runs' work is in stability_exec.c. */
#define _POSIX_C_SOURCE 200809L
#include "lab/stability.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/hash.h"
#include "core/fsutil.h"
#include "core/timer.h"
#include "io/exr.h"
#include "lab/stability_cases.h"
#include "lab/stability_proc.h"
#include "core/array.h"

#define DEFAULT_TIMEOUT_S 120.0
#define PREP_BOUNDS 3      /* a case's shared preparation: this many runs' time bound */
#define CASE_SLACK_S 30.0  /* the case process between two results: a run's bound and this */
#define MAX_JOBS 16
#define HEAVY_BOUND_FACTOR 3 /* a heavy case's runs (a 4096^2 image, 10^6 triangles): this many times the bound */

const char *stab_status_name(StabStatus s)
{
    static const char *const names[] = {"pass", "FAIL", "n/a", "known"};
    return names[s];
}

int stab_case_count(void) { return stab_cases_count(); }
const char *stab_case_name(int i) { return stab_cases_at(i)->name; }
const char *stab_case_doc(int i) { return stab_cases_at(i)->doc; }

/* ---- light kinds of a run ---------------------------------------------------- */

static const LightKind delta_order[] = {LIGHT_POINT, LIGHT_SPOT, LIGHT_DIRECTIONAL};
static const LightKind area_order[] = {LIGHT_SPHERE, LIGHT_RECT, LIGHT_DISK, LIGHT_TEXTURED_RECT};
static const LightKind any_order[] = {LIGHT_POINT,  LIGHT_SPHERE, LIGHT_SPOT,         LIGHT_DIRECTIONAL,
                                      LIGHT_RECT,   LIGHT_DISK,   LIGHT_TEXTURED_RECT};

static int first_of(const LightKind *order, int n, unsigned mask, LightKind *out)
{
    for (int i = 0; i < n; i++)
        if (mask & LIGHT_BIT(order[i])) {
            *out = order[i];
            return 1;
        }
    return 0;
}

/* The kinds a case runs with for a technique; 0 when none applies. Quick
 * runs take at most one delta and one area kind of a per-kind case. */
static int plan_kinds(const StabCase *c, unsigned tech_lights, bool quick, LightKind *kinds)
{
    unsigned mask = c->lights & tech_lights;
    int n = 0;
    switch (c->plan == PLAN_EACH && quick ? PLAN_TWO : c->plan) {
    case PLAN_EACH:
        for (int k = LIGHT_POINT; k <= LIGHT_TEXTURED_RECT; k++)
            if (mask & LIGHT_BIT(k)) kinds[n++] = (LightKind)k;
        return n;
    case PLAN_TWO:
        n = first_of(delta_order, 3, mask, kinds);
        return n + first_of(area_order, 4, mask, kinds + n);
    case PLAN_ONE: return first_of(any_order, 7, mask, kinds);
    default: return 0;
    }
}

/* ---- rows ------------------------------------------------------------------- */

static void row_init(StabResult *r, const char *tech, const char *case_name, const char *light)
{
    memset(r, 0, sizeof *r);
    snprintf(r->technique, sizeof r->technique, "%s", tech);
    snprintf(r->case_name, sizeof r->case_name, "%s", case_name);
    snprintf(r->light, sizeof r->light, "%s", light);
    r->status = STAB_FAIL;
    r->mae = r->rmse = r->max_abs = r->noise_rms = NAN;
}

static bool has_light(const StabJob *j) { return !(j->c && j->c->plan == PLAN_NONE); }

static void job_row(const StabJob *j, StabResult *r)
{
    row_init(r, j->tech ? j->tech->name : "-", j->name, has_light(j) ? light_kind_name(j->kind) : "");
    r->order = j->order;
}

/* The whole matrix, planned before anything runs. */
typedef struct Runner {
    const StabOptions *o;
    StabSettings st;
    double timeout_s;
    int jobs_at_once, threads;
    StabRowFn row;
    void *user;
    StabJob *jobs;
    int num_jobs, cap, order, serial;
    bool oom;
} Runner;

/* The hang bound of one run of job j: the timeout, times HEAVY_BOUND_FACTOR
 * for a case the matrix marks heavy (its work is that much above the
 * others': a 4096^2 image takes 70-76 s of 120 on 2 quiet cores). */
static double run_bound_s(const Runner *rn, const StabJob *j)
{
    return rn->timeout_s * (j->c && j->c->heavy ? HEAVY_BOUND_FACTOR : 1);
}

/* Does the comma-separated filter (stability.h) take case_name? */
static bool wanted(const Runner *rn, const char *case_name)
{
    const char *f = rn->o->only;
    if (!f) return true;
    bool any_include = false, included = false;
    while (*f) {
        size_t n = strcspn(f, ",");
        bool exclude = f[0] == '!';
        char term[STAB_NAME_MAX];
        snprintf(term, sizeof term, "%.*s", (int)(n - exclude), f + exclude);
        bool hit = strstr(case_name, term) != NULL;
        if (exclude && hit) return false;
        any_include = any_include || !exclude;
        included = included || (!exclude && hit);
        f += n + (f[n] == ',');
    }
    return included || !any_include;
}

static StabSettings settings(bool quick)
{
    return quick ? (StabSettings){true, STAB_QUICK_WIDTH, STAB_QUICK_HEIGHT, STAB_QUICK_REF_SAMPLES}
                 : (StabSettings){false, 128, 96, 256};
}

/* A run of case c (NULL: a parameter probe); a case whose limit is stated
 * at the full sizes keeps them in quick runs too. */
/* Is the run of t on this case or probe and light in the sample (StabOptions)? */
static bool sampled(const Runner *rn, const Technique *t, const char *name, LightKind kind)
{
    if (rn->o->sample_m <= 1) return true;
    Hasher h;
    hash_init(&h);
    hash_str(&h, t ? t->name : "(engine)");
    hash_str(&h, name);
    hash_u64(&h, (uint64_t)kind);
    return (hash_final(&h) % (uint64_t)rn->o->sample_m == (uint64_t)rn->o->sample_k) != rn->o->sample_invert;
}

static void add_job(Runner *rn, const Technique *t, const StabCase *c, int param, ParamProbe probe, LightKind kind,
                    const char *name)
{
    if (!sampled(rn, t, name, kind)) return;
    StabJob *jobs = array_room(rn->jobs, rn->num_jobs, &rn->cap, sizeof *jobs, 256);
    if (!jobs) {
        rn->oom = true;
        return;
    }
    rn->jobs = jobs;
    StabJob *j = &rn->jobs[rn->num_jobs++];
    StabSettings st = c && c->full_sizes ? settings(false) : rn->st;
    *j = (StabJob){t, c, param, probe, kind, st, rn->threads, rn->order++, ""};
    snprintf(j->name, sizeof j->name, "%s", name);
}

/* ---- scene files --------------------------------------------------------------- */

/* Atomically (core/fsutil.h): a run killed while `stability -o` writes a
 * case's files leaves the previous file or the whole new one. */
static bool write_bytes(const char *path, const void *data, size_t n, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    if (fwrite(data, 1, n, af.fp) == n) return atomic_commit(&af, err);
    atomic_abort(&af);
    return error_set(err, "%s: write failed: %s", path, strerror(errno));
}

/* A 4 x 4 RGB light image: a gradient in [0.2, 1], texel (1, 2) = f->exr_texel. */
static bool write_light_image(const char *path, const StabFile *f, Error *err)
{
    float rgb[3][16];
    for (int c = 0; c < 3; c++)
        for (int i = 0; i < 16; i++) rgb[c][i] = 0.2f + 0.05f * (float)i + 0.01f * (float)c;
    for (int c = 0; c < 3; c++) rgb[c][2 * 4 + 1] = f->exr_texel;
    const ExrChannel ch[3] = {{"R", rgb[0], 1}, {"G", rgb[1], 1}, {"B", rgb[2], 1}};
    return exr_write(path, 4, 4, ch, 3, NULL, 0, err);
}

static bool write_scene(const SceneSpec *s, LightKind kind, const char *dir, char *scene_path, size_t n, Error *err)
{
    if (!mkdir_p(dir, err)) return false;
    for (int i = 0; i < s->num_files; i++) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", dir, s->files[i].name);
        bool ok = s->files[i].exr ? write_light_image(path, &s->files[i], err)
                                  : write_bytes(path, s->files[i].data, s->files[i].size, err);
        if (!ok) return false;
    }
    static char text[20000];
    if (!stab_scene_text(s, kind, text, sizeof text)) return error_set(err, "%s: scene text too long", dir);
    snprintf(scene_path, n, "%s/scene.lua", dir);
    return write_bytes(scene_path, text, strlen(text), err);
}

/* What a run wrote, to remove it afterwards (the spec itself is freed
 * before the fork, so the child holds no allocation of the parent's). */
typedef struct Written {
    char dir[1100], scene_path[1200];
    char files[STAB_MAX_FILES][64];
    int num_files;
} Written;

static void remove_scene(const Written *w)
{
    char path[1200];
    for (int i = 0; i < w->num_files; i++) {
        snprintf(path, sizeof path, "%s/%s", w->dir, w->files[i]);
        remove(path);
    }
    remove(w->scene_path);
    rmdir(w->dir);
}

static void build_spec(const StabJob *j, SceneSpec *s)
{
    stab_base_scene(s, &j->st);
    if (j->c) j->c->build(s, j->kind, &j->st);
    if (!s->light_extra[0] && j->kind == LIGHT_TEXTURED_RECT) {
        StabFile *f = stab_file_add(s, "stab-light.exr");
        f->exr = true;
        f->exr_texel = 1.0f;
    }
}

/* ---- planning ---------------------------------------------------------------------- */

static void not_applicable(Runner *rn, const Technique *t, const StabCase *c)
{
    StabResult r;
    row_init(&r, t->name, c->name, "");
    r.status = STAB_NOT_APPLICABLE;
    r.order = rn->order++;
    char handles[160], needs[160];
    tech_lights_text(t, handles, sizeof handles);
    Technique fake = {.lights = c->lights};
    tech_lights_text(&fake, needs, sizeof needs);
    snprintf(r.detail, sizeof r.detail, "%s handles %s lights; the case needs %s", t->name, handles, needs);
    rn->row(&r, rn->user);
}

static void plan_case(Runner *rn, const Technique *t, const StabCase *c)
{
    if (!wanted(rn, c->name)) return;
    LightKind kinds[8];
    int n = plan_kinds(c, t->lights, rn->st.quick, kinds);
    if (n == 0) not_applicable(rn, t, c);
    for (int k = 0; k < n; k++) add_job(rn, t, c, -1, PROBE_NONE, kinds[k], c->name);
}

/* Each parameter's probes over the base scene: one row per probe, or in
 * quick runs one row per parameter (unless --case picks single probes). */
static void plan_param_probes(Runner *rn, const Technique *t)
{
    LightKind kind;
    if (!first_of(any_order, 7, t->lights, &kind)) return;
    for (int i = 0; i < t->num_params; i++) {
        char name[STAB_NAME_MAX];
        if (!tech_param_offered(t, i)) continue; /* not the technique's (registry.h): nothing to probe */
        snprintf(name, sizeof name, "param_%s", t->params[i].name);
        if (rn->st.quick && wanted(rn, name)) {
            add_job(rn, t, NULL, i, PROBE_ALL, kind, name);
            continue;
        }
        for (int probe = PROBE_AT_MIN; probe < PROBE_ALL; probe++) {
            if (!stab_probe_applies(&t->params[i], (ParamProbe)probe)) continue;
            snprintf(name, sizeof name, "param_%s_%s", t->params[i].name, stab_probe_suffix((ParamProbe)probe));
            if (wanted(rn, name)) add_job(rn, t, NULL, i, (ParamProbe)probe, kind, name);
        }
    }
}

/* ---- a case's process ----------------------------------------------------------------- */

/* The runs of one scene: the same case (NULL: the parameter probes' base
 * scene) with the same light kind. */
typedef struct CaseRun {
    const Runner *rn;
    const StabCase *c;
    int *members; /* indices into rn->jobs */
    int n;
    char scene_path[1200];
} CaseRun;

typedef struct RunArg {
    const StabJob *job;
    const StabShared *sh;
    StabResult r;
} RunArg;

static void run_body(void *arg, int fd)
{
    RunArg *a = arg;
    stab_job_execute(a->job, a->sh, &a->r);
    stab_proc_send(fd, &a->r);
}

static void log_name(const Runner *rn, int serial, const char *what, char *out, size_t n)
{
    snprintf(out, n, "%s/%s-%d-%ld.log", rn->o->work_dir, what, serial, (long)getpid());
}

/* A run's row: its result, unless it ended badly; the time and the case's
 * shared preparation time either way. */
static void finish_run(const StabProc *p, RunArg *a, double prep_s, int top_fd)
{
    StabResult r = p->results ? p->msg : a->r;
    if (p->why[0]) {
        r.status = STAB_FAIL;
        snprintf(r.detail, sizeof r.detail, "%s", p->why);
    } else if (!p->results) {
        r.status = STAB_FAIL;
        snprintf(r.detail, sizeof r.detail, "the run gave no result");
    }
    r.seconds = timer_now_s() - p->started_s;
    r.prep_seconds = prep_s;
    stab_proc_send(top_fd, &r);
}

/* Fork the case's runs from the prepared process, `jobs_at_once` at a time. */
static void run_members(const CaseRun *cr, const StabShared *sh, double prep_s, int top_fd)
{
    const Runner *rn = cr->rn;
    StabProc procs[MAX_JOBS], *active[MAX_JOBS];
    RunArg args[MAX_JOBS];
    bool busy[MAX_JOBS] = {false};
    int slot_of[MAX_JOBS], n_active = 0, next = 0;
    while (next < cr->n || n_active > 0) {
        while (n_active < rn->jobs_at_once && next < cr->n) {
            int slot = 0;
            while (busy[slot]) slot++;
            RunArg *a = &args[slot];
            a->job = &rn->jobs[cr->members[next++]];
            a->sh = sh;
            job_row(a->job, &a->r);
            char log[1100], why[256];
            log_name(rn, slot, "run", log, sizeof log);
            if (!stab_proc_spawn(&procs[slot], log, run_bound_s(rn, a->job), 0, top_fd, run_body, a, why, sizeof why)) {
                snprintf(a->r.detail, sizeof a->r.detail, "%s", why);
                a->r.prep_seconds = prep_s;
                stab_proc_send(top_fd, &a->r);
                continue;
            }
            busy[slot] = true;
            active[n_active] = &procs[slot];
            slot_of[n_active++] = slot;
        }
        if (n_active == 0) continue;
        StabEvent ev;
        int k = stab_proc_next(active, n_active, &ev);
        if (ev != STAB_EV_ENDED) continue;
        finish_run(active[k], &args[slot_of[k]], prep_s, top_fd);
        busy[slot_of[k]] = false;
        active[k] = active[--n_active];
        slot_of[k] = slot_of[n_active];
    }
}

static void case_body(void *arg, int top_fd)
{
    const CaseRun *cr = arg;
    const StabJob *first = &cr->rn->jobs[cr->members[0]];
    StabShared sh;
    StabResult why;
    job_row(first, &why);
    double t0 = timer_now_s();
    bool ok = stab_prepare(cr->c, &first->st, cr->scene_path, &sh, &why);
    int threads = stab_thread_count();
    if (ok && threads > 1) {
        snprintf(why.detail, sizeof why.detail,
                 "the case's preparation left %d threads: its runs cannot be forked safely", threads);
        ok = false;
    }
    double prep_s = timer_now_s() - t0;
    if (ok) run_members(cr, &sh, prep_s, top_fd);
    for (int i = 0; !ok && i < cr->n; i++) {
        StabResult r;
        job_row(&cr->rn->jobs[cr->members[i]], &r);
        snprintf(r.detail, sizeof r.detail, "%s", why.detail);
        r.prep_seconds = r.seconds = prep_s;
        stab_proc_send(top_fd, &r);
    }
    stab_shared_release(&sh);
}

/* ---- one case, from this process -------------------------------------------------------- */

static void fail_rows(const Runner *rn, const CaseRun *cr, const bool *delivered, const char *why)
{
    for (int i = 0; i < cr->n; i++) {
        if (delivered && delivered[i]) continue;
        StabResult r;
        job_row(&rn->jobs[cr->members[i]], &r);
        snprintf(r.detail, sizeof r.detail, "%s", why);
        rn->row(&r, rn->user);
    }
}

static void case_dir(const Runner *rn, const StabJob *j, char *out, size_t n)
{
    if (rn->o->scene_dir)
        snprintf(out, n, "%s/%s%s%s", rn->o->scene_dir, j->c ? j->c->name : "params", has_light(j) ? "-" : "",
                 has_light(j) ? light_kind_name(j->kind) : "");
    else snprintf(out, n, "%s/case-%d", rn->o->work_dir, rn->serial);
}

/* Write the case's scene, run its process and pass its rows on; a run the
 * process could not report (it crashed, hung or was killed) fails with why. */
static void run_case(Runner *rn, CaseRun *cr)
{
    const StabJob *first = &rn->jobs[cr->members[0]];
    SceneSpec *s = malloc(sizeof *s);
    bool *delivered = calloc((size_t)cr->n, sizeof *delivered);
    if (!s || !delivered) {
        free(s);
        free(delivered);
        fail_rows(rn, cr, NULL, "out of memory");
        return;
    }
    build_spec(first, s);
    Written w = {.num_files = s->num_files};
    for (int i = 0; i < s->num_files; i++) snprintf(w.files[i], sizeof w.files[i], "%s", s->files[i].name);
    case_dir(rn, first, w.dir, sizeof w.dir);
    Error err;
    bool written = write_scene(s, first->kind, w.dir, w.scene_path, sizeof w.scene_path, &err);
    free(s);
    snprintf(cr->scene_path, sizeof cr->scene_path, "%s", w.scene_path);
    char log[1100], why[STAB_DETAIL_MAX] = "";
    log_name(rn, rn->serial++, "case", log, sizeof log);
    StabProc p, *one[1] = {&p};
    double first_bound = (PREP_BOUNDS + 1) * run_bound_s(rn, first); /* the preparation, then the first run */
    bool started = written && stab_proc_spawn(&p, log, first_bound, run_bound_s(rn, first) + CASE_SLACK_S, -1, case_body, cr,
                                               why, sizeof why);
    if (!written) snprintf(why, sizeof why, "cannot write the case: %s", err.msg);
    if (started) {
        StabEvent ev;
        while (stab_proc_next(one, 1, &ev), ev == STAB_EV_RESULT) {
            for (int i = 0; i < cr->n; i++)
                if (rn->jobs[cr->members[i]].order == p.msg.order) delivered[i] = true;
            rn->row(&p.msg, rn->user);
        }
        snprintf(why, sizeof why, "the case's process ended before this run: %s",
                 p.why[0] ? p.why : "without its result");
        if (p.why[0] && p.results == cr->n) { /* every run reported; the shared part failed afterwards */
            StabResult r;
            job_row(first, &r);
            snprintf(r.technique, sizeof r.technique, "-");
            snprintf(r.detail, sizeof r.detail, "the case's process, after its runs: %s", p.why);
            rn->row(&r, rn->user);
        }
    }
    fail_rows(rn, cr, delivered, why);
    free(delivered);
    if (!rn->o->scene_dir) remove_scene(&w);
}

/* Runs grouped by the scene they need, in the order each scene first appears. */
static bool same_scene(const StabJob *a, const StabJob *b) { return a->c == b->c && a->kind == b->kind; }

static void run_planned(Runner *rn)
{
    int *members = malloc(sizeof *members * (size_t)(rn->num_jobs ? rn->num_jobs : 1));
    bool *done = calloc((size_t)rn->num_jobs + 1, sizeof *done);
    for (int i = 0; members && done && i < rn->num_jobs; i++) {
        if (done[i]) continue;
        CaseRun cr = {.rn = rn, .c = rn->jobs[i].c, .members = members, .n = 0};
        for (int j = i; j < rn->num_jobs; j++)
            if (!done[j] && same_scene(&rn->jobs[i], &rn->jobs[j])) {
                members[cr.n++] = j;
                done[j] = true;
            }
        run_case(rn, &cr);
    }
    if (!members || !done) rn->oom = true;
    free(members);
    free(done);
}

/* ---- the suite ----------------------------------------------------------------------- */

bool stab_run(const Technique *const *techs, int n, bool engine_cases, const StabOptions *o, StabRowFn row,
              void *user, Error *err)
{
    if (!o->work_dir) return error_set(err, "stability: no scratch folder");
    int threads = stab_thread_count();
    if (threads > 1)
        return error_set(err, "stability: runs are forked, but this process already has %d threads", threads);
    if (o->jobs < 0 || o->jobs > MAX_JOBS) return error_set(err, "stability: jobs %d outside [1, %d]", o->jobs, MAX_JOBS);
    Runner rn = {.o = o, .st = settings(o->quick), .row = row, .user = user};
    rn.timeout_s = o->timeout_s > 0 ? o->timeout_s : DEFAULT_TIMEOUT_S;
    rn.jobs_at_once = o->jobs > 0 ? o->jobs : 1;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    rn.threads = o->threads > 0 ? o->threads : (int)fmax(1.0, (double)(cores > 0 ? cores : 1) / rn.jobs_at_once);
    int count = techs ? n : tech_count();
    for (int i = 0; i < count; i++) {
        const Technique *t = techs ? techs[i] : tech_at(i);
        for (int c = 0; c < stab_cases_count(); c++)
            if (stab_cases_at(c)->plan != PLAN_NONE) plan_case(&rn, t, stab_cases_at(c));
        plan_param_probes(&rn, t);
    }
    for (int c = 0; engine_cases && c < stab_cases_count(); c++) {
        const StabCase *sc = stab_cases_at(c);
        if (sc->plan == PLAN_NONE && wanted(&rn, sc->name)) add_job(&rn, NULL, sc, -1, PROBE_NONE, LIGHT_POINT, sc->name);
    }
    if (!rn.oom) run_planned(&rn);
    free(rn.jobs);
    return !rn.oom || error_set(err, "stability: out of memory for the runs");
}
