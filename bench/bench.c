/* bench.c -- the bench programs' shared CSV rows and helpers (bench.h). */
#include "bench.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "core/fsutil.h"
#include "core/machine.h"
#include "core/timer.h"
#include "version.h"

void bench_csv_field(char *out, size_t n, const char *s)
{
    if (!strpbrk(s, ",\"\n")) { snprintf(out, n, "%s", s); return; }
    size_t k = 0;
    if (k + 1 < n) out[k++] = '"';
    for (; *s && k + 3 < n; s++) {
        if (*s == '"') out[k++] = '"';
        out[k++] = *s;
    }
    if (k + 1 < n) out[k++] = '"';
    out[k < n ? k : n - 1] = '\0';
}

double bench_load1(void)
{
    FILE *fp = fopen("/proc/loadavg", "r");
    double load = -1.0;
    if (fp) {
        if (fscanf(fp, "%lf", &load) != 1) load = -1.0;
        fclose(fp);
    }
    return load;
}

void bench_tail(char *out, size_t n, int threads)
{
    char cpu[256], cpu_q[300], commit_q[64], date[32];
    time_t now = time(NULL);
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    machine_cpu_model(cpu, sizeof cpu);
    bench_csv_field(cpu_q, sizeof cpu_q, cpu);
    bench_csv_field(commit_q, sizeof commit_q, SHADOWLAB_COMMIT);
    snprintf(out, n, "%d,%s,%s,%.2f,%s", threads, commit_q, cpu_q, bench_load1(), date);
}

/* Rows already in the file, if it has this header; NULL otherwise. */
static char *previous_rows(const char *path, const char *header)
{
    if (!file_exists(path)) return NULL;
    Error ignored;
    char *text = file_read_all(path, NULL, &ignored);
    if (text && strncmp(text, header, strlen(header)) == 0) return text;
    if (text) fprintf(stderr, "bench: note: %s has another header; starting it afresh\n", path);
    free(text);
    return NULL;
}

/* The old rows (or the header) plus `row` go to a fresh file, renamed into place. */
static bool write_csv(const char *path, const char *header, const char *row, bool keep, Error *err)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    if (slash && !mkdir_p(dir, err)) return false;
    char *old = keep ? previous_rows(path, header) : NULL;
    AtomicFile af;
    if (!atomic_open(&af, path, err)) { free(old); return false; }
    fputs(old ? old : header, af.fp);
    free(old);
    if (row) fputs(row, af.fp);
    return atomic_commit(&af, err);
}

bool bench_csv_append(const char *path, const char *header, const char *row, Error *err)
{
    return write_csv(path, header, row, true, err);
}

bool bench_csv_reset(const char *path, const char *header, Error *err)
{
    return write_csv(path, header, NULL, false, err);
}

bool bench_parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || end == s || *end != '\0' || v < lo || v > hi) return false;
    *out = (int)v;
    return true;
}

double bench_median(const double *v, int n)
{
    double *copy = malloc(sizeof *copy * (size_t)n);
    if (!copy) return v[0];
    memcpy(copy, v, sizeof *copy * (size_t)n);
    double m = timer_median(copy, n);
    free(copy);
    return m;
}

bool bench_paired(BenchPairFn round, void *run, int repeat, double med[3], Error *err)
{
    double *t = malloc(sizeof *t * 3 * (size_t)repeat), a_s, b_s;
    if (!t) return error_set(err, "out of memory");
    bool ok = round(run, &a_s, &b_s, err);
    for (int i = 0; ok && i < repeat; i++) {
        ok = round(run, &t[i], &t[repeat + i], err);
        t[2 * repeat + i] = t[i] / t[repeat + i];
    }
    for (int k = 0; ok && k < 3; k++) med[k] = bench_median(t + k * repeat, repeat);
    free(t);
    return ok;
}

int bench_casters(const Scene *scene, RasterMesh *out, int max, long *triangles)
{
    int n = 0;
    *triangles = 0;
    for (int i = 0; i < scene->num_objects; i++) {
        const Object *o = &scene->objects[i];
        if (!o->caster) continue;
        if (n == max) return -1;
        out[n++] = (RasterMesh){o->mesh.positions, o->mesh.indices, o->mesh.num_vertices, o->mesh.num_triangles};
        *triangles += o->mesh.num_triangles;
    }
    return n;
}

const ShadowMap *bench_map(Lab *lab, int res, Error *err)
{
    ShadowMapSpec spec = shadowmap_spec_default();
    spec.res = res;
    spec.depth = RASTER_DEPTH_NDC;
    spec.projection = MAP_PROJ_PERSPECTIVE; /* one face: a sphere light over a wide scene would get a cube */
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, err);
    if (m && m->num_faces != 1) {
        error_set(err, "light 1's map has %d faces; the rasterizer benches draw one", m->num_faces);
        return NULL;
    }
    return m;
}

/* ---- a technique's light ------------------------------------------------- */

/* Half the width of light l (see bench_lab_open). */
static float light_half_width(const Light *l, const Scene *sc)
{
    switch (l->kind) {
    case LIGHT_SPHERE:
    case LIGHT_DISK: return l->radius;
    case LIGHT_RECT:
    case LIGHT_TEXTURED_RECT: return 0.5f * sqrtf(l->width * l->height);
    default: return 0.01f * scene_extent(sc);
    }
}

/* "lights[1]={...}": light 1 as `kind`, in place of the scene's own. */
static void substitute_override(const Scene *sc, LightKind kind, char *out, size_t n, char *text, size_t tn)
{
    const Light *l = &sc->lights[0];
    vec3 centre = v3_scale(v3_add(sc->bounds_min, sc->bounds_max), 0.5f);
    vec3 p = l->kind == LIGHT_DIRECTIONAL ? v3_madd(centre, l->direction, -scene_extent(sc)) : l->position;
    vec3 d = v3_normalize_or(v3_sub(centre, p), v3(0, -1, 0));
    vec3 up = fabsf(d.y) < 0.9f ? v3(0, 1, 0) : v3(0, 0, -1); /* the loader orthonormalises it */
    float r = light_half_width(l, sc);
    int k = snprintf(out, n, "lights[1]={type=\"%s\", position={%.9g,%.9g,%.9g}, color={%.9g,%.9g,%.9g}, "
                     "intensity=%.9g", light_kind_name(kind), p.x, p.y, p.z, l->color.x, l->color.y, l->color.z,
                     l->intensity);
    if (kind == LIGHT_RECT || kind == LIGHT_DISK)
        k += snprintf(out + k, n - (size_t)k, ", direction={%.9g,%.9g,%.9g}", d.x, d.y, d.z);
    if (kind == LIGHT_RECT)
        k += snprintf(out + k, n - (size_t)k, ", up={%.9g,%.9g,%.9g}, width=%.9g, height=%.9g", up.x, up.y, up.z,
                      2.0f * r, 2.0f * r);
    if (kind == LIGHT_SPHERE || kind == LIGHT_DISK) k += snprintf(out + k, n - (size_t)k, ", radius=%.9g", r);
    snprintf(out + k, n - (size_t)k, "}");
    char size[48] = "";
    if (kind == LIGHT_RECT) snprintf(size, sizeof size, " %.3g x %.3g", 2.0f * r, 2.0f * r);
    if (kind == LIGHT_SPHERE || kind == LIGHT_DISK) snprintf(size, sizeof size, " r=%.3g", r);
    snprintf(text, tn, "%s%s in place of %s", light_kind_name(kind), size, light_kind_name(l->kind));
}

/* The first kind of `substitutes` t handles, or -1. */
static int substitute_kind(const Technique *t)
{
    static const LightKind substitutes[] = {LIGHT_RECT, LIGHT_SPHERE, LIGHT_DISK, LIGHT_POINT};
    for (int s = 0; s < 4; s++)
        if (t->lights & LIGHT_BIT(substitutes[s])) return (int)substitutes[s];
    return -1;
}

Lab *bench_lab_open(const char *scene, const Technique *t, const char *const *overrides, int n, BenchLight *used,
                    Error *err)
{
    const char *ov[BENCH_MAX_OVERRIDES];
    char light[1000];
    if (n >= BENCH_MAX_OVERRIDES) {
        error_set(err, "more than %d scene overrides", BENCH_MAX_OVERRIDES - 1);
        return NULL;
    }
    Lab *lab = lab_open(scene, overrides, n, err);
    if (!lab) return NULL;
    int first;
    if (!lab_light_index(lab, 1, &first, err)) {
        lab_close(lab);
        return NULL;
    }
    const Light *l = &lab_scene(lab)->lights[first];
    *used = (BenchLight){.substituted = !(t->lights & LIGHT_BIT(l->kind))};
    snprintf(used->text, sizeof used->text, "%s", light_kind_name(l->kind));
    if (!used->substituted) return lab;
    int kind = substitute_kind(t);
    if (kind >= 0) {
        substitute_override(lab_scene(lab), (LightKind)kind, light, sizeof light, used->text, sizeof used->text);
    } else {
        tech_check_light(t, l, 1, err); /* fails, naming the kinds t handles */
        error_prefix(err, "%s: no rect, sphere, disk or point light can replace light 1: ", scene);
    }
    lab_close(lab);
    if (kind < 0) return NULL;
    for (int i = 0; i < n; i++) ov[i] = overrides[i];
    ov[n] = light;
    return lab_open(scene, ov, n + 1, err);
}

/* ---- thread-scaling curves ------------------------------------------------ */

bool bench_curve_init(BenchCurve *c, int max_threads, int sides, int rounds, Error *err)
{
    *c = (BenchCurve){.sides = sides, .rounds = rounds};
    if (rounds < 1 || rounds > 1000 || max_threads < 1) return error_set(err, "curve: rounds in [1, 1000], threads >= 1");
    for (int k = 1; k < max_threads && c->points < BENCH_MAX_CURVE - 1; k *= 2) c->threads[c->points++] = k;
    c->threads[c->points++] = max_threads;
    c->s = malloc(sizeof *c->s * (size_t)(sides * c->points * rounds));
    return c->s || error_set(err, "out of memory");
}

static double *curve_at(const BenchCurve *c, int side, int k) { return c->s + (side * c->points + k) * c->rounds; }

/* Every side at every count once; times into round r (r < 0: untimed). */
static bool curve_round(BenchCurve *c, BenchTimedFn fn, void *ctx, int r, Error *err)
{
    for (int k = 0; k < c->points; k++) {
        omp_set_num_threads(c->threads[k]);
        for (int side = 0; side < c->sides; side++) {
            double s;
            if (!fn(ctx, side, c->threads[k], &s, err)) return false;
            if (r >= 0) curve_at(c, side, k)[r] = s;
        }
    }
    return true;
}

bool bench_curve_measure(BenchCurve *c, BenchTimedFn fn, void *ctx, Error *err)
{
    bool ok = curve_round(c, fn, ctx, -1, err);
    for (int r = 0; ok && r < c->rounds; r++) ok = curve_round(c, fn, ctx, r, err);
    omp_set_num_threads(c->threads[c->points - 1]);
    return ok;
}

double bench_curve_median_s(const BenchCurve *c, int side, int k) { return bench_median(curve_at(c, side, k), c->rounds); }

/* t(1) / t(k) of `side` in one round. */
static double round_speedup(const BenchCurve *c, int side, int k, int round)
{
    return curve_at(c, side, 0)[round] / curve_at(c, side, k)[round];
}

double bench_curve_relative(const BenchCurve *c, int a, int b, int k)
{
    double v[1000];
    for (int r = 0; r < c->rounds; r++) v[r] = round_speedup(c, a, k, r) / (b < 0 ? 1.0 : round_speedup(c, b, k, r));
    return bench_median(v, c->rounds);
}

double bench_curve_speedup(const BenchCurve *c, int side, int k) { return bench_curve_relative(c, side, -1, k); }

void bench_curve_free(BenchCurve *c)
{
    free(c->s);
    c->s = NULL;
}

/* One common option (or a scene path) at argv[i]: arguments taken, 0 if not common, -1 malformed. */
static int common_arg(BenchCommon *c, const char *a, const char *v)
{
    if (a[0] != '-') {
        if (c->num_scenes == BENCH_MAX_SCENES) return -1;
        c->scenes[c->num_scenes++] = a;
        return 1;
    }
    bool ok;
    if (strcmp(a, "--threads") == 0) ok = bench_parse_int(v, 1, 256, &c->threads);
    else if (strcmp(a, "--repeat") == 0) ok = bench_parse_int(v, 1, 1000, &c->repeat);
    else if (strcmp(a, "-o") == 0) ok = (c->dir = v) != NULL;
    else return 0;
    return ok ? 2 : -1;
}

bool bench_parse(int argc, char **argv, int repeat, BenchCommon *c, BenchOptionFn own, void *options)
{
    *c = (BenchCommon){.threads = omp_get_max_threads(), .repeat = repeat, .dir = "reports/bench"};
    for (int i = 1; i < argc;) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int n = common_arg(c, argv[i], v);
        if (n == 0 && own) n = own(options, argv[i], v);
        if (n <= 0) return false;
        i += n;
    }
    return true;
}

int bench_usage(const char *text)
{
    fprintf(stderr, "usage: %s\n", text);
    return 2;
}

int bench_fail(const char *program, const Error *err)
{
    fprintf(stderr, "%s: %s\n", program, err->msg);
    return 1;
}

/* The loop's result, written so the loop stays (one per thread: the
 * threads of bench_spin_parallel_s write it at once). */
static _Thread_local volatile double spin_result;

double bench_spin_s(long iters)
{
    double x0 = 1.0, x1 = 1.1, x2 = 1.2, x3 = 1.3, a = 0.999999, b = 1e-7;
    double t0 = timer_now_s();
    for (long i = 0; i < iters; i++) {
        x0 = x0 * a + b;
        x1 = x1 * a + b;
        x2 = x2 * a + b;
        x3 = x3 * a + b;
    }
    double s = timer_now_s() - t0;
    spin_result = x0 + x1 + x2 + x3;
    return s;
}

double bench_spin_parallel_s(long iters)
{
    double t0 = timer_now_s();
#pragma omp parallel
    bench_spin_s(iters / omp_get_num_threads());
    return timer_now_s() - t0;
}
