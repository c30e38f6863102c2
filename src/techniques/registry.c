/* registry.c -- the technique table and shared parameter handling. Adding a
 * technique is one file in this folder and one line in `registry` below. */
#include "techniques/registry.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

extern const Technique tech_hard;
extern const Technique tech_sm;
extern const Technique tech_pcf;
extern const Technique tech_vsm;
extern const Technique tech_lvsm;
extern const Technique tech_evsm;
extern const Technique tech_msm;
extern const Technique tech_esm;
extern const Technique tech_csm;
extern const Technique tech_single_sample_rt;
extern const Technique tech_accumulation;
extern const Technique tech_brabec;
extern const Technique tech_pcss;
extern const Technique tech_pcss_prefiltered;
extern const Technique tech_cssm;
extern const Technique tech_evssm;
extern const Technique tech_dpcf;
extern const Technique tech_adaptive_area;
extern const Technique tech_shadow_width;
extern const Technique tech_aliasing;

static const Technique *const registry[] = {
    &tech_hard,
    &tech_sm,
    &tech_pcf,
    &tech_vsm,
    &tech_lvsm,
    &tech_evsm,
    &tech_msm,
    &tech_esm,
    &tech_csm,
    &tech_single_sample_rt,
    &tech_accumulation,
    &tech_brabec,
    &tech_pcss,
    &tech_pcss_prefiltered,
    &tech_cssm,
    &tech_evssm,
    &tech_dpcf,
    &tech_adaptive_area,
    &tech_shadow_width,
    &tech_aliasing,
};

int tech_count(void) { return (int)(sizeof registry / sizeof registry[0]); }
const Technique *tech_at(int i) { return registry[i]; }

const Technique *tech_find(const char *name, Error *err)
{
    char known[512] = "";
    size_t used = 0;
    for (int i = 0; i < tech_count(); i++) {
        if (strcmp(registry[i]->name, name) == 0) return registry[i];
        used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", i ? ", " : "", registry[i]->name);
        if (used >= sizeof known) used = sizeof known - 1;
    }
    error_set(err, "unknown technique '%s' (known: %s; see shadowlab list)", name, known);
    return NULL;
}

const char *param_type_name(ParamType t)
{
    static const char *const names[] = {"int", "float", "enum", "bool"};
    return names[t];
}

void tech_lights_text(const Technique *t, char *out, size_t n)
{
    size_t used = 0;
    out[0] = '\0';
    for (int k = LIGHT_POINT; k <= LIGHT_TEXTURED_RECT && used < n; k++)
        if (t->lights & LIGHT_BIT(k))
            used += (size_t)snprintf(out + used, n - used, "%s%s", used ? ", " : "", light_kind_name((LightKind)k));
}

bool tech_acquires(const Technique *t, const char *kind)
{
    for (const char *const *r = t->resources; r && *r; r++)
        if (strcmp(*r, kind) == 0) return true;
    return false;
}

bool tech_check_light(const Technique *t, const Light *light, int light_number, Error *err)
{
    if (t->lights & LIGHT_BIT(light->kind)) return true;
    char kinds[160];
    tech_lights_text(t, kinds, sizeof kinds);
    return error_set(err, "%s handles %s lights; light %d is a %s light", t->name, kinds, light_number,
                     light_kind_name(light->kind));
}

void tech_params_default(const Technique *t, double *values)
{
    for (int i = 0; i < t->num_params; i++) values[i] = t->params[i].def;
}

int tech_param_index(const Technique *t, const char *name)
{
    for (int i = 0; i < t->num_params; i++)
        if (strcmp(t->params[i].name, name) == 0) return i;
    return -1;
}

void tech_param_range(const ParamDesc *p, char *out, size_t n)
{
    switch (p->type) {
    case PARAM_BOOL: snprintf(out, n, "true or false"); break;
    case PARAM_INT: snprintf(out, n, "[%.0f, %.0f]", p->min, p->max); break;
    case PARAM_FLOAT: snprintf(out, n, "[%g, %g]", p->min, p->max); break;
    case PARAM_ENUM: {
        size_t used = (size_t)snprintf(out, n, "one of: ");
        for (int i = (int)p->min; i <= (int)p->max && p->choices[i] && used < n; i++) /* a technique may accept a prefix */
            used += (size_t)snprintf(out + used, n - used, "%s%s", i > (int)p->min ? ", " : "", p->choices[i]);
        break;
    }
    }
}

void tech_param_format(const ParamDesc *p, double v, char *out, size_t n)
{
    switch (p->type) {
    case PARAM_BOOL: snprintf(out, n, "%s", v != 0.0 ? "true" : "false"); break;
    case PARAM_INT: snprintf(out, n, "%.0f", v); break;
    case PARAM_FLOAT: snprintf(out, n, "%.9g", v); break;
    case PARAM_ENUM: snprintf(out, n, "%s", p->choices[(int)v]); break;
    }
}

static bool refuse(const Technique *t, const ParamDesc *p, const char *what, Error *err)
{
    char range[256];
    tech_param_range(p, range, sizeof range);
    return error_set(err, "%s: parameter %s = %s is invalid: expected %s %s", t->name, p->name, what,
                     param_type_name(p->type), range);
}

bool tech_param_set(const Technique *t, const char *name, double v, double *values, Error *err)
{
    int i = tech_param_index(t, name);
    if (i < 0) {
        char known[512] = "";
        size_t used = 0;
        for (int k = 0; k < t->num_params && used < sizeof known; k++)
            used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", k ? ", " : "", t->params[k].name);
        return error_set(err, "%s: unknown parameter '%s' (parameters: %s)", t->name, name,
                         t->num_params ? known : "none");
    }
    const ParamDesc *p = &t->params[i];
    char text[64];
    snprintf(text, sizeof text, "%.9g", v);
    for (int c = 0; p->type == PARAM_ENUM && c <= v && p->choices[c]; c++) /* a name outside the declared prefix */
        if (v == c) snprintf(text, sizeof text, "%s", p->choices[c]);
    bool integral = p->type != PARAM_FLOAT;
    if (!isfinite(v) || (integral && v != floor(v)) || v < p->min || v > p->max) return refuse(t, p, text, err);
    values[i] = v;
    return true;
}

bool tech_params_check(const Technique *t, const double *values, Error *err)
{
    double scratch[TECH_MAX_PARAMS];
    for (int i = 0; i < t->num_params; i++)
        if (!tech_param_set(t, t->params[i].name, values[i], scratch, err)) return false;
    return true;
}

/* Text to number for a parameter's type: enum names, true/false, numbers. */
static bool parse_value(const ParamDesc *p, const char *s, double *v)
{
    if (p->type == PARAM_ENUM) {
        for (int i = 0; p->choices[i]; i++)
            if (strcmp(s, p->choices[i]) == 0) { *v = i; return true; }
        return false;
    }
    if (p->type == PARAM_BOOL) {
        if (strcmp(s, "true") == 0 || strcmp(s, "1") == 0) { *v = 1; return true; }
        if (strcmp(s, "false") == 0 || strcmp(s, "0") == 0) { *v = 0; return true; }
        return false;
    }
    char *end;
    *v = strtod(s, &end);
    return end != s && *end == '\0';
}

bool tech_param_parse(const Technique *t, const char *assignment, double *values, Error *err)
{
    const char *eq = strchr(assignment, '=');
    if (!eq || eq == assignment) return error_set(err, "%s: parameter '%s' must be name=value", t->name, assignment);
    char name[128];
    snprintf(name, sizeof name, "%.*s", (int)(eq - assignment), assignment);
    int i = tech_param_index(t, name);
    if (i < 0) return tech_param_set(t, name, 0, values, err); /* reports the unknown name */
    double v;
    if (!parse_value(&t->params[i], eq + 1, &v)) return refuse(t, &t->params[i], eq + 1, err);
    return tech_param_set(t, name, v, values, err);
}
