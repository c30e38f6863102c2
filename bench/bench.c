/* bench.c -- the bench programs' shared CSV rows and helpers (bench.h). */
#include "bench.h"
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
