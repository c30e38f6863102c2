/* run.c -- `render`, `reference` and `compare`: one pipeline (lab/compare.h),
 * three subsets of its stages (render: technique; reference: ground truth;
 * compare: both, then metrics), then the outputs and the printed table. */
#include <omp.h>
#include <string.h>
#include "cli/cli.h"
#include "lab/compare.h"
#include "resources/refcache.h"

enum Stage { STAGE_RENDER = 1, STAGE_REFERENCE = 2 };

static const char *const help_text =
    "usage: shadowlab %s SCENE [options]\n"
    "  -t, --technique NAME   technique (see shadowlab list)%s\n"
    "  -p, --param K=V        technique parameter (repeatable)\n"
    "  -s, --set KEY=V        scene override, e.g. -s lights[1].radius=0.3 (repeatable)\n"
    "  -l, --light N          light number in the scene (default 1)\n"
    "  -n, --samples N        reference light samples per view sample (default 1024)\n"
    "  --pattern P            r2 | stratified | random (default r2)\n"
    "  --seed S               sampling seed (default 1)\n"
    "  --measure M            visibility | irradiance (reference only; default visibility)\n"
    "  --cache DIR            reference cache folder (default $SHADOWLAB_CACHE or ~/.cache/shadowlab)\n"
    "  --no-cache             neither read nor write the reference cache\n"
    "  --repeat N             time N evaluations; median and minimum reported\n"
    "  --warmup N             untimed evaluations before the timed ones (default 0)\n"
    "  --threads N            worker threads (default: all cores)\n"
    "  -o, --out DIR          output folder (default reports/SCENE-NAME)\n"
    "  --no-png               skip the PNG previews\n";

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
                              NULL, 0.0};
    if (!(stages & STAGE_RENDER)) return reference_params_check(&o->ref, err);
    if (!o->technique) return error_set(err, "missing -t TECHNIQUE (see shadowlab list)");
    j->req.tech = tech_find(o->technique, err);
    if (!j->req.tech) return false;
    tech_params_default(j->req.tech, j->params);
    for (int i = 0; i < o->num_params; i++)
        if (!tech_param_parse(j->req.tech, o->params[i], j->params, err)) return false;
    if ((stages & STAGE_REFERENCE) && !reference_params_check(&o->ref, err)) return false;
    if (o->ref.measure != MEASURE_VISIBILITY)
        return error_set(err, "--measure irradiance is for `shadowlab reference`; techniques estimate visibility");
    return true;
}

static bool load(Job *j, Error *err)
{
    j->lab = lab_open(j->o.scene, j->o.overrides, j->o.num_overrides, err);
    if (!j->lab) return false;
    const Scene *sc = lab_scene(j->lab);
    if (j->o.out_dir) snprintf(j->out_dir, sizeof j->out_dir, "%s", j->o.out_dir);
    else snprintf(j->out_dir, sizeof j->out_dir, "reports/%s", sc->name);
    if (j->o.cache_dir) snprintf(j->cache_dir, sizeof j->cache_dir, "%s", j->o.cache_dir);
    else refcache_default_dir(j->cache_dir, sizeof j->cache_dir);
    j->req.cache_dir = j->o.no_cache ? NULL : j->cache_dir;
    return lab_light_index(j->lab, j->o.light, &j->req.light_index, err);
}

static int run(const char *name, int stages, int argc, char **argv)
{
    Job j;
    memset(&j, 0, sizeof j);
    Error err;
    if (!cli_parse(argc, argv, true, &j.o, &err) || (!j.o.help && !setup(&j, stages, &err))) {
        fprintf(stderr, "shadowlab %s: %s\n", name, err.msg);
        return EXIT_USAGE;
    }
    if (j.o.help) {
        printf(help_text, name, stages & STAGE_RENDER ? " (required)" : " (unused)");
        return EXIT_OK;
    }
    cli_apply_threads(&j.o);
    int status = EXIT_RUNTIME;
    bool loaded = load(&j, &err);
    if (loaded) { /* the first line before the work: what runs, on what */
        report_print_header(j.lab, j.req.tech, j.req.light_index, stdout);
        fflush(stdout);
    }
    if (loaded && lab_compare(j.lab, &j.req, &j.result, &err)) {
        if (j.result.ref_info.cache_note[0]) fprintf(stderr, "shadowlab: warning: %s\n", j.result.ref_info.cache_note);
        RunReport rep = compare_report(j.lab, &j.result, name, omp_get_max_threads());
        if (report_write_all(&rep, j.out_dir, !j.o.no_png, &err)) {
            report_print_body(&rep, stdout);
            printf("outputs: %s/%s.{exr,json%s}\n", j.out_dir, report_stem(&rep), j.o.no_png ? "" : ",png");
            status = EXIT_OK;
        }
    }
    if (status != EXIT_OK) fprintf(stderr, "shadowlab %s: %s\n", name, err.msg);
    compare_result_free(&j.result);
    lab_close(j.lab);
    return status;
}

int cmd_render(int argc, char **argv) { return run("render", STAGE_RENDER, argc, argv); }
int cmd_reference(int argc, char **argv) { return run("reference", STAGE_REFERENCE, argc, argv); }
int cmd_compare(int argc, char **argv) { return run("compare", STAGE_RENDER | STAGE_REFERENCE, argc, argv); }
