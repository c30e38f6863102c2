/* bare_embree.c -- the reference's throughput against bare Embree loops,
 * the fastest of which is the limit (issue 17). Every loop traces the same
 * occlusion rays as the reference: the scene's casters BVH, view samples and
 * classes from the lab's resource manager; for every lit-candidate sample the
 * reference's origin offset, sample stream (r2, seed 1) and light samples,
 * those on or below the sample's geometric tangent plane dropped, and one ray
 * toward the light's highest point where none is left (reference.c's
 * horizon rule), rows in parallel (OpenMP, dynamic 1). A loop generates one
 * view sample's rays, traces them and counts the unoccluded ones; the
 * variants differ only in the Embree call: rtcOccluded1 ray by ray,
 * rtcOccluded4/8/16 over consecutive rays (a sample's rays in order, the
 * packet's lanes its consecutive light samples: tile order within the
 * sample), and rtcOccluded1M streams of all of a sample's rays with the
 * context flag INCOHERENT (Embree 3's default) or COHERENT. reference_compute
 * does everything they do. Rounds run every variant and the reference, each
 * round starting one pass later in that list (after one untimed warm-up
 * round); every round checks that each variant and the reference saw the
 * same rays and the same visibility per sample, and that the work counters
 * (core/counters.h) counted the rays the reference reports;
 * the limit is the variant with the lowest median time, and the ratio the
 * median over rounds of that variant's time over the reference's. One CSV
 * row is added to reports/bench/reference_throughput.csv.
 * With --scaling, the 16-wide loop and the reference instead run on the
 * thread curve 1, 2, 4, ... N (bench.h's BenchCurve, bare then reference at
 * each count, still checked against each other): the bare loop's own
 * speed-up, the reference's, and their ratio (median of per-round reference
 * / bare speed-ups, target >= 0.9 of the bare loop's scaling), one row per
 * count, into the -o CSV.
 * Usage: bare_embree [SCENE] [-n SAMPLES] [--threads N] [--repeat R] [--scaling] [-o CSV] */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench.h"
#include "core/timer.h"
#include "lab/lab.h"

#define SEED 1u
#define PATTERN SAMPLING_R2
#define CSV_HEADER "scene,triangles,samples,rays,bare_rays_per_s,reference_rays_per_s,ratio,fastest," \
                   "occluded1_rays_per_s,occluded4_rays_per_s,occluded8_rays_per_s,occluded16_rays_per_s," \
                   "occluded1M_incoherent_rays_per_s,occluded1M_coherent_rays_per_s," BENCH_TAIL_HEADER "\n"
#define SCALING_BOUND 0.9
#define SCALING_HEADER "scene,triangles,samples,rays,bare_ms_1,bare_ms_n,bare_speedup,reference_ms_1," \
                       "reference_ms_n,reference_speedup,ratio,bound,within," BENCH_TAIL_HEADER "\n"

typedef struct Options {
    const char *scene, *csv;
    int samples, threads, repeat;
    bool scaling;
} Options;

/* What every loop traces, fetched once (untimed). */
typedef struct Inputs {
    const Scene *scene;
    const RtScene *casters;
    const ViewSamples *vs;
    const uint8_t *cls;
    int light_index;
    int count; /* light samples drawn per candidate sample: N, or 1 for delta lights */
} Inputs;

/* The Embree calls tried (see the top of the file). */
typedef enum Variant { V_1, V_4, V_8, V_16, V_1M_INCOHERENT, V_1M_COHERENT, NUM_VARIANTS } Variant;
static const char *const variant_names[NUM_VARIANTS] = {"occluded1",  "occluded4",  "occluded8",
                                                        "occluded16", "occluded1M_incoherent",
                                                        "occluded1M_coherent"};
static const unsigned variant_width[NUM_VARIANTS] = {1, 4, 8, 16, 0, 0}; /* 0: a stream */

/* What one pass of a loop saw: rays traced, and per view sample the rays
 * kept above its horizon and how many of them were unoccluded. */
typedef struct Trace {
    long long rays;
    int *kept, *lit;
} Trace;

/* Medians over the timed rounds. */
typedef struct Result {
    double variant_s[NUM_VARIANTS], ref_s;
    Variant fastest;  /* the lowest median: the limit */
    double ratio;     /* median of per-round fastest / reference times */
    long long rays;   /* per pass */
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
    return (ReferenceParams){MEASURE_VISIBILITY, o->samples, PATTERN, SEED, false};
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
    return true;
}

static bool trace_alloc(Trace *t, const Inputs *in)
{
    t->kept = calloc((size_t)in->vs->count, sizeof(int));
    t->lit = calloc((size_t)in->vs->count, sizeof(int));
    return t->kept && t->lit;
}

static void trace_free(Trace *t)
{
    free(t->kept);
    free(t->lit);
}

/* ---- the bare loops ----------------------------------------------------- */

/* The open segment from org toward the light sample (course Eq. 1.1), as
 * reference.c's aim_lane. */
static void aim(struct RTCRay *r, vec3 org, const LightSample *s, unsigned id)
{
    r->org_x = org.x; r->org_y = org.y; r->org_z = org.z;
    r->dir_x = s->dir_world.x; r->dir_y = s->dir_world.y; r->dir_z = s->dir_world.z;
    r->tnear = 0.0f;
    r->tfar = isinf(s->dist) ? INFINITY : s->dist * (1.0f - 1e-5f);
    r->time = 0.0f;
    r->mask = 0xFFFFFFFFu;
    r->id = id;
    r->flags = 0;
}

/* View sample s's rays into rays[0 .. n), n returned: the reference's light
 * samples above the geometric tangent plane, or the one ray toward the
 * light's highest point where none is (reference.c's fill_batch and
 * fill_highest). */
static int sample_rays(const Inputs *in, float extent, int s, struct RTCRay *rays)
{
    vec3 p = in->vs->p_world[s], ng = in->vs->n_geom_world[s];
    vec3 org = v3_madd(p, ng, rt_ray_offset(extent, p));
    uint32_t stream = sampling_stream(SEED, (uint32_t)s);
    const Light *l = &in->scene->lights[in->light_index];
    int n = 0;
    for (int i = 0; i < in->count; i++) {
        float u, v;
        sample_2d(PATTERN, stream, i, in->count, &u, &v);
        LightSample ls = light_sample(l, p, u, v);
        if (v3_dot(ng, ls.dir_world) > 0.0f) aim(&rays[n], org, &ls, (unsigned)n), n++;
    }
    if (n == 0) {
        LightSample ls = light_sample_highest(l, p, ng);
        aim(&rays[n++], org, &ls, 0);
    }
    return n;
}

/* A packet of width N (RTCRay4/8/16) as Embree lays it out: twelve arrays
 * of N 4-byte lanes, org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, time,
 * tfar, mask, id, flags (rtcore_ray.h; its RTCRayN accessors are C++ only). */
enum { L_ORG_X, L_ORG_Y, L_ORG_Z, L_TNEAR, L_DIR_X, L_DIR_Y, L_DIR_Z, L_TIME, L_TFAR, L_MASK, L_ID, L_FLAGS };
static float *lane_f(float *packet, unsigned N, int field, unsigned k) { return &packet[(unsigned)field * N + k]; }
static void set_lane_u(float *packet, unsigned N, int field, unsigned k, unsigned v)
{
    memcpy(lane_f(packet, N, field, k), &v, sizeof v); /* an integer lane: no aliasing through a cast */
}

/* Rays [0, n) (n <= N) into a packet of width N; lanes past n repeat ray 0
 * (finite, as Embree reads every lane) and are not valid. */
static void pack(float *r, unsigned N, const struct RTCRay *rays, int n, int *valid)
{
    for (unsigned k = 0; k < N; k++) {
        const struct RTCRay *x = &rays[k < (unsigned)n ? k : 0];
        valid[k] = k < (unsigned)n ? -1 : 0;
        *lane_f(r, N, L_ORG_X, k) = x->org_x; *lane_f(r, N, L_ORG_Y, k) = x->org_y; *lane_f(r, N, L_ORG_Z, k) = x->org_z;
        *lane_f(r, N, L_DIR_X, k) = x->dir_x; *lane_f(r, N, L_DIR_Y, k) = x->dir_y; *lane_f(r, N, L_DIR_Z, k) = x->dir_z;
        *lane_f(r, N, L_TNEAR, k) = x->tnear;
        *lane_f(r, N, L_TFAR, k) = x->tfar;
        *lane_f(r, N, L_TIME, k) = x->time;
        set_lane_u(r, N, L_MASK, k, x->mask);
        set_lane_u(r, N, L_ID, k, x->id);
        set_lane_u(r, N, L_FLAGS, k, x->flags);
    }
}

/* Unoccluded rays of a packet's valid lanes (Embree marks occluded rays with tfar = -inf). */
static int packet_lit(float *r, unsigned N, const int *valid)
{
    int lit = 0;
    for (unsigned k = 0; k < N; k++) lit += valid[k] && *lane_f(r, N, L_TFAR, k) != -INFINITY;
    return lit;
}

/* Consecutive packets of width N over rays [0, n). */
static int trace_packets(RTCScene rtc, struct RTCIntersectContext *ctx, unsigned N, const struct RTCRay *rays,
                         int n)
{
    _Alignas(64) float r[sizeof(struct RTCRay16) / sizeof(float)];
    _Alignas(64) int valid[16];
    int lit = 0;
    for (int first = 0; first < n; first += (int)N) {
        pack(r, N, rays + first, n - first < (int)N ? n - first : (int)N, valid);
        if (N == 4) rtcOccluded4(valid, rtc, ctx, (struct RTCRay4 *)r);
        else if (N == 8) rtcOccluded8(valid, rtc, ctx, (struct RTCRay8 *)r);
        else rtcOccluded16(valid, rtc, ctx, (struct RTCRay16 *)r);
        lit += packet_lit(r, N, valid);
    }
    return lit;
}

/* Unoccluded rays among rays[0, n), traced by variant v. */
static int trace_rays(Variant v, RTCScene rtc, struct RTCIntersectContext *ctx, struct RTCRay *rays, int n)
{
    int lit = 0;
    if (variant_width[v] == 1) {
        for (int i = 0; i < n; i++) rtcOccluded1(rtc, ctx, &rays[i]);
    } else if (variant_width[v] == 0) {
        rtcOccluded1M(rtc, ctx, rays, (unsigned)n, sizeof *rays);
    } else {
        return trace_packets(rtc, ctx, variant_width[v], rays, n);
    }
    for (int i = 0; i < n; i++) lit += rays[i].tfar != -INFINITY;
    return lit;
}

/* One pass of variant v over every lit candidate into *t. */
static bool trace_pass(const Inputs *in, Variant v, Trace *t, Error *err)
{
    RTCScene rtc = rt_scene_handle(in->casters);
    float extent = scene_extent(in->scene);
    const ViewSamples *vs = in->vs;
    size_t bytes = sizeof(struct RTCRay) * (size_t)(in->count + 1);
    bytes = (bytes + 63) / 64 * 64;
    long long rays = 0;
    int failed = 0;
#pragma omp parallel reduction(+ : rays, failed)
    {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx); /* flags INCOHERENT */
        if (v == V_1M_COHERENT) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        struct RTCRay *buf = aligned_alloc(64, bytes);
        failed += buf == NULL;
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < vs->height; y++)
            for (int s = y * vs->width; buf && s < (y + 1) * vs->width; s++) {
                if (in->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
                int n = sample_rays(in, extent, s, buf);
                t->kept[s] = n;
                t->lit[s] = trace_rays(v, rtc, &ctx, buf, n);
                rays += n;
            }
        free(buf);
    }
    t->rays = rays;
    return failed == 0 || error_set(err, "out of memory for %d rays per thread", in->count + 1);
}

/* ---- rounds and the agreement check ------------------------------------- */

/* The reference saw what the loop saw: the same rays, and per lit candidate
 * the visibility lit / kept (reference.c's ratio over the rays kept). */
static bool check_agreement(const Inputs *in, const Reference *ref, const Trace *t, Variant v, Error *err)
{
    if (ref->rays != t->rays)
        return error_set(err, "MISMATCH: the reference traced %lld rays, %s %lld", ref->rays, variant_names[v],
                         t->rays);
    if (ref->value.channels != 1) return true; /* RGB-weighted visibility: no ray count to recover */
    for (int s = 0; s < in->vs->count; s++) {
        if (in->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float want = (float)((double)t->lit[s] / t->kept[s]);
        if (ref->value.data[s] != want)
            return error_set(err, "MISMATCH at sample %d: reference visibility %.9g, %s %d of %d rays unoccluded", s,
                             ref->value.data[s], variant_names[v], t->lit[s], t->kept[s]);
    }
    return true;
}

/* Every variant and the reference, each pass timed, all checked. Round r
 * starts at the r-th of the NUM_VARIANTS + 1 passes (the reference last in
 * the list), so on a shared machine no pass always runs first or last. */
static bool run_round(const Inputs *in, const ReferenceParams *prm, int round, Trace *traces, double *variant_s,
                      double *ref_s, Error *err)
{
    Reference ref;
    bool have_ref = false, ok = true;
    WorkCounters w0 = {0}, w1 = {0}; /* around the reference: its rays as the work counters saw them */
    for (int i = 0; ok && i <= NUM_VARIANTS; i++) {
        int v = (round + i) % (NUM_VARIANTS + 1);
        bool is_ref = v == NUM_VARIANTS;
        if (is_ref) work_snapshot(&w0);
        double t0 = timer_now_s();
        if (is_ref)
            ok = have_ref = reference_compute(in->casters, in->scene, in->light_index, in->vs, in->cls, prm, &ref, err);
        else ok = trace_pass(in, (Variant)v, &traces[v], err);
        double dt = timer_now_s() - t0;
        if (is_ref) {
            work_snapshot(&w1);
            *ref_s = dt;
        } else {
            variant_s[v] = dt;
        }
    }
    WorkCounters counted = work_diff(&w1, &w0);
    if (ok && (long long)counted.rays != ref.rays)
        ok = error_set(err, "MISMATCH: the work counters saw %llu reference rays, the reference reports %lld",
                       (unsigned long long)counted.rays, ref.rays);
    for (int v = 0; ok && v < NUM_VARIANTS; v++) ok = check_agreement(in, &ref, &traces[v], (Variant)v, err);
    if (have_ref) reference_free(&ref);
    return ok;
}

/* Rounds' times: round i of variant v at t[v * repeat + i], the reference's
 * at t[NUM_VARIANTS * repeat + i]. */
static void summarise(const double *t, int repeat, Result *res)
{
    const double *ref = t + NUM_VARIANTS * repeat;
    double *ratio = malloc(sizeof(double) * (size_t)repeat), *col = malloc(sizeof(double) * (size_t)repeat);
    res->fastest = V_1;
    for (int v = 0; v < NUM_VARIANTS; v++) {
        memcpy(col, t + v * repeat, sizeof(double) * (size_t)repeat);
        res->variant_s[v] = timer_median(col, repeat);
        if (res->variant_s[v] < res->variant_s[res->fastest]) res->fastest = (Variant)v;
    }
    memcpy(col, ref, sizeof(double) * (size_t)repeat);
    res->ref_s = timer_median(col, repeat);
    for (int i = 0; i < repeat; i++) ratio[i] = t[res->fastest * repeat + i] / ref[i];
    res->ratio = timer_median(ratio, repeat);
    free(ratio);
    free(col);
}

static bool measure(const Inputs *in, const Options *o, Result *res, Error *err)
{
    ReferenceParams prm = ref_params(o);
    int R = o->repeat;
    double *t = malloc(sizeof(double) * (NUM_VARIANTS + 1) * (size_t)(R > 1 ? R : 1)), warm[NUM_VARIANTS], warm_ref;
    double round_s[NUM_VARIANTS];
    Trace traces[NUM_VARIANTS] = {{0}};
    bool ok = t != NULL;
    for (int v = 0; ok && v < NUM_VARIANTS; v++) ok = trace_alloc(&traces[v], in);
    if (!ok) error_set(err, "out of memory");
    ok = ok && run_round(in, &prm, NUM_VARIANTS, traces, warm, &warm_ref, err);
    for (int i = 0; ok && i < R; i++) {
        ok = run_round(in, &prm, i, traces, round_s, &t[NUM_VARIANTS * R + i], err);
        for (int v = 0; v < NUM_VARIANTS; v++) t[v * R + i] = round_s[v];
    }
    if (ok) {
        summarise(t, R, res);
        res->rays = traces[V_1].rays;
    }
    for (int v = 0; v < NUM_VARIANTS; v++) trace_free(&traces[v]);
    free(t);
    return ok;
}

/* ---- the thread curve ---------------------------------------------------- */

/* What the curve's two sides share: side 0 is the 16-wide loop, side 1 the
 * reference, checked against the bare pass just before it. */
typedef struct CurveRun {
    const Inputs *in;
    ReferenceParams prm;
    Trace bare;
} CurveRun;

static bool curve_side(void *ctx, int side, int threads, double *seconds, Error *err)
{
    CurveRun *cr = ctx;
    (void)threads;
    double t0 = timer_now_s();
    if (side == 0) {
        bool ok = trace_pass(cr->in, V_16, &cr->bare, err);
        *seconds = timer_now_s() - t0;
        return ok;
    }
    Reference ref;
    if (!reference_compute(cr->in->casters, cr->in->scene, cr->in->light_index, cr->in->vs, cr->in->cls, &cr->prm,
                           &ref, err))
        return false;
    *seconds = timer_now_s() - t0;
    bool ok = check_agreement(cr->in, &ref, &cr->bare, V_16, err);
    reference_free(&ref);
    return ok;
}

static bool scaling_rows(const Inputs *in, const Options *o, const BenchCurve *c, long long rays, Error *err)
{
    char name[160];
    bench_csv_field(name, sizeof name, in->scene->name);
    printf("%s: %lld rays per pass, %d samples; speed-ups over 1 thread (medians of %d rounds):\n", in->scene->name,
           rays, o->samples, c->rounds);
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
                 in->scene->num_triangles, o->samples, rays, b1, bk, bs, r1, rk, rs, ratio, SCALING_BOUND,
                 within ? "yes" : "no", tail);
        ok = bench_csv_append(o->csv, SCALING_HEADER, row, err);
    }
    return ok;
}

static bool scaling(const Inputs *in, const Options *o, Error *err)
{
    CurveRun cr = {in, ref_params(o), {0}};
    BenchCurve c;
    bool ok = trace_alloc(&cr.bare, in) || error_set(err, "out of memory");
    ok = ok && bench_curve_init(&c, o->threads, 2, o->repeat, err);
    if (ok) {
        ok = bench_curve_measure(&c, curve_side, &cr, err) && scaling_rows(in, o, &c, cr.bare.rays, err);
        bench_curve_free(&c);
    }
    trace_free(&cr.bare);
    return ok;
}

/* ---- the record --------------------------------------------------------- */

/* Add one row to the CSV (bench.h: earlier rows kept under the same header):
 * bare_rays_per_s is the fastest variant's, named in `fastest`. */
static bool append_csv(const char *path, const Inputs *in, const Options *o, const Result *r, Error *err)
{
    char row[2048], name[160], tail[512];
    bench_csv_field(name, sizeof name, in->scene->name);
    bench_tail(tail, sizeof tail, o->threads);
    int n = snprintf(row, sizeof row, "%s,%d,%d,%lld,%.0f,%.0f,%.4f,%s", name, in->scene->num_triangles, o->samples,
                     r->rays, r->rays / r->variant_s[r->fastest], r->rays / r->ref_s, r->ratio,
                     variant_names[r->fastest]);
    for (int v = 0; v < NUM_VARIANTS; v++) n += snprintf(row + n, sizeof row - (size_t)n, ",%.0f", r->rays / r->variant_s[v]);
    snprintf(row + n, sizeof row - (size_t)n, ",%s\n", tail);
    return bench_csv_append(path, CSV_HEADER, row, err);
}

static void print_summary(const Inputs *in, const Options *o, const Result *r)
{
    printf("%s: %d triangles, %lld rays per pass, %d samples, %d threads, medians of %d rounds\n", in->scene->name,
           in->scene->num_triangles, r->rays, o->samples, o->threads, o->repeat);
    for (int v = 0; v < NUM_VARIANTS; v++)
        printf("  %-22s %7.2f Mrays/s%s\n", variant_names[v], r->rays / r->variant_s[v] * 1e-6,
               v == (int)r->fastest ? "  (fastest: the limit)" : "");
    printf("  %-22s %7.2f Mrays/s\n", "reference", r->rays / r->ref_s * 1e-6);
    printf("reference / fastest (%s): %.3f (target >= 0.9; median of the rounds' ratios), %.3f (ratio of the "
           "medians)\n", variant_names[r->fastest], r->ratio, r->variant_s[r->fastest] / r->ref_s);
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
