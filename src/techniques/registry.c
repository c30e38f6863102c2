/* registry.c -- the technique table and shared parameter handling. Adding a
 * technique is one file in this folder and one line in `registry` below. */
#include "techniques/registry.h"
#include "techniques/smap.h"
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
extern const Technique tech_vssm;
extern const Technique tech_essm;
extern const Technique tech_moment_soft;
extern const Technique tech_dpcf;
extern const Technique tech_adaptive_area;
extern const Technique tech_shadow_width;
extern const Technique tech_aliasing;
extern const Technique tech_backprojection;
extern const Technique tech_hsm;
extern const Technique tech_mssm;
extern const Technique tech_ysm;
extern const Technique tech_light_sampling;
extern const Technique tech_layered_attenuation;
extern const Technique tech_penumbra_deep_map;
extern const Technique tech_occlusion_textures;
extern const Technique tech_smrt;
extern const Technique tech_shadow_volume;
extern const Technique tech_soft_shadow_volume;
extern const Technique tech_penumbra_wedge;
extern const Technique tech_depth_complexity;
extern const Technique tech_view_sample_mapping;
extern const Technique tech_smoothies;
extern const Technique tech_penumbra_map;

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
    &tech_vssm,
    &tech_essm,
    &tech_moment_soft,
    &tech_dpcf,
    &tech_adaptive_area,
    &tech_shadow_width,
    &tech_aliasing,
    &tech_backprojection,
    &tech_hsm,
    &tech_mssm,
    &tech_ysm,
    &tech_light_sampling,
    &tech_layered_attenuation,
    &tech_penumbra_deep_map,
    &tech_occlusion_textures,
    &tech_smrt,
    &tech_shadow_volume,
    &tech_soft_shadow_volume,
    &tech_penumbra_wedge,
    &tech_depth_complexity,
    &tech_view_sample_mapping,
    &tech_smoothies,
    &tech_penumbra_map,
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

static bool condition_possible(const Technique *t, int k);

/* Check value v for parameter i and store it. */
static bool set_value(const Technique *t, int i, double v, double *values, Error *err)
{
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

bool tech_param_set(const Technique *t, const char *name, double v, double *values, Error *err)
{
    int i = tech_param_index(t, name);
    if (i < 0) {
        char known[512] = "";
        size_t used = 0;
        for (int k = 0; k < t->num_params && used < sizeof known; k++)
            if (tech_param_offered(t, k))
                used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", used ? ", " : "", t->params[k].name);
        return error_set(err, "%s: unknown parameter '%s' (parameters: %s)", t->name, name,
                         t->num_params ? known : "none");
    }
    double scratch[TECH_MAX_PARAMS];
    if (!condition_possible(t, i) && v != t->params[i].def) /* its default: what leaving it out means */
        return set_value(t, i, v, scratch, err) && /* an ill-typed value: refused with the range */
               error_set(err, "%s: parameter '%s' is not one of its own: it acts only when %s, which %s does not take",
                         t->name, name, tech_param_when(t, i), t->name);
    return set_value(t, i, v, values, err);
}

bool tech_params_check(const Technique *t, const double *values, Error *err)
{
    double scratch[TECH_MAX_PARAMS];
    for (int i = 0; i < t->num_params; i++)
        if (!set_value(t, i, values[i], scratch, err)) return false;
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

/* ---- conditions (Technique.conditions, smap_conditions) ---- */

const char *tech_param_when(const Technique *t, int k)
{
    const char *name = t->params[k].name;
    for (const ParamCondition *c = t->conditions; c && c->param; c++)
        if (strcmp(c->param, name) == 0) return c->when;
    if (k < SMAP_P_BIAS && smap_has_map_params(t)) /* the shared block's own */
        for (const ParamCondition *c = smap_conditions; c->param; c++)
            if (strcmp(c->param, name) == 0) return c->when;
    return NULL;
}

#define COND_MAX_CLAUSES 8
#define COND_MAX_VALUES 16

/* One clause NAME=V1|V2 (or NAME!=...); `alternative` starts an " or " branch. */
typedef struct CondClause {
    int param;
    bool negate, alternative;
    int n;
    double v[COND_MAX_VALUES];
} CondClause;

/* A clause NAME=V1|V2 (or NAME!=...). Values outside the technique's range
 * of NAME are dropped: the shared map block's conditions name every warp,
 * and a technique that accepts fewer keeps the clause's other values. */
static bool clause_parse(const Technique *t, const char *who, char *text, CondClause *c, Error *err)
{
    char *eq = strchr(text, '=');
    if (!eq || eq == text) return error_set(err, "%s: condition '%s' of %s: expected NAME=VALUE", t->name, text, who);
    c->negate = eq[-1] == '!';
    *(c->negate ? eq - 1 : eq) = '\0';
    c->param = tech_param_index(t, text);
    if (c->param < 0) return error_set(err, "%s: condition of %s names no parameter '%s'", t->name, who, text);
    const ParamDesc *p = &t->params[c->param];
    c->n = 0;
    char *save = NULL;
    for (char *v = strtok_r(eq + 1, "|", &save); v; v = strtok_r(NULL, "|", &save)) {
        double x;
        if (c->n == COND_MAX_VALUES || !parse_value(p, v, &x))
            return error_set(err, "%s: condition of %s: '%s' is not a value of %s", t->name, who, v, p->name);
        if (x >= p->min && x <= p->max) c->v[c->n++] = x;
    }
    return true;
}

/* The clauses of parameter k's condition; 0 when it has none, -1 on a malformed one. */
static int condition_parse(const Technique *t, int k, CondClause *c, Error *err)
{
    const char *text = tech_param_when(t, k);
    if (!text) return 0;
    char buf[512], *save = NULL;
    snprintf(buf, sizeof buf, "%s", text);
    int n = 0;
    bool alternative = true;
    for (char *w = strtok_r(buf, " ", &save); w; w = strtok_r(NULL, " ", &save)) {
        if (strcmp(w, "or") == 0 || strcmp(w, "and") == 0) {
            if (alternative || n == 0) break; /* two joins in a row, or a join first */
            alternative = w[0] == 'o';
            continue;
        }
        if (n == COND_MAX_CLAUSES || !clause_parse(t, t->params[k].name, w, &c[n], err)) return -1;
        c[n++].alternative = alternative;
        alternative = false;
    }
    if (n == 0 || alternative) {
        error_set(err, "%s: condition '%s' of %s: expected clauses joined by 'and' or 'or'", t->name, text,
                  t->params[k].name);
        return -1;
    }
    return n;
}

static bool clause_holds(const CondClause *c, const double *values)
{
    bool listed = false;
    for (int i = 0; i < c->n; i++) listed = listed || values[c->param] == c->v[i];
    return listed != c->negate;
}

bool tech_param_condition_check(const Technique *t, int k, Error *err)
{
    CondClause c[COND_MAX_CLAUSES];
    return condition_parse(t, k, c, err) >= 0;
}

/* The end of the alternative (the " or " branch) that starts at clause i. */
static int alternative_end(const CondClause *c, int n, int i)
{
    while (++i < n && !c[i].alternative) {}
    return i;
}

bool tech_param_acts(const Technique *t, int k, const double *values)
{
    CondClause c[COND_MAX_CLAUSES];
    Error err;
    int n = condition_parse(t, k, c, &err);
    if (n <= 0) return true; /* none (a malformed one is refused by the registry's test) */
    for (int a = 0, b; a < n; a = b) {
        b = alternative_end(c, n, a);
        bool holds = true;
        for (int i = a; i < b; i++) holds = holds && clause_holds(&c[i], values);
        if (holds) return true;
    }
    return false;
}

/* A value that satisfies clause c within its parameter's range: the first
 * listed value, or for NAME!=... the first not listed of the default, the
 * integers above the minimum and the range's ends; false when none does. */
static bool clause_value(const Technique *t, const CondClause *c, double *v)
{
    if (!c->negate) {
        *v = c->v[0];
        return c->n > 0;
    }
    const ParamDesc *p = &t->params[c->param];
    double tries[COND_MAX_VALUES + 4] = {p->def};
    int n = 1;
    for (double x = p->min + 1.0; p->type != PARAM_FLOAT && x < p->max && n < COND_MAX_VALUES + 2; x++)
        tries[n++] = x;
    tries[n++] = p->min;
    tries[n++] = p->max;
    for (int i = 0; i < n; i++) {
        bool listed = false;
        for (int j = 0; j < c->n; j++) listed = listed || tries[i] == c->v[j];
        if (!listed) {
            *v = tries[i];
            return true;
        }
    }
    return false;
}

/* The first alternative of parameter k's condition that can hold within the
 * technique's ranges: its clauses [*a, *b); false when none can. */
static bool possible_alternative(const Technique *t, const CondClause *c, int n, int *a, int *b)
{
    for (*a = 0; *a < n; *a = *b) {
        *b = alternative_end(c, n, *a);
        bool possible = true;
        double v;
        for (int i = *a; i < *b; i++) possible = possible && clause_value(t, &c[i], &v);
        if (possible) return true;
    }
    return false;
}

/* Can parameter k's condition hold within the technique's ranges? */
static bool condition_possible(const Technique *t, int k)
{
    CondClause c[COND_MAX_CLAUSES];
    Error err;
    int n = condition_parse(t, k, c, &err), a, b;
    return n <= 0 || possible_alternative(t, c, n, &a, &b);
}

bool tech_param_offered(const Technique *t, int k)
{
    return t->params[k].min < t->params[k].max && condition_possible(t, k); /* one value: nothing to choose */
}

void tech_param_enable(const Technique *t, int k, double *values)
{
    CondClause c[COND_MAX_CLAUSES];
    Error err;
    int n = condition_parse(t, k, c, &err), a, b;
    if (n > 0 && possible_alternative(t, c, n, &a, &b))
        for (int i = a; i < b; i++) clause_value(t, &c[i], &values[c[i].param]);
}
