/* stability_exec.c -- what the stability suite's processes do: a case's
 * shared preparation (its scene, BVH, view samples, classes and reference,
 * on one thread), and one run forked from it: render the technique (with a
 * parameter probe's value), count non-finite and out-of-range outputs over
 * the lit candidates, measure the error against the cheap reference and
 * check the case's limit; or check that bad input is refused with a message
 * naming what is wrong. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lab/stability_cases.h"
#include "rt/rt.h"

static bool fail(StabResult *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static bool fail(StabResult *r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->detail, sizeof r->detail, fmt, ap);
    va_end(ap);
    r->status = STAB_FAIL;
    return false;
}

static void note(StabResult *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void note(StabResult *r, const char *fmt, ...)
{
    size_t used = strlen(r->detail);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->detail + used, sizeof r->detail - used, fmt, ap);
    va_end(ap);
}

/* ---- parameter values --------------------------------------------------- */

const char *stab_probe_suffix(ParamProbe probe)
{
    static const char *const names[PROBE_COUNT] = {"", "min", "min_plus_1", "max", "at_42", "at_44.36", "at_88.72",
                                                   "below_min", "above_max", "nonfinite", "all"};
    return names[probe];
}

/* Float32's exponential limits (course §4.2.4, catalogue [OWN]; issue 7):
 * exp(c z) overflows above c = ln(FLT_MAX) = 88.72 (ESM), the second moment
 * exp(2 c z) above 44.36 (EVSM), whose usual limit 42 leaves a margin for
 * the filter's sums. Every float parameter whose range holds one is
 * rendered there: a technique must stay finite at any value it accepts. */
static double fp32_limit(ParamProbe probe)
{
    double ln_max = log((double)FLT_MAX);
    return probe == PROBE_FP32_EVSM ? 42.0 : probe == PROBE_FP32_EXP2 ? 0.5 * ln_max : ln_max;
}

static bool is_fp32_probe(ParamProbe probe) { return probe >= PROBE_FP32_EVSM && probe <= PROBE_FP32_EXP; }

bool stab_probe_applies(const ParamDesc *p, ParamProbe probe)
{
    if (probe == PROBE_MIN_PLUS_ONE) return p->type == PARAM_INT && p->max >= p->min + 2;
    if (is_fp32_probe(probe)) return p->type == PARAM_FLOAT && p->min < fp32_limit(probe) && fp32_limit(probe) < p->max;
    return true;
}

double stab_probe_value(const ParamDesc *p, ParamProbe probe)
{
    bool integral = p->type != PARAM_FLOAT;
    double below = integral ? 1.0 : fmax(fabs(p->min) * 1e-6, 1e-9);
    double above = integral ? 1.0 : fmax(fabs(p->max) * 1e-6, 1e-9);
    switch (probe) {
    case PROBE_AT_MIN: return p->min;
    case PROBE_MIN_PLUS_ONE: return p->min + 1.0;
    case PROBE_AT_MAX: return p->max;
    case PROBE_FP32_EVSM:
    case PROBE_FP32_EXP2:
    case PROBE_FP32_EXP: return fp32_limit(probe);
    case PROBE_BELOW_MIN: return p->min - below;
    case PROBE_ABOVE_MAX: return p->max + above;
    default: return NAN;
    }
}

/* A refusal must name the parameter and its valid range. */
static bool refusal_names_range(const Technique *t, const ParamDesc *p, const char *what, bool accepted,
                                const Error *e, StabResult *r)
{
    char range[256];
    tech_param_range(p, range, sizeof range);
    if (accepted) return fail(r, "%s: %s was accepted", t->name, what);
    if (!strstr(e->msg, p->name) || !strstr(e->msg, range))
        return fail(r, "refusal of %s does not name '%s' and %s: %s", what, p->name, range, e->msg);
    return true;
}

static bool check_refused_value(const Technique *t, int i, double v, StabResult *r)
{
    double vals[TECH_MAX_PARAMS];
    tech_params_default(t, vals);
    Error e = {{0}};
    char what[96];
    snprintf(what, sizeof what, "%s = %.9g", t->params[i].name, v);
    return refusal_names_range(t, &t->params[i], what, tech_param_set(t, t->params[i].name, v, vals, &e), &e, r);
}

static bool check_refused_text(const Technique *t, int i, const char *text, StabResult *r)
{
    double vals[TECH_MAX_PARAMS];
    tech_params_default(t, vals);
    char assign[160];
    snprintf(assign, sizeof assign, "%s=%s", t->params[i].name, text);
    Error e = {{0}};
    return refusal_names_range(t, &t->params[i], assign, tech_param_parse(t, assign, vals, &e), &e, r);
}

/* A raw non-finite value handed to lab_render (as the Lua layer or any
 * library caller could) is refused before the technique's prepare runs. */
static bool check_render_refuses_nan(Lab *lab, const Technique *t, int i, StabResult *r)
{
    double vals[TECH_MAX_PARAMS];
    tech_params_default(t, vals);
    vals[i] = NAN;
    RenderRequest req = {t, vals, 0, 1};
    RenderResult out;
    Error e = {{0}};
    bool ok = lab_render(lab, &req, &out, &e);
    if (ok) render_result_free(&out);
    if (ok) return fail(r, "lab_render accepted %s = NaN", t->params[i].name);
    if (!strstr(e.msg, t->params[i].name)) return fail(r, "lab_render's refusal of NaN does not name %s: %s", t->params[i].name, e.msg);
    return true;
}

static void run_param_refusal(const StabJob *j, Lab *lab, StabResult *r)
{
    const Technique *t = j->tech;
    int i = j->param;
    bool ok;
    if (j->probe == PROBE_NONFINITE) {
        ok = check_refused_value(t, i, NAN, r) && check_refused_value(t, i, INFINITY, r) &&
             check_refused_value(t, i, -INFINITY, r) && check_refused_text(t, i, "nan", r) &&
             check_refused_text(t, i, "inf", r) && check_render_refuses_nan(lab, t, i, r);
    } else {
        ok = check_refused_value(t, i, stab_probe_value(&t->params[i], j->probe), r);
    }
    if (ok) r->status = STAB_PASS;
}

/* ---- rendering -------------------------------------------------------------- */

/* Quick runs cap the technique's integer texel counts (map resolutions) at
 * STAB_QUICK_TEXELS, except the parameter being probed (cases whose limit is
 * stated at the full sizes run with the full settings, st.quick false). */
static void quick_caps(const StabJob *j, double *vals)
{
    bool cap = j->st.quick;
    for (int i = 0; cap && i < j->tech->num_params; i++) {
        const ParamDesc *p = &j->tech->params[i];
        if (i != j->param && p->type == PARAM_INT && !strcmp(p->unit, "texels") && vals[i] > STAB_QUICK_TEXELS &&
            p->min <= STAB_QUICK_TEXELS)
            vals[i] = STAB_QUICK_TEXELS;
    }
}

/* Index of the technique's "precision" choice "f32", or -1 (value in *f32). */
static int precision_param(const Technique *t, double *f32)
{
    int i = tech_param_index(t, "precision");
    if (i < 0 || t->params[i].type != PARAM_ENUM) return -1;
    for (int c = 0; t->params[i].choices[c]; c++)
        if (!strcmp(t->params[i].choices[c], "f32")) {
            *f32 = c;
            return i;
        }
    return -1;
}

/* The float32 probes are about float32: where the technique has a precision
 * parameter (default f64 for moment maps) they also set it to f32, so the
 * limit is tested in the arithmetic it is a limit of. */
static bool probe_params(const StabJob *j, double *vals, StabResult *r)
{
    tech_params_default(j->tech, vals);
    quick_caps(j, vals);
    if (j->probe == PROBE_NONE) return true;
    const ParamDesc *p = &j->tech->params[j->param];
    double v = stab_probe_value(p, j->probe);
    Error e;
    if (!tech_param_set(j->tech, p->name, v, vals, &e)) return fail(r, "value at the bound was refused: %s", e.msg);
    note(r, "%s = %.9g", p->name, v);
    double f32;
    int q = is_fp32_probe(j->probe) ? precision_param(j->tech, &f32) : -1;
    if (q >= 0) {
        vals[q] = f32;
        note(r, ", %s = f32", j->tech->params[q].name);
    }
    note(r, ". ");
    return true;
}

/* Non-finite and out-of-range outputs over the lit candidates. */
static void count_outputs(const Image *v, const uint8_t *cls, StabResult *r)
{
    long count = (long)v->width * v->height;
    for (long s = 0; s < count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        r->samples++;
        for (int c = 0; c < v->channels; c++) {
            float x = v->data[s * v->channels + c];
            if (!isfinite(x)) r->nonfinite++;
            else if (x < 0.0f || x > 1.0f) r->out_of_range++;
        }
    }
}

/* The cheap reference of a case (NULL: parameter probes); heavy cases take
 * 16 light samples, and none at all in quick runs (their output is checked,
 * not its error). */
static bool measured(const StabCase *c, const StabSettings *st) { return !(st->quick && c && c->heavy); }

static RefRequest reference_request(const StabCase *c, const StabSettings *st)
{
    return (RefRequest){0, {MEASURE_VISIBILITY, c && c->heavy ? 16 : st->ref_samples, SAMPLING_R2, 1, false}, NULL};
}

/* metrics.h's lit region: reference V >= 0.99. */
#define LIT_BOUND 0.99

static double pixel_mean(const Image *im, long s)
{
    double v = 0;
    for (int c = 0; c < im->channels; c++) v += im->data[s * im->channels + c];
    return v / im->channels;
}

/* The classes of the hard shadow's band (StabMeasure): a lit candidate
 * stays one where the reference or `hard` is below LIT_BOUND within
 * STAB_BAND_PX pixels (Chebyshev distance on the view grid); every other
 * sample is made background, which metrics_compute leaves out. */
static void band_classes(const Image *ref, const Image *hard, const uint8_t *cls, uint8_t *shadowed, uint8_t *band)
{
    int w = ref->width, h = ref->height;
    for (long s = 0; s < (long)w * h; s++)
        shadowed[s] = cls[s] == SAMPLE_LIT_CANDIDATE && (pixel_mean(ref, s) < LIT_BOUND || pixel_mean(hard, s) < LIT_BOUND);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            bool near = false;
            for (int dy = -STAB_BAND_PX; !near && dy <= STAB_BAND_PX; dy++)
                for (int dx = -STAB_BAND_PX; !near && dx <= STAB_BAND_PX; dx++) {
                    int u = x + dx, t = y + dy;
                    near = u >= 0 && u < w && t >= 0 && t < h && shadowed[(long)t * w + u];
                }
            long s = (long)y * w + x;
            band[s] = near && cls[s] == SAMPLE_LIT_CANDIDATE ? SAMPLE_LIT_CANDIDATE : SAMPLE_BACKGROUND;
        }
}

/* `hard` with its defaults on the run's light: the point-light shadow the
 * band is drawn around. */
static bool render_hard(Lab *lab, RenderResult *out, Error *e)
{
    const Technique *hard = tech_find("hard", e);
    double vals[TECH_MAX_PARAMS];
    if (!hard) return false;
    tech_params_default(hard, vals);
    RenderRequest req = {hard, vals, 0, 1};
    return lab_render(lab, &req, out, e);
}

/* The metrics over the hard shadow's band of the run's view. */
static bool band_metrics(Lab *lab, const Image *v, const Reference *ref, const uint8_t *cls, const uint8_t *term,
                         Metrics *band, StabResult *r)
{
    RenderResult hard;
    Error e;
    if (!render_hard(lab, &hard, &e)) return fail(r, "hard shadow for the band failed: %s", e.msg);
    size_t count = (size_t)v->width * (size_t)v->height;
    uint8_t *shadowed = malloc(count), *band_cls = malloc(count);
    bool ok = shadowed && band_cls;
    if (!ok) {
        fail(r, "out of memory for the shadow band");
    } else {
        band_classes(&ref->value, &hard.visibility, cls, shadowed, band_cls);
        ok = metrics_compute(v, ref, band_cls, term, band, NULL, &e) || fail(r, "band metrics failed: %s", e.msg);
    }
    free(shadowed);
    free(band_cls);
    render_result_free(&hard);
    return ok;
}

/* Error against the reference; the case's limit if it has one. *known:
 * the limit was missed as a known limitation lists it (the row's note says
 * why and by how much). */
static bool measure(const StabJob *j, Lab *lab, const Image *v, const uint8_t *cls, StabResult *r, bool *known)
{
    RefRequest rq = reference_request(j->c, &j->st);
    RefInfo info;
    Error e;
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &e);
    if (!ref) return fail(r, "reference failed: %s", e.msg);
    const uint8_t *term = res_terminator(lab_resources(lab), lab_scene(lab), 0, &e);
    if (!term) return fail(r, "sample classes failed: %s", e.msg);
    StabMeasure m;
    if (!metrics_compute(v, ref, cls, term, &m.all, NULL, &e)) return fail(r, "metrics failed: %s", e.msg);
    r->ref_samples = light_is_delta(&lab_scene(lab)->lights[0]) ? 1 : rq.params.samples;
    r->noise_rms = m.all.region[REGION_ALL].noise_rms;
    if (m.all.region[REGION_ALL].count > 0) {
        r->mae = m.all.region[REGION_ALL].mae;
        r->rmse = m.all.region[REGION_ALL].rmse;
        r->max_abs = m.all.region[REGION_ALL].max_abs;
    }
    char why[400] = "", missed_names[160], listed_names[160];
    if (!j->c || !j->c->limit) return true;
    if (!band_metrics(lab, v, ref, cls, term, &m.band, r)) return false;
    unsigned missed = j->c->limit(&m, why, sizeof why);
    const KnownLimit *k = stab_known_limit(j->c, j->tech, j->kind);
    if (!k && !missed && why[0]) note(r, "limit met: %s. ", why);
    if (!k) return !missed || fail(r, "%s", why);
    stab_quantity_names(missed, missed_names, sizeof missed_names);
    stab_quantity_names(k->misses, listed_names, sizeof listed_names);
    if (!missed) return fail(r, "meets the limit it is listed as missing (%s): remove its known-limit entry", k->reason);
    if (missed != k->misses)
        return fail(r, "misses %s where its known-limit entry lists %s: %s", missed_names, listed_names, why);
    note(r, "known limitation: %s. Measured (%s missed): %s. ", k->reason, missed_names, why);
    *known = true;
    return true;
}

/* The first of the case's refusal words a message lacks, or NULL. */
static const char *refusal_lacks(const StabCase *c, const char *msg)
{
    for (int w = 0; c && w < 3 && c->refusal[w]; w++)
        if (!strstr(msg, c->refusal[w])) return c->refusal[w];
    return NULL;
}

static void run_render(const StabJob *j, Lab *lab, StabResult *r)
{
    double vals[TECH_MAX_PARAMS];
    if (!probe_params(j, vals, r)) return;
    RenderRequest req = {j->tech, vals, 0, 1};
    RenderResult out;
    Error e = {{0}};
    bool may_refuse = (j->c && j->c->may_refuse) || j->probe == PROBE_AT_MAX;
    if (!lab_render(lab, &req, &out, &e)) {
        const char *lacks = j->probe == PROBE_AT_MAX ? NULL : refusal_lacks(j->c, e.msg);
        if (may_refuse && e.msg[0] && lacks) {
            fail(r, "refusal lacks '%s': %s", lacks, e.msg);
        } else if (may_refuse && e.msg[0]) {
            r->status = STAB_PASS;
            note(r, "refused (allowed here): %s", e.msg);
        } else {
            fail(r, "render failed: %s", e.msg);
        }
        return;
    }
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &e);
    if (!cls) {
        render_result_free(&out);
        fail(r, "classes: %s", e.msg);
        return;
    }
    count_outputs(&out.visibility, cls, r);
    bool known = false;
    bool ok = !measured(j->c, &j->st) || measure(j, lab, &out.visibility, cls, r, &known);
    render_result_free(&out);
    if (!ok) return;
    if (r->nonfinite || r->out_of_range)
        fail(r, "%ld non-finite and %ld out-of-range values in [0, 1] over %ld lit samples", r->nonfinite,
             r->out_of_range, r->samples);
    else r->status = known ? STAB_KNOWN : STAB_PASS;
    if (r->status == STAB_PASS && r->samples == 0) note(r, "no lit candidates. ");
}

/* ---- bad scenes ---------------------------------------------------------------- */

static void run_scene_refusal(const StabJob *j, const char *path, StabResult *r)
{
    Error e = {{0}};
    Lab *lab = lab_open(path, NULL, 0, &e);
    if (lab) {
        lab_close(lab);
        fail(r, "the scene was accepted");
        return;
    }
    const char *lacks = refusal_lacks(j->c, e.msg);
    if (lacks) {
        fail(r, "refusal lacks '%s': %s", lacks, e.msg);
        return;
    }
    r->status = STAB_PASS;
    snprintf(r->detail, sizeof r->detail, "refused: %s", e.msg);
}

/* ---- a parameter's probes in one run (quick) ----------------------------------- */

static void run_probe(const StabJob *j, Lab *lab, StabResult *r)
{
    if (j->probe >= PROBE_BELOW_MIN) run_param_refusal(j, lab, r);
    else run_render(j, lab, r);
}

/* Counts add up, errors take the worst probe; the first failure ends the
 * row, named by its probe. */
static void run_all_probes(const StabJob *j, Lab *lab, StabResult *r)
{
    const ParamDesc *p = &j->tech->params[j->param];
    r->status = STAB_PASS;
    for (int probe = PROBE_AT_MIN; probe < PROBE_ALL; probe++) {
        if (!stab_probe_applies(p, (ParamProbe)probe)) continue;
        StabJob one = *j;
        one.probe = (ParamProbe)probe;
        StabResult part = {.status = STAB_FAIL, .mae = NAN, .rmse = NAN, .max_abs = NAN, .noise_rms = NAN};
        run_probe(&one, lab, &part);
        r->samples += part.samples;
        r->nonfinite += part.nonfinite;
        r->out_of_range += part.out_of_range;
        r->mae = fmax(r->mae, part.mae);
        r->rmse = fmax(r->rmse, part.rmse);
        r->max_abs = fmax(r->max_abs, part.max_abs);
        r->noise_rms = fmax(r->noise_rms, part.noise_rms);
        if (part.ref_samples > r->ref_samples) r->ref_samples = part.ref_samples;
        if (part.status != STAB_PASS) {
            fail(r, "%s: %s", stab_probe_suffix((ParamProbe)probe), part.detail);
            return;
        }
        note(r, "%s", part.detail);
    }
}

/* ---- the case's shared preparation and the runs ---------------------------------- */

bool stab_prepare(const StabCase *c, const StabSettings *st, const char *scene_path, StabShared *sh, StabResult *r)
{
    sh->lab = NULL;
    sh->scene_path = scene_path;
    if (c && c->plan == PLAN_NONE) return true;
    omp_set_num_threads(1); /* no thread may exist when the runs are forked */
    rt_set_threads(1);
    Error e;
    sh->lab = lab_open(scene_path, NULL, 0, &e);
    if (!sh->lab) return fail(r, "the case's scene was refused: %s", e.msg);
    ResourceManager *rm = lab_resources(sh->lab);
    const Scene *sc = lab_scene(sh->lab);
    if (!res_view_samples(rm, sc, &e) || !res_classes(rm, sc, 0, &e))
        return fail(r, "view samples failed: %s", e.msg);
    RefRequest rq = reference_request(c, st);
    RefInfo info;
    if (measured(c, st) && !res_reference(rm, sc, &rq, &info, &e)) return fail(r, "reference failed: %s", e.msg);
    return true;
}

void stab_shared_release(StabShared *sh)
{
    lab_close(sh->lab);
    sh->lab = NULL;
}

/* Runs with the case's Embree device, made on one thread by the preparation;
 * OpenMP starts this run's own threads. */
void stab_job_execute(const StabJob *j, const StabShared *sh, StabResult *r)
{
    if (j->threads > 0) omp_set_num_threads(j->threads);
    if (!sh->lab) {
        run_scene_refusal(j, sh->scene_path, r);
        return;
    }
    if (j->probe == PROBE_ALL) run_all_probes(j, sh->lab, r);
    else run_probe(j, sh->lab, r);
}
