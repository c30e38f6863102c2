/* args.c -- options shared by render, reference and compare. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "rt/rt.h"

static bool parse_int(const char *opt, const char *s, int lo, int hi, int *out, Error *err)
{
    char *end;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || end == s || *end != '\0' || v < lo || v > hi)
        return error_set(err, "%s expects an integer in [%d, %d], got '%s'", opt, lo, hi, s ? s : "(nothing)");
    *out = (int)v;
    return true;
}

static bool push(const char **list, int *n, const char *opt, const char *value, Error *err)
{
    if (!value) return error_set(err, "%s expects a value", opt);
    if (*n >= CLI_MAX_ASSIGN) return error_set(err, "more than %d %s options", CLI_MAX_ASSIGN, opt);
    list[(*n)++] = value;
    return true;
}

static bool is(const char *a, const char *s, const char *l) { return strcmp(a, s) == 0 || (l && strcmp(a, l) == 0); }

static bool parse_option(char **argv, int *i, int argc, CliOptions *o, Error *err)
{
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    bool takes = true, ok = true;
    if (is(a, "-t", "--technique")) o->technique = v;
    else if (is(a, "-p", "--param")) ok = push(o->params, &o->num_params, a, v, err);
    else if (is(a, "-s", "--set")) ok = push(o->overrides, &o->num_overrides, a, v, err);
    else if (is(a, "-o", "--out")) o->out_dir = v;
    else if (is(a, "--threads", NULL)) ok = parse_int(a, v, 1, 1024, &o->threads, err);
    else if (is(a, "--repeat", NULL)) ok = parse_int(a, v, 1, 10000, &o->repeat, err);
    else if (is(a, "--warmup", NULL)) ok = parse_int(a, v, 0, 1000, &o->warmup, err);
    else if (is(a, "--light", "-l")) ok = parse_int(a, v, 1, 64, &o->light, err);
    else if (is(a, "--samples", "-n")) ok = parse_int(a, v, 1, REFERENCE_MAX_SAMPLES, &o->ref.samples, err);
    else if (is(a, "--seed", NULL)) {
        int seed = 0;
        ok = parse_int(a, v, 0, 2147483647, &seed, err);
        o->ref.seed = (uint32_t)seed;
    }
    else if (is(a, "--measure", NULL)) ok = v ? measure_parse(v, &o->ref.measure, err) : error_set(err, "--measure expects a value");
    else if (is(a, "--pattern", NULL)) ok = v ? sampling_pattern_parse(v, &o->ref.pattern, err) : error_set(err, "--pattern expects a value");
    else if (is(a, "--cache", NULL)) o->cache_dir = v;
    else {
        takes = false;
        if (is(a, "--no-cache", NULL)) o->no_cache = true;
        else if (is(a, "--no-png", NULL)) o->no_png = true;
        else if (is(a, "--json", NULL)) o->json = true;
        else if (is(a, "--names", NULL)) o->names = true;
        else if (is(a, "--markdown", NULL)) o->markdown = true;
        else if (is(a, "--help", "-h")) o->help = true;
        else return error_set(err, "unknown option '%s'", a);
    }
    if (takes && !v) return error_set(err, "%s expects a value", a);
    if (takes) (*i)++;
    return ok;
}

bool cli_parse(int argc, char **argv, bool needs_scene, CliOptions *o, Error *err)
{
    memset(o, 0, sizeof *o);
    o->repeat = 1;
    o->light = 1;
    o->ref = (ReferenceParams){MEASURE_VISIBILITY, 1024, SAMPLING_R2, 1};
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1] != '\0') {
            if (!parse_option(argv, &i, argc, o, err)) return false;
        } else if (needs_scene && !o->scene) {
            o->scene = argv[i];
        } else {
            return error_set(err, "unexpected argument '%s'", argv[i]);
        }
    }
    if (needs_scene && !o->scene && !o->help) return error_set(err, "missing SCENE (a scene file, e.g. scenes/sphere-on-plane.lua)");
    return true;
}

void cli_apply_threads(const CliOptions *o)
{
    if (o->threads > 0) omp_set_num_threads(o->threads);
    rt_set_threads(o->threads > 0 ? o->threads : omp_get_max_threads());
}
