/* test_registry.c -- the technique registry: every parameter is typed,
 * documented and has its default inside its range; out-of-range, ill-typed
 * and unknown values are refused with the parameter's name and range. */
#include <string.h>
#include "techniques/registry.h"
#include "test.h"

TEST(test_registry_declarations_are_complete)
{
    CHECK(tech_count() >= 1);
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        CHECK_MSG(t->name && t->family && t->source && t->summary && t->resources, "technique %d", i);
        CHECK_MSG(t->prepare && t->evaluate, "%s: no prepare/evaluate", t->name);
        CHECK(t->num_params <= TECH_MAX_PARAMS);
        CHECK_MSG(t->lights != 0 && (t->lights & ~LIGHTS_ALL) == 0, "%s: light kinds %#x", t->name, t->lights);
        CHECK_MSG(!t->main_param || tech_param_index(t, t->main_param) >= 0, "%s: main parameter %s is not one of its own",
                  t->name, t->main_param);
        Error err;
        CHECK_MSG(tech_find(t->name, &err) == t, "%s is not found by name", t->name);
        for (int j = 0; j < i; j++) CHECK_MSG(strcmp(tech_at(j)->name, t->name) != 0, "duplicate %s", t->name);
        for (int k = 0; k < t->num_params; k++) {
            const ParamDesc *p = &t->params[k];
            CHECK_MSG(p->name && p->doc && p->doc[0] && p->unit, "%s: parameter %d undocumented", t->name, k);
            CHECK_MSG(p->min <= p->def && p->def <= p->max, "%s.%s: default %g outside [%g, %g]", t->name,
                      p->name, p->def, p->min, p->max);
            CHECK_MSG(p->type != PARAM_ENUM || p->choices, "%s.%s: enum without choices", t->name, p->name);
        }
    }
}

TEST(test_registry_refuses_bad_values_with_the_range)
{
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        double v[TECH_MAX_PARAMS];
        tech_params_default(t, v);
        Error err;
        CHECK(!tech_param_parse(t, "no_such_parameter=1", v, &err));
        CHECK_MSG(strstr(err.msg, "no_such_parameter"), "%s", err.msg);
        for (int k = 0; k < t->num_params; k++) {
            const ParamDesc *p = &t->params[k];
            char assign[256], range[256];
            if (!tech_param_offered(t, k)) continue; /* refused by name: test_registry_conditions_are_well_formed */
            tech_param_range(p, range, sizeof range);
            snprintf(assign, sizeof assign, "%s=%.17g", p->name, p->max + 1.0);
            CHECK_MSG(!tech_param_parse(t, assign, v, &err), "%s accepted", assign);
            CHECK_MSG(strstr(err.msg, p->name) && strstr(err.msg, range), "message lacks name or range: %s", err.msg);
            snprintf(assign, sizeof assign, "%s=%.17g", p->name, p->min - 1.0);
            CHECK_MSG(!tech_param_parse(t, assign, v, &err), "%s accepted", assign);
            snprintf(assign, sizeof assign, "%s=nan", p->name);
            CHECK_MSG(!tech_param_parse(t, assign, v, &err), "%s accepted", assign);
            snprintf(assign, sizeof assign, "%s=banana", p->name);
            CHECK_MSG(!tech_param_parse(t, assign, v, &err), "%s accepted", assign);
            char def[64];
            tech_param_format(p, p->def, def, sizeof def);
            snprintf(assign, sizeof assign, "%s=%s", p->name, def);
            CHECK_MSG(tech_param_parse(t, assign, v, &err), "%s refused: %s", assign, err.msg);
            CHECK(v[k] == p->def);
        }
    }
}

/* Every declared condition (Technique.conditions, smap_conditions) parses,
 * names parameters of its technique and parses their values; a condition
 * holds once tech_param_enable has set what it names. */
TEST(test_registry_conditions_are_well_formed)
{
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        for (const ParamCondition *c = t->conditions; c && c->param; c++)
            CHECK_MSG(tech_param_index(t, c->param) >= 0, "%s: condition for unknown parameter %s", t->name, c->param);
        for (int k = 0; k < t->num_params; k++) {
            Error err;
            CHECK_MSG(tech_param_condition_check(t, k, &err), "%s", err.msg);
            if (!tech_param_offered(t, k)) continue;
            double v[TECH_MAX_PARAMS];
            tech_params_default(t, v);
            tech_param_enable(t, k, v);
            CHECK_MSG(tech_param_acts(t, k, v), "%s.%s: its condition '%s' does not hold once enabled", t->name,
                      t->params[k].name, tech_param_when(t, k));
            CHECK_MSG(tech_params_check(t, v, &err), "%s.%s enabled: %s", t->name, t->params[k].name, err.msg);
        }
    }
    Error err;
    const Technique *pcss = tech_find("pcss", &err);
    double v[TECH_MAX_PARAMS];
    tech_params_default(pcss, v);
    int taps = tech_param_index(pcss, "blocker_taps");
    CHECK(tech_param_acts(pcss, taps, v));
    CHECK(tech_param_parse(pcss, "sampling=exhaustive", v, &err));
    CHECK(!tech_param_acts(pcss, taps, v));
    /* a shared parameter whose condition cannot hold in the technique is not its own */
    const Technique *aa = tech_find("adaptive_area", &err);
    CHECK(!tech_param_offered(aa, tech_param_index(aa, "warp_n")));
    CHECK(!tech_param_parse(aa, "warp_n=2", v, &err));
    CHECK_MSG(strstr(err.msg, "warp_n") && strstr(err.msg, "projection=lispsm"), "%s", err.msg);
    CHECK_MSG(tech_param_parse(aa, "warp_n=1", v, &err), "its default, as a record names it: %s", err.msg);
}
