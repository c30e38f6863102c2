/* list.c -- `shadowlab list`: every technique in the registry with its
 * parameters (type, default, range, unit, doc, the condition under which
 * it acts), as text or JSON, or the
 * generated documents (docgen.h). */
#include "cli/cli.h"
#include "cli/docgen.h"
#include "core/json.h"

static void print_text(void)
{
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        char lights[160];
        tech_lights_text(t, lights, sizeof lights);
        printf("%s  [%s; %s]\n  %s\n  lights: %s\n  main parameter: %s\n", t->name, t->family, t->source, t->summary,
               lights, t->main_param ? t->main_param : "none");
        printf("  resources:");
        for (const char *const *r = t->resources; *r; r++) printf(" %s", *r);
        printf("\n");
        for (int k = 0; k < t->num_params; k++) {
            const ParamDesc *p = &t->params[k];
            const char *when = tech_param_when(t, k);
            char def[64], range[256];
            if (!tech_param_offered(t, k)) continue;
            tech_param_format(p, p->def, def, sizeof def);
            tech_param_range(p, range, sizeof range);
            printf("  -p %s=%s  (%s %s%s%s)\n      %s\n", p->name, def, param_type_name(p->type), range,
                   p->unit[0] ? ", " : "", p->unit, p->doc);
            if (when) printf("      acts only when %s\n", when);
        }
        printf("\n");
    }
}

static void print_json(void)
{
    JsonWriter w;
    json_init(&w, stdout);
    json_array_begin(&w, NULL);
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        json_object_begin(&w, NULL);
        json_string(&w, "name", t->name);
        json_string(&w, "family", t->family);
        json_string(&w, "source", t->source);
        json_string(&w, "summary", t->summary);
        json_bool(&w, "rgb", t->rgb);
        if (t->main_param) json_string(&w, "main_param", t->main_param); /* absent: none */
        json_array_begin(&w, "lights");
        for (int k = LIGHT_POINT; k <= LIGHT_TEXTURED_RECT; k++)
            if (t->lights & LIGHT_BIT(k)) json_string(&w, NULL, light_kind_name((LightKind)k));
        json_array_end(&w);
        json_array_begin(&w, "resources");
        for (const char *const *r = t->resources; *r; r++) json_string(&w, NULL, *r);
        json_array_end(&w);
        json_array_begin(&w, "params");
        for (int k = 0; k < t->num_params; k++) {
            const ParamDesc *p = &t->params[k];
            if (!tech_param_offered(t, k)) continue;
            json_object_begin(&w, NULL);
            json_string(&w, "name", p->name);
            json_string(&w, "type", param_type_name(p->type));
            json_number(&w, "default", p->def);
            json_number(&w, "min", p->min);
            json_number(&w, "max", p->max);
            json_string(&w, "unit", p->unit);
            json_string(&w, "doc", p->doc);
            if (tech_param_when(t, k)) json_string(&w, "acts_when", tech_param_when(t, k)); /* absent: always */
            if (p->type == PARAM_ENUM) {
                json_array_begin(&w, "choices");
                for (int c = 0; p->choices[c]; c++) json_string(&w, NULL, p->choices[c]);
                json_array_end(&w);
            }
            json_object_end(&w);
        }
        json_array_end(&w);
        json_object_end(&w);
    }
    json_array_end(&w);
    json_finish(&w);
}

static const CliAccept list_options[] = {
    {OPT_JSON, NULL}, {OPT_MARKDOWN, NULL}, {OPT_README, NULL}, {OPT_NAMES, NULL}, {OPT_END, NULL}};
static const CliCommand list_cmd = {"list", "[--json | --markdown | --readme | --names]", false, list_options,
                                    "every technique of the registry with its parameters: type, default, range, "
                                    "unit, doc\n"};

int cmd_list(int argc, char **argv)
{
    CliOptions o;
    Error err;
    bool ok = cli_parse(&list_cmd, argc, argv, &o, &err);
    if (ok && o.json + o.markdown + o.readme + o.names > 1)
        ok = error_set(&err, "--json, --markdown, --readme and --names are exclusive: give one");
    if (!ok) {
        fprintf(stderr, "shadowlab list: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (o.help) cli_print_help(&list_cmd, stdout);
    else if (o.json) print_json();
    else if (o.markdown) docgen_techniques_md(stdout);
    else if (o.readme) docgen_readme_block(stdout);
    else if (o.names)
        for (int i = 0; i < tech_count(); i++) printf("%s\n", tech_at(i)->name);
    else print_text();
    return EXIT_OK;
}
