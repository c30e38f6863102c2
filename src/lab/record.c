/* record.c -- the JSON record of a run and the printed metrics table: scene
 * and its hash, technique and every parameter value, per-stage timings,
 * resources built and reused, metrics, reference samples and noise, thread
 * count, machine and git commit, so a figure can be regenerated from records
 * alone. */
#include <math.h>
#include <string.h>
#include "core/fsutil.h"
#include "core/hash.h"
#include "core/json.h"
#include "core/machine.h"
#include "lab/report.h"
#include "version.h"

static void write_machine(JsonWriter *w, int threads)
{
    MachineInfo m;
    machine_info(&m);
    json_object_begin(w, "machine");
    if (m.named) {
        json_string(w, "host", m.host);
        json_string(w, "system", m.system);
        json_string(w, "release", m.release);
        json_string(w, "arch", m.arch);
    }
    json_string(w, "cpu", m.cpu);
    json_int(w, "threads", threads);
    json_string(w, "commit", SHADOWLAB_COMMIT);
    json_string(w, "dirty_files", SHADOWLAB_DIRTY); /* what differs from the commit at build time */
    json_object_end(w);
}

static void write_scene(JsonWriter *w, const RunReport *r)
{
    const Scene *sc = lab_scene(r->lab);
    char hex[17];
    json_object_begin(w, "scene");
    json_string(w, "name", sc->name);
    json_string(w, "path", sc->path);
    hash_hex(sc->hash, hex);
    json_string(w, "hash", hex);
    json_int(w, "triangles", sc->num_triangles);
    json_int(w, "width", sc->camera.width);
    json_int(w, "height", sc->camera.height);
    json_int(w, "supersample", sc->camera.supersample);
    json_int(w, "light", r->light_index + 1);
    json_string(w, "light_type", light_kind_name(sc->lights[r->light_index].kind));
    json_array_begin(w, "models");
    for (int i = 0; i < sc->num_objects; i++) json_string(w, NULL, sc->objects[i].source);
    json_array_end(w);
    const char *const *overrides;
    int num_overrides = lab_overrides(r->lab, &overrides);
    json_array_begin(w, "overrides");
    for (int i = 0; i < num_overrides; i++) json_string(w, NULL, overrides[i]);
    json_array_end(w);
    json_object_end(w);
}

static void write_technique(JsonWriter *w, const RunReport *r)
{
    json_object_begin(w, "technique");
    json_string(w, "name", r->tech->name);
    json_string(w, "family", r->tech->family);
    json_string(w, "source", r->tech->source);
    json_object_begin(w, "params");
    for (int i = 0; i < r->tech->num_params; i++) {
        const ParamDesc *p = &r->tech->params[i];
        if (p->type == PARAM_ENUM) json_string(w, p->name, p->choices[(int)r->params[i]]);
        else if (p->type == PARAM_BOOL) json_bool(w, p->name, r->params[i] != 0.0);
        else json_number(w, p->name, r->params[i]);
    }
    json_object_end(w);
    json_object_end(w);
}

static void write_reference(JsonWriter *w, const RunReport *r)
{
    const ReferenceParams *p = &r->ref->params;
    char hex[17];
    json_object_begin(w, "reference");
    json_string(w, "measure", measure_name(p->measure));
    json_int(w, "samples", p->samples);
    json_int(w, "rays_per_sample", r->ref->rays_per_sample);
    json_string(w, "pattern", sampling_pattern_name(p->pattern));
    json_string(w, "std_error", ref_error_estimator_name(r->ref->estimator));
    json_int(w, "batches", r->ref->batches);
    json_int(w, "seed", p->seed);
    json_string(w, "sample_set", p->shared_set ? "shared" : "per_view_sample");
    json_int(w, "rays", r->ref->rays);
    hash_hex(r->ref_info->key, hex);
    json_string(w, "key", hex);
    json_string(w, "origin", ref_origin_name(r->ref_info->origin));
    json_string(w, "cache_path", r->ref_info->cache_path);
    if (r->ref_info->cache_note[0]) json_string(w, "cache_note", r->ref_info->cache_note);
    json_number(w, "seconds", r->ref_info->seconds);
    json_number(w, "rays_per_second", r->ref_info->rays_per_second);
    json_object_end(w);
}

static void write_stats(JsonWriter *w, const char *key, const ErrorStats *s)
{
    json_object_begin(w, key);
    json_int(w, "count", s->count);
    json_int(w, "nonfinite", s->nonfinite);
    json_number(w, "mae", s->mae); /* null when the region is empty */
    json_number(w, "rmse", s->rmse);
    json_number(w, "max_abs", s->max_abs);
    json_number(w, "mean_signed", s->mean_signed);
    json_number(w, "leak_mean", s->leak_mean);
    json_number(w, "dark_mean", s->dark_mean);
    json_number(w, "misclassified", s->misclassified);
    json_number(w, "noise_rms", s->noise_rms);
    json_number(w, "noise_mean", s->noise_mean);
    json_number(w, "rmse_debiased", s->rmse_debiased);
    if (s->count > 0) json_bool(w, "resolved", s->resolved); /* absent, like the statistics, for an empty region */
    json_object_end(w);
}

static void write_metrics(JsonWriter *w, const RunReport *r)
{
    const Metrics *m = r->metrics;
    json_object_begin(w, "metrics");
    json_object_begin(w, "samples");
    for (int c = 0; c < SAMPLE_CLASS_COUNT; c++) json_int(w, sample_class_name((SampleClass)c), m->class_count[c]);
    json_object_end(w);
    for (int g = 0; g < REGION_COUNT; g++) write_stats(w, region_name((Region)g), &m->region[g]);
    json_int(w, "false_shadow", m->false_shadow);
    json_int(w, "false_lit", m->false_lit);
    json_int(w, "nonfinite", m->nonfinite);
    json_int(w, "out_of_range", m->out_of_range);
    json_number(w, "error_png_scale", r->error_scale);
    json_object_end(w);
}

#define AUX_BINS 16

/* The technique's auxiliary channels over the lit candidates: mean, range,
 * and how many samples have each integer part 0 .. AUX_BINS - 1 (clamped). */
static void write_aux(JsonWriter *w, const RunReport *r)
{
    Error err;
    const Image *aux = &r->render->aux;
    const uint8_t *cls = res_classes(lab_resources(r->lab), lab_scene(r->lab), r->light_index, &err);
    if (!cls) return; /* the render made them: always held */
    json_object_begin(w, "aux");
    for (int k = 0; k < aux->channels; k++) {
        long counts[AUX_BINS] = {0}, n = 0;
        double sum = 0, lo = INFINITY, hi = -INFINITY;
        for (long s = 0; s < (long)aux->width * aux->height; s++) {
            if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
            double v = aux->data[(size_t)s * aux->channels + k];
            counts[v < 1.0 ? 0 : v >= AUX_BINS - 1 ? AUX_BINS - 1 : (int)v]++;
            sum += v;
            lo = fmin(lo, v);
            hi = fmax(hi, v);
            n++;
        }
        json_object_begin(w, r->tech->aux[k]);
        json_int(w, "lit_candidates", n);
        json_number(w, "mean", n ? sum / n : 0.0);
        json_number(w, "min", n ? lo : 0.0);
        json_number(w, "max", n ? hi : 0.0);
        json_array_begin(w, "counts");
        for (int b = 0; b < AUX_BINS; b++) json_int(w, NULL, counts[b]);
        json_array_end(w);
        json_object_end(w);
    }
    json_object_end(w);
}

static void write_timings(JsonWriter *w, const RunReport *r)
{
    json_object_begin(w, "timings_s");
    json_number(w, "scene_load", lab_scene_load_seconds(r->lab));
    if (r->render) {
        json_number(w, "view_samples", r->render->view_s);
        json_number(w, "prepare", r->render->prepare_s);
        json_number(w, "evaluate_median", r->render->eval_median_s);
        json_number(w, "evaluate_min", r->render->eval_min_s);
        json_number(w, "evaluate_max", r->render->eval_max_s);
        json_int(w, "repeat", r->render->repeat);
        json_int(w, "warmup", r->render->warmup);
        /* frame = technique_build + prepare_own + evaluate_median (lab.h); the G-buffer's and
         * the set-up tables' builds are reported, left out */
        json_number(w, "technique_build", r->render->tech_build_s);
        json_number(w, "prepare_own", r->render->prepare_own_s);
        json_number(w, "gbuffer_left_out", r->render->gbuffer_s);
        json_number(w, "setup_left_out", r->render->setup_s);
        json_number(w, "frame", r->render->frame_s);
    }
    if (r->ref) json_number(w, "reference", r->ref_info->seconds);
    if (r->metrics) json_number(w, "metrics", r->metrics_s);
    json_number(w, "output", r->output_s);
    json_object_end(w);
}

/* The counters' fields, into an open object. */
static void write_counters(JsonWriter *w, const WorkCounters *c)
{
    json_int(w, "texel_fetches", (long long)c->texel_fetches);
    json_int(w, "texel_bytes", (long long)c->texel_bytes);
    json_int(w, "ray_calls", (long long)c->ray_calls);
    json_int(w, "rays", (long long)c->rays);
    json_int(w, "triangles", (long long)c->triangles);
    json_int(w, "fragments", (long long)c->fragments);
    json_int(w, "edges", (long long)c->edges);
    json_int(w, "influence", (long long)c->influence);
    json_int(w, "micropatches", (long long)c->micropatches);
}

/* Machine-independent work (core/counters.h): one evaluation's, the
 * frame's (as timings_s.frame: its resources' own builds, the prepare's
 * own, one evaluation) with the frame resources' bytes, and the
 * evaluation's per lit candidate (null without any). texel_bytes are the
 * bytes the reads load at the element size stored here (float32 depth: 4). */
static void write_work(JsonWriter *w, const RenderResult *r)
{
    json_object_begin(w, "work");
    json_int(w, "lit_candidates", r->lit_candidates);
    json_object_begin(w, "evaluate");
    write_counters(w, &r->eval_work);
    json_object_end(w);
    json_object_begin(w, "frame");
    write_counters(w, &r->frame_work);
    json_int(w, "bytes_built", (long long)r->frame_bytes);
    json_object_end(w);
    double n = r->lit_candidates > 0 ? (double)r->lit_candidates : NAN;
    json_object_begin(w, "per_sample");
    json_number(w, "texel_fetches", (double)r->eval_work.texel_fetches / n);
    json_number(w, "texel_bytes", (double)r->eval_work.texel_bytes / n);
    json_number(w, "rays", (double)r->eval_work.rays / n);
    json_number(w, "edges", (double)r->eval_work.edges / n);
    json_number(w, "micropatches", (double)r->eval_work.micropatches / n);
    json_object_end(w);
    json_object_end(w);
}

static void write_event(JsonWriter *w, const ResourceEvent *ev)
{
    char hex[17];
    json_object_begin(w, NULL);
    json_string(w, "kind", ev->kind);
    json_string(w, "desc", ev->desc);
    hash_hex(ev->key, hex);
    json_string(w, "key", hex);
    json_string(w, "action", ev->built ? "built" : "reused");
    json_string(w, "category", resource_category_name(ev->category));
    json_number(w, "build_s", ev->build_s);   /* medians of `builds` builds (resources.h scopes) */
    json_number(w, "own_build_s", ev->own_s);
    json_int(w, "builds", ev->builds);
    json_number(w, "cold_own_build_s", ev->cold_own_s);
    json_int(w, "bytes", (long long)ev->bytes);
    json_object_begin(w, "work"); /* of its first build, net of the builds nested in it */
    write_counters(w, &ev->work);
    json_object_end(w);
    json_object_end(w);
}

/* The run's resource log; what the technique's prepare depends on (its
 * frame time counts their own build times); cold when anything was built. */
static void write_resources(JsonWriter *w, const RunReport *r)
{
    const ResourceManager *rm = lab_resources(r->lab);
    bool any_built = false;
    json_array_begin(w, "resources");
    for (int i = 0; i < rm_log_count(rm); i++) {
        write_event(w, rm_log_event(rm, i));
        any_built = any_built || rm_log_event(rm, i)->built;
    }
    json_array_end(w);
    if (r->render) {
        json_array_begin(w, "technique_resources");
        for (int i = 0; i < r->render->num_tech_resources; i++) write_event(w, &r->render->tech_resources[i]);
        json_array_end(w);
    }
    json_string(w, "resource_cache", any_built ? "cold" : "warm");
}

bool report_write_record(const RunReport *r, const char *path, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    report_write_record_fp(r, af.fp);
    return atomic_commit(&af, err);
}

void report_write_record_fp(const RunReport *r, FILE *fp)
{
    JsonWriter w;
    json_init(&w, fp);
    json_object_begin(&w, NULL);
    json_string(&w, "shadowlab_record", "1");
    json_string(&w, "command", r->command);
    write_scene(&w, r);
    if (r->tech) write_technique(&w, r);
    if (r->ref) write_reference(&w, r);
    if (r->metrics) write_metrics(&w, r);
    if (r->render && r->render->aux.data) write_aux(&w, r);
    write_timings(&w, r);
    if (r->render) write_work(&w, r->render);
    write_resources(&w, r);
    write_machine(&w, r->threads);
    json_object_end(&w);
    json_finish(&w);
}

/* ---- the table for people ---------------------------------------------- */

void report_print_header(const Lab *lab, const Technique *tech, int light_index, FILE *fp)
{
    const Scene *sc = lab_scene(lab);
    fprintf(fp, "%s on %s (light %d: %s, %d triangles)\n", tech ? tech->name : "reference", sc->name,
            light_index + 1, light_kind_name(sc->lights[light_index].kind), sc->num_triangles);
}

void report_print(const RunReport *r, FILE *fp)
{
    report_print_header(r->lab, r->tech, r->light_index, fp);
    report_print_body(r, fp);
}

/* "reference: visibility, 1024 r2 samples in 16 randomisations, std error
 * their spread, ..." : what was traced and how its noise was estimated. */
static void print_reference(const RunReport *r, FILE *fp)
{
    const Reference *ref = r->ref;
    fprintf(fp, "reference: %s, ", measure_name(ref->params.measure));
    if (ref->estimator == REF_ERROR_EXACT) fprintf(fp, "one ray per sample (delta light: exact, std error 0)");
    else if (ref->estimator == REF_ERROR_RQMC)
        fprintf(fp, "%d %s samples in %d randomisations (std error: their spread)", ref->params.samples,
                sampling_pattern_name(ref->params.pattern), ref->batches);
    else
        fprintf(fp, "%d %s samples (std error: independent samples')", ref->params.samples,
                sampling_pattern_name(ref->params.pattern));
    if (ref->params.shared_set) fprintf(fp, ", one set shared by every view sample");
    fprintf(fp, ", %.3g s (%s), %.3g Mrays/s\n", r->ref_info->seconds, ref_origin_name(r->ref_info->origin),
            r->ref_info->rays_per_second * 1e-6);
}

/* A statistic, or "-" for an empty region's NaN. */
static void print_cell(FILE *fp, const char *fmt, int width, double v)
{
    if (isnan(v)) fprintf(fp, " %*s", width, "-");
    else fprintf(fp, fmt, v);
}

/* One row per region: errors, then the reference's noise over the same samples and the RMSE net of it. */
static void print_metrics(const Metrics *m, FILE *fp)
{
    fprintf(fp, "%-9s %9s %9s %9s %9s %9s %9s %9s %7s %9s %9s %s\n", "region", "samples", "MAE", "RMSE", "max|e|",
            "signed", "leak", "dark", ">0.5", "noise", "RMSE-net", "non-finite");
    for (int g = 0; g < REGION_COUNT; g++) {
        const ErrorStats *s = &m->region[g];
        fprintf(fp, "%-9s %9ld", region_name((Region)g), s->count);
        print_cell(fp, " %9.5f", 9, s->mae);
        print_cell(fp, " %9.5f", 9, s->rmse);
        print_cell(fp, " %9.5f", 9, s->max_abs);
        print_cell(fp, " %+9.5f", 9, s->mean_signed);
        print_cell(fp, " %9.5f", 9, s->leak_mean);
        print_cell(fp, " %9.5f", 9, s->dark_mean);
        print_cell(fp, " %7.4f", 7, s->misclassified);
        print_cell(fp, " %9.5f", 9, s->noise_rms);
        print_cell(fp, " %9.5f", 9, s->rmse_debiased);
        fprintf(fp, " %ld%s\n", s->nonfinite, s->count > 0 && !s->resolved ? "  (below 2x the noise: not resolved)" : "");
    }
    fprintf(fp, "false shadow (acne) %ld, false lit (leaks) %ld, non-finite %ld (left out), outside [0,1] %ld\n",
            m->false_shadow, m->false_lit, m->nonfinite, m->out_of_range);
}

void report_print_body(const RunReport *r, FILE *fp)
{
    if (r->ref) print_reference(r, fp);
    if (r->render)
        fprintf(fp, "technique: prepare %.3g s, evaluate %.3g s (median of %d, min %.3g s)\n", r->render->prepare_s,
                r->render->eval_median_s, r->render->repeat, r->render->eval_min_s);
    if (r->metrics) {
        print_metrics(r->metrics, fp);
        fprintf(fp, "error PNG scale: blue -%g (too dark) .. white 0 .. red +%g (leaking), black non-finite\n",
                r->error_scale, r->error_scale);
    }
    const ResourceManager *rm = lab_resources(r->lab);
    for (int i = 0; i < rm_log_count(rm); i++) {
        const ResourceEvent *ev = rm_log_event(rm, i);
        fprintf(fp, "resource %-6s %-14s %-40s %8.3f s %10.1f KiB\n", ev->built ? "built" : "reused", ev->kind,
                ev->desc, ev->build_s, (double)ev->bytes / 1024.0);
    }
}
