/* run.c -- `render`, `reference` and `compare`: one pipeline (lab/compare.h),
 * three subsets of its stages (render: technique; reference: ground truth;
 * compare: both, then metrics), then the outputs and the printed table. */
#include <omp.h>
#include <string.h>
#include "cli/cli.h"
#include "core/hash.h"
#include "core/progress.h"
#include "lab/compare.h"
#include "resources/refcache.h"

enum Stage { STAGE_RENDER = 1, STAGE_REFERENCE = 2 };

/* The options that act on each command (args.c has their help lines). */
static const CliAccept render_options[] = {
    {OPT_TECHNIQUE, "technique (required; see shadowlab list)"}, {OPT_PARAM, NULL}, {OPT_SET, NULL},
    {OPT_LIGHT, NULL}, {OPT_REPEAT, NULL}, {OPT_WARMUP, NULL}, {OPT_THREADS, NULL}, {OPT_OUT, NULL},
    {OPT_NO_PNG, NULL}, {OPT_END, NULL}};
static const CliAccept reference_options[] = {
    {OPT_SET, NULL}, {OPT_LIGHT, NULL}, {OPT_SAMPLES, NULL}, {OPT_PATTERN, NULL}, {OPT_SEED, NULL}, {OPT_SAMPLE_SET, NULL},
    {OPT_MEASURE, NULL}, {OPT_CACHE, NULL}, {OPT_NO_CACHE, NULL}, {OPT_THREADS, NULL}, {OPT_OUT, NULL},
    {OPT_NO_PNG, NULL}, {OPT_END, NULL}};
static const CliAccept compare_options[] = {
    {OPT_TECHNIQUE, "technique (required; see shadowlab list)"}, {OPT_PARAM, NULL}, {OPT_SET, NULL},
    {OPT_LIGHT, NULL}, {OPT_SAMPLES, NULL}, {OPT_PATTERN, NULL}, {OPT_SEED, NULL}, {OPT_SAMPLE_SET, NULL}, {OPT_CACHE, NULL},
    {OPT_NO_CACHE, NULL}, {OPT_REPEAT, NULL}, {OPT_WARMUP, NULL}, {OPT_THREADS, NULL}, {OPT_OUT, NULL},
    {OPT_NO_PNG, NULL}, {OPT_END, NULL}};

static const CliCommand render_cmd = {"render", "SCENE -t TECH [options]", true, render_options,
                                      "the technique's visibility, no reference: TECH.{exr,json,png} in the output folder\n"};
static const CliCommand reference_cmd = {"reference", "SCENE [options]", true, reference_options,
                                         "the Embree ground truth (read from the cache when there): reference.{exr,json,png}\n"};
static const CliCommand compare_cmd = {"compare", "SCENE -t TECH [options]", true, compare_options,
                                       "render, reference, metrics per region and the signed error: TECH.{exr,json,png}\n"};

typedef struct Job {
    CliOptions o;
    Lab *lab;
    CompareRequest req;
    double params[TECH_MAX_PARAMS];
    CompareResult result;
    char cache_dir[1024];
    char out_dir[1024];
} Job;

static bool setup(Job *j, int stages, Error *err)
{
    const CliOptions *o = &j->o;
    j->req = (CompareRequest){NULL, j->params, 0, o->repeat, o->warmup, (stages & STAGE_REFERENCE) != 0, o->ref,
                              NULL, 0.0, 0.0}; /* the CLI: each error PNG its own scale */
    if ((stages & STAGE_REFERENCE) && !reference_params_check(&o->ref, err)) return false;
    if (!(stages & STAGE_RENDER)) return true;
    if (!o->technique) return error_set(err, "missing -t TECHNIQUE (see shadowlab list)");
    j->req.tech = tech_find(o->technique, err);
    if (!j->req.tech) return false;
    tech_params_default(j->req.tech, j->params);
    for (int i = 0; i < o->num_params; i++)
        if (!tech_param_parse(j->req.tech, o->params[i], j->params, err)) return false;
    return true;
}

/* -o DIR, else reports/SCENE-NAME for the scene as its file says, and
 * reports/SCENE-NAME-HASH (8 hex digits of the scene's content hash) under
 * -s overrides: outputs of different scene states never share a folder (a
 * reference of radius 0.4 beside a technique's image of radius 0.1). */
static void default_out_dir(Job *j, const Scene *sc)
{
    char hex[17];
    hash_hex(sc->hash, hex);
    if (j->o.out_dir) snprintf(j->out_dir, sizeof j->out_dir, "%s", j->o.out_dir);
    else if (j->o.num_overrides == 0) snprintf(j->out_dir, sizeof j->out_dir, "reports/%s", sc->name);
    else snprintf(j->out_dir, sizeof j->out_dir, "reports/%s-%.8s", sc->name, hex);
}

static bool load(Job *j, Error *err)
{
    j->lab = lab_open(j->o.scene, j->o.overrides, j->o.num_overrides, err);
    if (!j->lab) return false;
    const Scene *sc = lab_scene(j->lab);
    default_out_dir(j, sc);
    if (j->o.cache_dir) snprintf(j->cache_dir, sizeof j->cache_dir, "%s", j->o.cache_dir);
    else refcache_default_dir(j->cache_dir, sizeof j->cache_dir);
    j->req.cache_dir = j->o.no_cache ? NULL : j->cache_dir;
    return lab_light_index(j->lab, j->o.light, &j->req.light_index, err);
}

/* The stages, then the outputs. */
static bool work(Job *j, const char *name, RunReport *rep, Error *err)
{
    if (!lab_compare(j->lab, &j->req, &j->result, err)) return false;
    *rep = compare_report(j->lab, &j->result, name, omp_get_max_threads());
    Progress outputs;
    progress_begin(&outputs, "outputs", 0);
    bool ok = report_write_all(rep, j->out_dir, !j->o.no_png, err);
    progress_end(&outputs);
    return ok;
}

static int run(const CliCommand *cmd, int stages, int argc, char **argv)
{
    const char *name = cmd->name;
    Job j;
    memset(&j, 0, sizeof j);
    Error err;
    if (!cli_parse(cmd, argc, argv, &j.o, &err) || (!j.o.help && !setup(&j, stages, &err))) {
        fprintf(stderr, "shadowlab %s: %s\n", name, err.msg);
        return EXIT_USAGE;
    }
    if (j.o.help) {
        cli_print_help(cmd, stdout);
        return EXIT_OK;
    }
    cli_apply_threads(&j.o);
    progress_set_heartbeat(true); /* this process never forks */
    char label[PROGRESS_LABEL_MAX];
    snprintf(label, sizeof label, "%s%s%s", name, j.req.tech ? " " : "", j.req.tech ? j.req.tech->name : "");
    Progress prog; /* "compare pcf > shadow_map, 1.2 s" on a terminal, after a second */
    progress_begin(&prog, label, 0);
    int status = EXIT_RUNTIME;
    bool loaded = load(&j, &err);
    if (loaded) { /* the first line before the work: what runs, on what */
        progress_clear();
        report_print_header(j.lab, j.req.tech, j.req.light_index, stdout);
        fflush(stdout);
    }
    RunReport rep;
    bool done = loaded && work(&j, name, &rep, &err);
    progress_end(&prog);
    if (done) {
        if (j.result.ref_info.cache_note[0]) fprintf(stderr, "shadowlab: warning: %s\n", j.result.ref_info.cache_note);
        report_print_body(&rep, stdout);
        printf("outputs: %s/%s.{exr,json%s}\n", j.out_dir, report_stem(&rep), j.o.no_png ? "" : ",png");
        status = EXIT_OK;
    }
    if (status != EXIT_OK) fprintf(stderr, "shadowlab %s: %s\n", name, err.msg);
    compare_result_free(&j.result);
    lab_close(j.lab);
    return status;
}

int cmd_render(int argc, char **argv) { return run(&render_cmd, STAGE_RENDER, argc, argv); }
int cmd_reference(int argc, char **argv) { return run(&reference_cmd, STAGE_REFERENCE, argc, argv); }
int cmd_compare(int argc, char **argv) { return run(&compare_cmd, STAGE_RENDER | STAGE_REFERENCE, argc, argv); }
