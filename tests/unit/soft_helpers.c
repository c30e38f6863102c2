/* soft_helpers.c -- labs, renders and comparisons for the soft-shadow map tests. */
#include "soft_helpers.h"
#include <stdio.h>
#include <string.h>
#include "fixtures.h"
#include "techniques/smap.h"

#define SOFT_MAX_OVERRIDES 16

Lab *soft_open(const char *name, const char *const *overrides)
{
    const char *all[SOFT_MAX_OVERRIDES] = {"camera.width=160", "camera.height=120"};
    int n = 2;
    for (int i = 0; overrides && overrides[i] && n < SOFT_MAX_OVERRIDES; i++) all[n++] = overrides[i];
    char path[256];
    snprintf(path, sizeof path, "scenes/%s", name);
    Error err;
    Lab *lab = lab_open(path, all, n, &err);
    if (!lab) printf("    %s: %s\n", path, err.msg);
    return lab;
}

Lab *soft_strip(const char *light, double strip_height)
{
    char text[2048];
    snprintf(text, sizeof text,
             "return {\n"
             "  camera = { position = {0, 6, 3}, target = {0, 0, 0}, fov = 50, width = 128, height = 96 },\n"
             "  lights = { %s },\n"
             "  objects = {\n"
             "    { name = 'ground', shape = 'plane', size = {8, 8} },\n"
             "    { name = 'strip', shape = 'plane', size = {1.5, 8}, translate = {0, %g, 0}, receiver = false },\n"
             "  },\n"
             "}\n",
             light, strip_height);
    return fixture_lab("strip.lua", text);
}

double soft_map_dx(Lab *lab, const char *tech, int map_size)
{
    Error err;
    const Technique *t = tech_find(tech, &err);
    double p[TECH_MAX_PARAMS];
    if (!t) return NAN;
    tech_params_default(t, p);
    p[SMAP_P_MAP_SIZE] = map_size;
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    return m ? (m->view.face[0].r - m->view.face[0].l) / m->res : NAN;
}

bool soft_render(Lab *lab, const char *tech, const char *const *params, RenderResult *out)
{
    Error err;
    const Technique *t = tech_find(tech, &err);
    double values[TECH_MAX_PARAMS];
    if (t) tech_params_default(t, values);
    for (int i = 0; t && params && params[i]; i++)
        if (!tech_param_parse(t, params[i], values, &err)) t = NULL;
    RenderRequest rq = {.tech = t, .params = values, .light_index = 0, .repeat = 1};
    if (t && lab_render(lab, &rq, out, &err)) return true;
    printf("    %s: %s\n", tech, err.msg);
    return false;
}

bool soft_render_event(Lab *lab, const char *tech, const char *const *params, const char *kind, bool *built,
                       size_t *bytes)
{
    RenderResult r;
    if (!soft_render(lab, tech, params, &r)) return false;
    bool found = false;
    for (int e = 0; e < r.num_tech_resources && !found; e++)
        if ((found = strcmp(r.tech_resources[e].kind, kind) == 0)) {
            *built = r.tech_resources[e].built;
            *bytes = r.tech_resources[e].bytes;
        }
    render_result_free(&r);
    if (!found) printf("    %s: no %s in the run's resources\n", tech, kind);
    return found;
}

bool soft_metrics(Lab *lab, const Image *v, int samples, Metrics *m)
{
    Error err;
    RefInfo info;
    RefRequest rq = {0, {MEASURE_VISIBILITY, samples, SAMPLING_STRATIFIED, 1, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
    const uint8_t *cls = ref ? res_classes(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    const uint8_t *term = cls ? res_terminator(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    if (term && metrics_compute(v, ref, cls, term, m, NULL, &err)) return true;
    printf("    metrics: %s\n", err.msg);
    return false;
}

Agreement soft_agreement(Lab *lab, const Image *a, const Image *b)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    Agreement g = {0, 0, 0.0};
    for (long s = 0; cls && s < (long)a->width * a->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        double d = fabs((double)a->data[s * a->channels] - b->data[s * b->channels]);
        g.candidates++;
        g.differ += d > 0.5;
        g.mean_abs += d;
    }
    if (g.candidates) g.mean_abs /= g.candidates;
    return g;
}
