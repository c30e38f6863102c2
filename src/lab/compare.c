/* compare.c -- render, reference and metrics in one call (see compare.h):
 * the one pipeline the CLI commands and the Lua bindings share. */
#include "lab/compare.h"
#include <string.h>
#include "core/hash.h"
#include "core/timer.h"

static bool compute_metrics(Lab *lab, double error_scale, CompareResult *out, Error *err)
{
    double t0 = timer_now_s();
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), out->light_index, err);
    const uint8_t *term = cls ? res_terminator(lab_resources(lab), lab_scene(lab), out->light_index, err) : NULL;
    const Image *v = &out->render.visibility;
    if (!term || !image_init(&out->signed_error, v->width, v->height, v->channels, err) ||
        !metrics_compute(v, out->ref, cls, term, &out->metrics, &out->signed_error, err))
        return false;
    out->metrics_s = timer_now_s() - t0;
    out->error_scale = error_scale > 0 ? error_scale : report_error_scale(out->metrics.region[REGION_ALL].max_abs);
    out->compared = true;
    return true;
}

static bool run_stages(Lab *lab, const CompareRequest *req, CompareResult *out, Error *err)
{
    if (req->tech) {
        RenderRequest rr = {req->tech, req->params, req->light_index, req->repeat};
        RenderTiming timing = {req->warmup, req->time_budget_s};
        if (!lab_render_timed(lab, &rr, &timing, &out->render, err)) return false;
    }
    if (req->reference) {
        RefRequest rq = {req->light_index, req->ref, req->cache_dir};
        out->ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &out->ref_info, err);
        if (!out->ref) return false;
    }
    return !(req->tech && req->reference) || compute_metrics(lab, req->error_scale, out, err);
}

bool lab_compare(Lab *lab, const CompareRequest *req, CompareResult *out, Error *err)
{
    memset(out, 0, sizeof *out);
    if (!req->tech && !req->reference) return error_set(err, "a comparison needs a technique, a reference or both");
    if (req->reference && !reference_params_check(&req->ref, err)) return false;
    if (req->tech && req->ref.measure != MEASURE_VISIBILITY)
        return error_set(err, "--measure irradiance is for the reference alone; techniques estimate visibility");
    out->tech = req->tech;
    out->light_index = req->light_index;
    if (req->tech) memcpy(out->params, req->params, sizeof(double) * (size_t)req->tech->num_params);
    rm_log_reset(lab_resources(lab));
    if (run_stages(lab, req, out, err)) return true;
    compare_result_free(out);
    return false;
}

void compare_result_free(CompareResult *r)
{
    render_result_free(&r->render);
    image_free(&r->signed_error);
    r->ref = NULL;
    r->compared = false;
}

RunReport compare_report(Lab *lab, const CompareResult *r, const char *command, int threads)
{
    return (RunReport){command, lab, r->light_index, r->tech, r->params, r->tech ? &r->render : NULL,
                       r->ref, &r->ref_info, r->compared ? &r->metrics : NULL,
                       r->compared ? &r->signed_error : NULL, r->error_scale, r->metrics_s, 0, threads};
}

uint64_t lab_config_key(const Lab *lab, const Technique *t, const double *params, int light_index)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, "shadowlab configuration 2"); /* 2: enums by name; parameters that do not act left out */
    hash_u64(&h, lab_scene(lab)->hash);
    hash_u64(&h, (uint64_t)light_index);
    hash_str(&h, t->name);
    for (int i = 0; i < t->num_params; i++) {
        if (!tech_param_acts(t, i, params)) continue; /* changes nothing: no row of its own */
        const ParamDesc *p = &t->params[i];
        hash_str(&h, p->name);
        /* An enum by its choice's name, not its index: reordering or inserting
         * a choice must not make a recorded row answer for another one. */
        if (p->type == PARAM_ENUM) hash_str(&h, p->choices[(int)params[i]]);
        else hash_f64(&h, params[i]);
    }
    return hash_final(&h);
}
