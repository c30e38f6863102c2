/* stability.c -- the stability runner: expands the case table and every
 * technique's parameter declarations into runs, writes each run's scene, and
 * runs it in a forked child under a time bound, so a crash, a hang or a
 * sanitizer report becomes one failed row with its cause. The children do
 * the work (stability_exec.c); this process never starts a thread. */
#define _POSIX_C_SOURCE 200809L
#include "lab/stability.h"
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "core/fsutil.h"
#include "core/timer.h"
#include "io/exr.h"
#include "lab/stability_cases.h"

#define DEFAULT_TIMEOUT_S 120.0

const char *stab_status_name(StabStatus s)
{
    static const char *const names[] = {"pass", "FAIL", "n/a"};
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

typedef struct Runner {
    const StabOptions *o;
    StabSettings st;
    StabRowFn row;
    void *user;
    int serial;
} Runner;

static bool wanted(const Runner *rn, const char *case_name)
{
    return !rn->o->only || strstr(case_name, rn->o->only);
}

/* ---- scene files --------------------------------------------------------------- */

static bool write_bytes(const char *path, const void *data, size_t n, Error *err)
{
    FILE *fp = fopen(path, "wb");
    if (!fp) return error_set(err, "%s: cannot write: %s", path, strerror(errno));
    bool ok = fwrite(data, 1, n, fp) == n;
    ok = fclose(fp) == 0 && ok;
    return ok || error_set(err, "%s: write failed", path);
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

/* ---- the child ------------------------------------------------------------------ */

/* The line of a child's stderr that says most: a sanitizer's error line,
 * else any sanitizer line, else the last one. */
static void log_excerpt(const char *log_path, char *out, size_t n)
{
    out[0] = '\0';
    char *text = file_read_all(log_path, NULL, NULL);
    if (!text) return;
    char *error = NULL, *sanitizer = NULL, *last = NULL;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (!error && (strstr(line, "ERROR: ") || strstr(line, "runtime error"))) error = line;
        if (!sanitizer && strstr(line, "Sanitizer")) sanitizer = line;
        if (line[strspn(line, " \t")]) last = line;
    }
    const char *best = error ? error : sanitizer ? sanitizer : last;
    if (best) snprintf(out, n, "%.300s", best);
    free(text);
}

static void child(const StabJob *j, const char *scene_path, const char *log_path, int fd, StabResult *r)
{
    FILE *log = freopen(log_path, "w", stderr);
    (void)log;
    stab_job_execute(j, scene_path, r);
    size_t done = 0;
    while (done < sizeof *r) {
        ssize_t k = write(fd, (const char *)r + done, sizeof *r - done);
        if (k <= 0) break;
        done += (size_t)k;
    }
    close(fd);
    exit(0); /* atexit handlers run, so LeakSanitizer checks the run */
}

/* Read the child's result until EOF or the deadline; true if all of it came. */
static bool read_result(int fd, double deadline, StabResult *r)
{
    StabResult got;
    size_t done = 0;
    while (done < sizeof got) {
        int ms = (int)fmax(0.0, (deadline - timer_now_s()) * 1000.0);
        struct pollfd p = {fd, POLLIN, 0};
        int k = poll(&p, 1, ms);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return false;
        ssize_t n = read(fd, (char *)&got + done, sizeof got - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        done += (size_t)n;
    }
    *r = got;
    return true;
}

/* Wait for the child until the deadline, then kill it. */
static int reap(pid_t pid, double deadline, bool *killed)
{
    int status = 0;
    *killed = false;
    for (;;) {
        pid_t w = waitpid(pid, &status, WNOHANG);
        if (w == pid) return status;
        if (w < 0 && errno != EINTR) return 0;
        if (timer_now_s() > deadline) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            *killed = true;
            return status;
        }
        usleep(2000);
    }
}

static void judge_exit(bool have_result, bool killed, int status, double timeout_s, const char *log_path, StabResult *r)
{
    char excerpt[320];
    log_excerpt(log_path, excerpt, sizeof excerpt);
    bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    bool sanitizer = strstr(excerpt, "Sanitizer") || strstr(excerpt, "runtime error");
    bool caught_signal = strstr(excerpt, "DEADLYSIGNAL") || strstr(excerpt, "SEGV on");
    if (!killed && clean && have_result) return;
    r->status = STAB_FAIL;
    if (killed) snprintf(r->detail, sizeof r->detail, "no result within %.0f s (hang?) %s", timeout_s, excerpt);
    else if (WIFSIGNALED(status))
        snprintf(r->detail, sizeof r->detail, "crashed: signal %d (%s) %s", WTERMSIG(status),
                 strsignal(WTERMSIG(status)), excerpt);
    else if (caught_signal) snprintf(r->detail, sizeof r->detail, "crashed (signal caught by the sanitizer): %s", excerpt);
    else if (sanitizer)
        snprintf(r->detail, sizeof r->detail, "sanitizer report%s: %s", have_result ? " after the run" : "", excerpt);
    else if (!clean) snprintf(r->detail, sizeof r->detail, "exit status %d: %s", WEXITSTATUS(status), excerpt);
    else snprintf(r->detail, sizeof r->detail, "the child gave no result %s", excerpt);
}

static void run_isolated(const StabJob *j, const char *scene_path, const char *log_path, double timeout_s,
                         StabResult *r)
{
    int fds[2];
    if (pipe(fds) != 0) {
        snprintf(r->detail, sizeof r->detail, "pipe: %s", strerror(errno));
        return;
    }
    fflush(NULL);
    double t0 = timer_now_s();
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(r->detail, sizeof r->detail, "fork: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return;
    }
    if (pid == 0) {
        close(fds[0]);
        child(j, scene_path, log_path, fds[1], r);
    }
    close(fds[1]);
    double deadline = t0 + timeout_s;
    bool have = read_result(fds[0], deadline, r);
    close(fds[0]);
    bool killed;
    int status = reap(pid, deadline, &killed);
    judge_exit(have, killed, status, timeout_s, log_path, r);
    r->seconds = timer_now_s() - t0;
    remove(log_path);
}

/* ---- one run ---------------------------------------------------------------------- */

static void run_job(Runner *rn, const StabJob *j, const char *case_name)
{
    const char *tech = j->tech ? j->tech->name : "-";
    bool has_light = !(j->c && j->c->plan == PLAN_NONE);
    StabResult r;
    row_init(&r, tech, case_name, has_light ? light_kind_name(j->kind) : "");
    SceneSpec *s = malloc(sizeof *s);
    if (!s) {
        snprintf(r.detail, sizeof r.detail, "out of memory");
        rn->row(&r, rn->user);
        return;
    }
    build_spec(j, s);
    Written w = {.num_files = s->num_files};
    for (int i = 0; i < s->num_files; i++) snprintf(w.files[i], sizeof w.files[i], "%s", s->files[i].name);
    char log_path[1100];
    if (rn->o->scene_dir)
        snprintf(w.dir, sizeof w.dir, "%s/%s-%s%s%s", rn->o->scene_dir, j->tech ? tech : "engine", case_name,
                 has_light ? "-" : "", r.light);
    else snprintf(w.dir, sizeof w.dir, "%s/run-%d", rn->o->work_dir, rn->serial);
    snprintf(log_path, sizeof log_path, "%s/child-%d.log", rn->o->work_dir, rn->serial++);
    Error err;
    bool written = write_scene(s, j->kind, w.dir, w.scene_path, sizeof w.scene_path, &err);
    free(s);
    if (!written) snprintf(r.detail, sizeof r.detail, "cannot write the case: %s", err.msg);
    else run_isolated(j, w.scene_path, log_path, rn->o->timeout_s > 0 ? rn->o->timeout_s : DEFAULT_TIMEOUT_S, &r);
    if (!rn->o->scene_dir) remove_scene(&w);
    rn->row(&r, rn->user);
}

static void not_applicable(Runner *rn, const Technique *t, const StabCase *c)
{
    StabResult r;
    row_init(&r, t->name, c->name, "");
    r.status = STAB_NOT_APPLICABLE;
    char handles[160], needs[160];
    tech_lights_text(t, handles, sizeof handles);
    Technique fake = {.lights = c->lights};
    tech_lights_text(&fake, needs, sizeof needs);
    snprintf(r.detail, sizeof r.detail, "%s handles %s lights; the case needs %s", t->name, handles, needs);
    rn->row(&r, rn->user);
}

static void run_case(Runner *rn, const Technique *t, const StabCase *c)
{
    if (!wanted(rn, c->name)) return;
    LightKind kinds[8];
    int n = plan_kinds(c, t->lights, rn->st.quick, kinds);
    if (n == 0) {
        not_applicable(rn, t, c);
        return;
    }
    for (int k = 0; k < n; k++) {
        StabJob j = {t, c, -1, PROBE_NONE, kinds[k], rn->st, rn->o->threads};
        run_job(rn, &j, c->name);
    }
}

static bool probe_applies(const ParamDesc *p, ParamProbe probe)
{
    if (probe == PROBE_MIN_PLUS_ONE) return p->type == PARAM_INT && p->max >= p->min + 2;
    return true;
}

static void run_param_probes(Runner *rn, const Technique *t)
{
    LightKind kind;
    if (!first_of(any_order, 7, t->lights, &kind)) return;
    for (int i = 0; i < t->num_params; i++) {
        for (int probe = PROBE_AT_MIN; probe < PROBE_COUNT; probe++) {
            if (!probe_applies(&t->params[i], (ParamProbe)probe)) continue;
            char name[STAB_NAME_MAX];
            snprintf(name, sizeof name, "param_%s_%s", t->params[i].name, stab_probe_suffix((ParamProbe)probe));
            if (!wanted(rn, name)) continue;
            StabJob j = {t, NULL, i, (ParamProbe)probe, kind, rn->st, rn->o->threads};
            run_job(rn, &j, name);
        }
    }
}

/* ---- the suite ----------------------------------------------------------------------- */

/* Forking is safe only while this process has one thread. */
static int thread_count(void)
{
    DIR *d = opendir("/proc/self/task");
    if (!d) return 1;
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static StabSettings settings(bool quick)
{
    return quick ? (StabSettings){true, 40, 30, 16} : (StabSettings){false, 128, 96, 256};
}

bool stab_run(const Technique *const *techs, int n, bool engine_cases, const StabOptions *o, StabRowFn row,
              void *user, Error *err)
{
    if (!o->work_dir) return error_set(err, "stability: no scratch folder");
    int threads = thread_count();
    if (threads > 1)
        return error_set(err, "stability: runs are forked, but this process already has %d threads", threads);
    Runner rn = {o, settings(o->quick), row, user, 0};
    int count = techs ? n : tech_count();
    for (int i = 0; i < count; i++) {
        const Technique *t = techs ? techs[i] : tech_at(i);
        for (int c = 0; c < stab_cases_count(); c++)
            if (stab_cases_at(c)->plan != PLAN_NONE) run_case(&rn, t, stab_cases_at(c));
        run_param_probes(&rn, t);
    }
    for (int c = 0; engine_cases && c < stab_cases_count(); c++) {
        const StabCase *sc = stab_cases_at(c);
        if (sc->plan != PLAN_NONE || !wanted(&rn, sc->name)) continue;
        StabJob j = {NULL, sc, -1, PROBE_NONE, LIGHT_POINT, rn.st, o->threads};
        run_job(&rn, &j, sc->name);
    }
    return true;
}
