/* list.c -- `shadowlab list`: every technique in the registry with its
 * parameters (type, default, range, unit, doc, the condition under which
 * it acts), as text or JSON, or the
 * generated documents (docgen.h). */
#include "cli/cli.h"
#include "cli/docgen.h"
#include "core/json.h"
#include "techniques/smap.h"

static void print_param(const Technique *t, int k)
{
    const ParamDesc *p = &t->params[k];
    const char *when = tech_param_when(t, k);
    char def[64], range[256];
    tech_param_format(p, p->def, def, sizeof def);
    tech_param_range(p, range, sizeof range);
    printf("  -p %s=%s  (%s %s%s%s)\n      %s\n", p->name, def, param_type_name(p->type), range, p->unit[0] ? ", " : "",
           p->unit, p->doc);
    if (when) printf("      acts only when %s\n", when);
}

static void print_header(const Technique *t)
{
    char lights[160];
    tech_lights_text(t, lights, sizeof lights);
    printf("%s  [%s; %s]\n  %s\n  lights: %s\n  main parameter: %s\n", t->name, t->family, t->source, t->summary,
           lights, t->main_param ? t->main_param : "none");
    printf("  resources:");
    for (const char *const *r = t->resources; *r; r++) printf(" %s", *r);
    printf("\n");
}

/* One technique with every parameter it offers (`list TECH`). */
static void print_one(const Technique *t)
{
    print_header(t);
    for (int k = 0; k < t->num_params; k++)
        if (tech_param_offered(t, k)) print_param(t, k);
}

/* Every technique: the shared map and bias parameters once, then each
 * technique's own, with where its declaration of a shared one differs. */
static void print_all(void)
{
    const Technique *maps[64];
    int shared, n = docgen_map_techniques(maps, 64, &shared);
    if (n > 0) {
        printf("shared shadow-map parameters, taken first by every map technique (marked [map] below; where one "
               "differs it says so; `shadowlab list TECH` shows one technique whole):\n");
        for (int k = 0; k < shared; k++) print_param(maps[0], k);
        printf("\n");
    }
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        bool map = n > 0 && smap_has_map_params(t);
        print_header(t);
        if (map) printf("  [map] the shared parameters above\n");
        for (int k = 0; map && k < shared; k++) {
            char what[320];
            docgen_param_difference(maps[0], t, k, what, sizeof what);
            if (what[0]) printf("  -p %s: %s here\n", maps[0]->params[k].name, what);
        }
        for (int k = map ? docgen_shared_prefix(maps[0], t, shared) : 0; k < t->num_params; k++)
            if (tech_param_offered(t, k)) print_param(t, k);
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
static const CliCommand list_cmd = {"list", "[TECH] [--json | --markdown | --readme | --names]", false, list_options,
                                    "every technique of the registry with its parameters: type, default, range, "
                                    "unit, doc (the shared map parameters once); TECH: that technique whole\n"};

int cmd_list(int argc, char **argv)
{
    CliOptions o;
    Error err;
    const Technique *one = NULL;
    bool ok = true;
    if (argc > 1 && argv[1][0] != '-') { /* list TECH */
        one = tech_find(argv[1], &err);
        ok = one != NULL;
        argv[1] = argv[0];
        argc--, argv++;
    }
    ok = ok && cli_parse(&list_cmd, argc, argv, &o, &err);
    if (ok && o.json + o.markdown + o.readme + o.names > 1)
        ok = error_set(&err, "--json, --markdown, --readme and --names are exclusive: give one");
    if (ok && one && o.json + o.markdown + o.readme + o.names > 0)
        ok = error_set(&err, "list TECH prints one technique as text: no --json, --markdown, --readme or --names");
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
    else if (one) print_one(one);
    else print_all();
    return EXIT_OK;
}
