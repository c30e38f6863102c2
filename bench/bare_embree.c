/* bare_embree.c -- the reference's throughput against a bare Embree loop.
 * Both trace the same occlusion rays: the scene's casters BVH, view samples
 * and classes from the lab's resource manager; for every lit-candidate sample
 * the reference's origin offset, sample stream (r2, seed 1) and light samples,
 * in packets of 16 with rtcOccluded16 over rows (OpenMP, dynamic 1). The bare
 * loop only counts unoccluded rays; reference_compute does everything it
 * does. Rounds alternate bare, reference (after one untimed warm-up round);
 * every round checks that both saw the same rays, medians are reported and
 * one CSV row is added to reports/bench/reference_throughput.csv.
 * With --scaling, both instead run on the thread curve 1, 2, 4, ... N
 * (bench.h's BenchCurve, bare then reference at each count, still checked
 * against each other): the bare loop's own speed-up, the reference's, and
 * their ratio (median of per-round reference / bare speed-ups, target >=
 * 0.9 of the bare loop's scaling), one row per count, into the -o CSV.
 * Usage: bare_embree [SCENE] [-n SAMPLES] [--threads N] [--repeat R] [--scaling] [-o CSV] */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "lab/lab.h"

#define PACKET 16
#define SEED 1u
#define PATTERN SAMPLING_R2
#define CSV_HEADER "scene,triangles,samples,rays,bare_rays_per_s,reference_rays_per_s,ratio," BENCH_TAIL_HEADER "\n"
#define SCALING_BOUND 0.9
#define SCALING_HEADER "scene,triangles,samples,rays,bare_ms_1,bare_ms_n,bare_speedup,reference_ms_1," \
                       "reference_ms_n,reference_speedup,ratio,bound,within," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    const char *scene, *csv;
    int samples, threads, repeat;
    bool scaling;
} Options;

/* What both loops trace, fetched once (untimed). */
typedef struct Inputs {
    const Scene *scene;
    const RtScene *casters;
    const ViewSamples *vs;
    const uint8_t *cls;
    int light_index;
    int count;      /* rays per candidate sample: N, or 1 for delta lights */
    long long rays; /* rays per pass */
} Inputs;

/* Medians over the timed rounds. */
typedef struct Result {
    double bare_s, ref_s, ratio; /* ratio: median of per-round bare_s / ref_s */
} Result;

static int usage(const char *msg)
{
    fprintf(stderr,
            "bare_embree: %s\nusage: bare_embree [SCENE] [-n SAMPLES] [--threads N] [--repeat R] [--scaling] [-o CSV]\n",
            msg);
    return 1;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){"scenes/sphere-on-plane.lua", "reports/bench/reference_throughput.csv", 256,
                   omp_get_max_threads(), 5, false};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok;
        if (strcmp(a, "--scaling") == 0) { o->scaling = true; continue; }
        if (strcmp(a, "-n") == 0) ok = bench_parse_int(v, 1, REFERENCE_MAX_SAMPLES, &o->samples);
        else if (strcmp(a, "--threads") == 0) ok = bench_parse_int(v, 1, 1024, &o->threads);
        else if (strcmp(a, "--repeat") == 0) ok = bench_parse_int(v, 1, 1000, &o->repeat);
        else if (strcmp(a, "-o") == 0) ok = (o->csv = v) != NULL;
        else if (a[0] != '-') { o->scene = a; continue; }
        else return false;
        if (!ok) return false;
        i++;
    }
    return true;
}

static ReferenceParams ref_params(const Options *o)
{
    return (ReferenceParams){MEASURE_VISIBILITY, o->samples, PATTERN, SEED};
}

static bool load_inputs(Lab *lab, const Options *o, Inputs *in, Error *err)
{
    ResourceManager *rm = lab_resources(lab);
    in->scene = lab_scene(lab);
    if (!lab_light_index(lab, 1, &in->light_index, err)) return false;
    in->casters = res_bvh(rm, in->scene, RT_CASTERS, err);
    in->vs = in->casters ? res_view_samples(rm, in->scene, err) : NULL;
    in->cls = in->vs ? res_classes(rm, in->scene, in->light_index, err) : NULL;
    if (!in->cls) return false;
    in->count = light_is_delta(&in->scene->lights[in->light_index]) ? 1 : o->samples;
    long long candidates = 0;
    for (int s = 0; s < in->vs->count; s++) candidates += in->cls[s] == SAMPLE_LIT_CANDIDATE;
    in->rays = candidates * in->count;
    return true;
}

/* ---- the bare loop ------------------------------------------------------ */

/* Fields that no ray of a thread ever changes. */
static void packet_init(struct RTCRay16 *r)
{
    for (int k = 0; k < PACKET; k++) {
        r->tnear[k] = 0.0f;
        r->time[k] = 0.0f;
        r->mask[k] = 0xFFFFFFFFu;
        r->id[k] = (unsigned)k;
        r->flags[k] = 0;
    }
}

static void packet_origin(struct RTCRay16 *r, vec3 org)
{
    for (int k = 0; k < PACKET; k++) {
        r->org_x[k] = org.x; r->org_y[k] = org.y; r->org_z[k] = org.z;
    }
}

static void packet_fill(struct RTCRay16 *r, int *valid, const Light *l, vec3 p, uint32_t stream, int first,
                        int count)
{
    for (int k = 0; k < PACKET; k++) {
        int i = first + k;
        valid[k] = i < count ? -1 : 0;
        if (i >= count) continue;
        float u, v;
        sample_2d(PATTERN, stream, i, count, &u, &v);
        LightSample s = light_sample(l, p, u, v);
        r->dir_x[k] = s.dir_world.x; r->dir_y[k] = s.dir_world.y; r->dir_z[k] = s.dir_world.z;
        r->tfar[k] = isinf(s.dist) ? INFINITY : s.dist * (1.0f - 1e-5f);
    }
}

static long long packet_unoccluded(const struct RTCRay16 *r, const int *valid)
{
    long long n = 0;
    for (int k = 0; k < PACKET; k++) n += valid[k] && r->tfar[k] != -INFINITY;
    return n;
}

static long long bare_sample(const Inputs *in, RTCScene rtc, float extent, int s, struct RTCIntersectContext *ctx,
                             struct RTCRay16 *r, int *valid)
{
    vec3 p = in->vs->p_world[s];
    packet_origin(r, v3_madd(p, in->vs->n_geom_world[s], rt_ray_offset(extent, p)));
    uint32_t stream = sampling_stream(SEED, (uint32_t)s);
    const Light *l = &in->scene->lights[in->light_index];
    long long lit = 0;
    for (int first = 0; first < in->count; first += PACKET) {
        packet_fill(r, valid, l, p, stream, first, in->count);
        rtcOccluded16(valid, rtc, ctx, r);
        lit += packet_unoccluded(r, valid);
    }
    return lit;
}

/* One pass over every lit candidate; returns the unoccluded ray count. */
static long long bare_trace(const Inputs *in)
{
    RTCScene rtc = rt_scene_handle(in->casters);
    float extent = scene_extent(in->scene);
    const ViewSamples *vs = in->vs;
    long long lit = 0;
#pragma omp parallel reduction(+ : lit)
    {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct RTCRay16 ray;
        _Alignas(64) int valid[PACKET];
        packet_init(&ray);
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < vs->height; y++)
            for (int s = y * vs->width; s < (y + 1) * vs->width; s++)
                if (in->cls[s] == SAMPLE_LIT_CANDIDATE) lit += bare_sample(in, rtc, extent, s, &ctx, &ray, valid);
    }
    return lit;
}

/* ---- rounds and the agreement check ------------------------------------- */

/* Unoccluded rays the reference saw: round(visibility * count) per candidate. */
static long long reference_unoccluded(const Inputs *in, const Reference *ref)
{
    long long n = 0;
    for (int s = 0; s < in->vs->count; s++)
        if (in->cls[s] == SAMPLE_LIT_CANDIDATE) n += llround((double)ref->value.data[s] * in->count);
    return n;
}

static bool check_agreement(const Inputs *in, const Reference *ref, long long bare_lit, Error *err)
{
    if (ref->rays != in->rays)
        return error_set(err, "MISMATCH: the reference traced %lld rays, the bare loop %lld", ref->rays, in->rays);
    if (ref->value.channels != 1) return true; /* RGB-weighted visibility: no ray count to recover */
    long long ref_lit = reference_unoccluded(in, ref);
    if (ref_lit != bare_lit)
        return error_set(err, "MISMATCH: unoccluded rays: reference %lld, bare loop %lld (of %lld)", ref_lit,
                         bare_lit, in->rays);
    return true;
}

/* One bare pass then one reference pass, timed, and checked against each other. */
static bool run_round(const Inputs *in, const ReferenceParams *prm, double *bare_s, double *ref_s, Error *err)
{
    double t0 = timer_now_s();
    long long lit = bare_trace(in);
    double t1 = timer_now_s();
    Reference ref;
    bool ok = reference_compute(in->casters, in->scene, in->light_index, in->vs, in->cls, prm, &ref, err);
    double t2 = timer_now_s();
    if (!ok) return false;
    *bare_s = t1 - t0;
    *ref_s = t2 - t1;
    ok = check_agreement(in, &ref, lit, err);
    reference_free(&ref);
    return ok;
}

static bool measure(const Inputs *in, const Options *o, Result *res, Error *err)
{
    ReferenceParams prm = ref_params(o);
    double warm_b, warm_r, *t = malloc(sizeof(double) * 3 * (size_t)o->repeat);
    if (!t) return error_set(err, "out of memory");
    double *bare = t, *ref = t + o->repeat, *ratio = t + 2 * o->repeat;
    bool ok = run_round(in, &prm, &warm_b, &warm_r, err);
    for (int i = 0; ok && i < o->repeat; i++) {
        ok = run_round(in, &prm, &bare[i], &ref[i], err);
        ratio[i] = bare[i] / ref[i];
    }
    if (ok)
        *res = (Result){timer_median(bare, o->repeat), timer_median(ref, o->repeat), timer_median(ratio, o->repeat)};
    free(t);
    return ok;
}

/* ---- the thread curve ---------------------------------------------------- */

/* What the curve's two sides share: side 0 is the bare loop, side 1 the
 * reference, checked against the bare pass just before it. */
typedef struct CurveRun {
    const Inputs *in;
    ReferenceParams prm;
    long long bare_lit;
} CurveRun;

static bool curve_side(void *ctx, int side, int threads, double *seconds, Error *err)
{
    CurveRun *cr = ctx;
    (void)threads;
    double t0 = timer_now_s();
    if (side == 0) {
        cr->bare_lit = bare_trace(cr->in);
        *seconds = timer_now_s() - t0;
        return true;
    }
    Reference ref;
    if (!reference_compute(cr->in->casters, cr->in->scene, cr->in->light_index, cr->in->vs, cr->in->cls, &cr->prm,
                           &ref, err))
        return false;
    *seconds = timer_now_s() - t0;
    bool ok = check_agreement(cr->in, &ref, cr->bare_lit, err);
    reference_free(&ref);
    return ok;
}

static bool scaling_rows(const Inputs *in, const Options *o, const BenchCurve *c, Error *err)
{
    char name[160];
    bench_csv_field(name, sizeof name, in->scene->name);
    printf("%s: %lld rays per pass, %d samples; speed-ups over 1 thread (medians of %d rounds):\n", in->scene->name,
           in->rays, o->samples, c->rounds);
    bool ok = true;
    for (int k = 0; ok && k < c->points; k++) {
        double b1 = bench_curve_median_s(c, 0, 0) * 1e3, bk = bench_curve_median_s(c, 0, k) * 1e3;
        double r1 = bench_curve_median_s(c, 1, 0) * 1e3, rk = bench_curve_median_s(c, 1, k) * 1e3;
        double bs = bench_curve_speedup(c, 0, k), rs = bench_curve_speedup(c, 1, k), ratio = bench_curve_relative(c, 1, 0, k);
        bool within = ratio >= SCALING_BOUND;
        printf("  %2d threads: bare %8.2f ms (x%.2f), reference %8.2f ms (x%.2f), ratio %.3f (bound %.1f)%s\n",
               c->threads[k], bk, bs, rk, rs, ratio, SCALING_BOUND, within ? "" : "  UNDER");
        char row[1024], tail[512];
        bench_tail(tail, sizeof tail, c->threads[k]);
        snprintf(row, sizeof row, "%s,%d,%d,%lld,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%s,%s\n", name,
                 in->scene->num_triangles, o->samples, in->rays, b1, bk, bs, r1, rk, rs, ratio, SCALING_BOUND,
                 within ? "yes" : "no", tail);
        ok = bench_csv_append(o->csv, SCALING_HEADER, row, err);
    }
    return ok;
}

static bool scaling(const Inputs *in, const Options *o, Error *err)
{
    CurveRun cr = {in, ref_params(o), 0};
    BenchCurve c;
    bool ok = bench_curve_init(&c, o->threads, 2, o->repeat, err) && bench_curve_measure(&c, curve_side, &cr, err) &&
              scaling_rows(in, o, &c, err);
    bench_curve_free(&c);
    return ok;
}

/* ---- the record --------------------------------------------------------- */

/* Add one row to the CSV (bench.h: earlier rows kept under the same header). */
static bool append_csv(const char *path, const Inputs *in, const Options *o, const Result *r, Error *err)
{
    char row[1024], name[160], tail[512];
    bench_csv_field(name, sizeof name, in->scene->name);
    bench_tail(tail, sizeof tail, o->threads);
    snprintf(row, sizeof row, "%s,%d,%d,%lld,%.0f,%.0f,%.4f,%s\n", name, in->scene->num_triangles, o->samples,
             in->rays, in->rays / r->bare_s, in->rays / r->ref_s, r->ratio, tail);
    return bench_csv_append(path, CSV_HEADER, row, err);
}

static void print_summary(const Inputs *in, const Options *o, const Result *r)
{
    printf("%s: %d triangles, %lld rays per pass, %d samples, %d threads\n", in->scene->name,
           in->scene->num_triangles, in->rays, o->samples, o->threads);
    printf("reference %.1f Mrays/s, bare %.1f Mrays/s, ratio %.2f (median of %d)\n", in->rays / r->ref_s * 1e-6,
           in->rays / r->bare_s * 1e-6, r->ratio, o->repeat);
}

static bool bench(const Options *o, Error *err)
{
    Lab *lab = lab_open(o->scene, NULL, 0, err);
    if (!lab) return false;
    Inputs in;
    Result r = {0};
    bool ok = load_inputs(lab, o, &in, err);
    if (ok && o->scaling) {
        ok = scaling(&in, o, err);
        lab_close(lab);
        return ok;
    }
    ok = ok && measure(&in, o, &r, err);
    if (ok) {
        print_summary(&in, o, &r);
        ok = append_csv(o->csv, &in, o, &r, err);
    }
    lab_close(lab);
    return ok;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o)) return usage("bad arguments");
    omp_set_num_threads(o.threads);
    rt_set_threads(o.threads);
    Error err;
    if (!bench(&o, &err)) {
        fprintf(stderr, "bare_embree: %s\n", err.msg);
        return 1;
    }
    return 0;
}
