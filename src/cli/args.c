/* args.c -- the options of every command, declared once: name, value, help
 * line and how the value is parsed. A command accepts the subset its
 * CliCommand lists (cli.h); anything else is a usage error naming the option
 * and the command, and the command's --help prints exactly that subset. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "rt/rt.h"

typedef struct OptDesc {
    const char *short_name, *long_name; /* short_name may be NULL */
    const char *value;                  /* the value's name in --help; NULL: a flag */
    const char *help;                   /* the default help line */
} OptDesc;

static const OptDesc opts[OPT_COUNT] = {
    [OPT_TECHNIQUE] = {"-t", "--technique", "NAME", "technique (see shadowlab list)"},
    [OPT_PARAM] = {"-p", "--param", "K=V", "technique parameter (repeatable; ranges in shadowlab list)"},
    [OPT_SET] = {"-s", "--set", "KEY=V", "scene override, e.g. -s lights[1].radius=0.3 (repeatable)"},
    [OPT_LIGHT] = {"-l", "--light", "N", "light number in the scene (default 1)"},
    [OPT_SAMPLES] = {"-n", "--samples", "N", "reference light samples per view sample (default 1024)"},
    [OPT_PATTERN] = {NULL, "--pattern", "P", "reference sampling: r2 | stratified | random (default r2)"},
    [OPT_SEED] = {NULL, "--seed", "S", "reference sampling seed (default 1)"},
    [OPT_SAMPLE_SET] = {NULL, "--sample-set", "SET",
                        "per_view_sample (each view sample its own stream; default) | shared (one light-sample set "
                        "for the frame, view_sample_mapping's sample_set=shared)"},
    [OPT_MEASURE] = {NULL, "--measure", "M", "visibility | irradiance (Lambertian direct light; default visibility)"},
    [OPT_CACHE] = {NULL, "--cache", "DIR", "reference cache folder (default $SHADOWLAB_CACHE or ~/.cache/shadowlab)"},
    [OPT_NO_CACHE] = {NULL, "--no-cache", NULL, "neither read nor write the reference cache"},
    [OPT_REPEAT] = {NULL, "--repeat", "N", "time N evaluations (median and minimum) and N builds of the frame's resources (median; default 1)"},
    [OPT_WARMUP] = {NULL, "--warmup", "N", "untimed evaluations before the timed ones (default 0)"},
    [OPT_THREADS] = {NULL, "--threads", "N", "worker threads (default: all cores)"},
    [OPT_OUT] = {"-o", "--out", "DIR", "output folder (default reports/SCENE-NAME, reports/SCENE-NAME-HASH under -s overrides)"},
    [OPT_NO_PNG] = {NULL, "--no-png", NULL, "skip the PNG previews"},
    [OPT_FRUSTUM] = {NULL, "--frustum", "N", "Lloyd's measure over the view frustum at N x N image points x N depths"},
    [OPT_JSON] = {NULL, "--json", NULL, "as JSON, for programs"},
    [OPT_MARKDOWN] = {NULL, "--markdown", NULL, "as Markdown: docs/techniques.md (make docs)"},
    [OPT_README] = {NULL, "--readme", NULL, "the README's generated block (make docs)"},
    [OPT_NAMES] = {NULL, "--names", NULL, "the names only, one per line"},
    [OPT_CASE] = {NULL, "--case", "TEXT", "only cases whose name contains TEXT"},
    [OPT_QUICK] = {NULL, "--quick", NULL, "reduced sizes"},
    [OPT_SAMPLE] = {NULL, "--sample", "K/M", "a deterministic sample of the runs (!K/M: the others)"},
    [OPT_TIMEOUT] = {NULL, "--timeout", "S",
                     "per-run time bound in seconds (default 120; 3x for the heavy cases: a 4096^2 image, 10^6 "
                     "triangles)"},
    [OPT_JOBS] = {NULL, "--jobs", "N", "runs at once (default 1)"},
    [OPT_LIST] = {NULL, "--list", NULL, "list and exit"},
};

static bool parse_int(const char *opt, const char *s, int lo, int hi, int *out, Error *err)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || v < lo || v > hi)
        return error_set(err, "%s expects an integer in [%d, %d], got '%s'", opt, lo, hi, s);
    *out = (int)v;
    return true;
}

/* --sample "K/M" with 0 <= K < M <= 64, or "!K/M" for its complement. */
static bool parse_sample(const char *a, const char *v, int *k, int *m, bool *invert, Error *err)
{
    const char *text = v;
    *invert = v[0] == '!';
    v += *invert;
    char *end;
    long kk = strtol(v, &end, 10), mm = 0;
    if (end != v && *end == '/') {
        const char *mv = end + 1;
        mm = strtol(mv, &end, 10);
        if (end == mv) mm = 0;
    }
    if (*end != '\0' || mm < 1 || mm > 64 || kk < 0 || kk >= mm)
        return error_set(err, "%s expects K/M or !K/M with 0 <= K < M <= 64, got '%s'", a, text);
    *k = (int)kk;
    *m = (int)mm;
    return true;
}

static bool parse_seconds(const char *opt, const char *s, double lo, double hi, double *out, Error *err)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end != '\0' || !(v >= lo && v <= hi))
        return error_set(err, "%s expects a number of seconds in [%g, %g], got '%s'", opt, lo, hi, s);
    *out = v;
    return true;
}

static bool push(const char **list, int *n, const char *opt, const char *value, Error *err)
{
    if (*n >= CLI_MAX_ASSIGN) return error_set(err, "more than %d %s options", CLI_MAX_ASSIGN, opt);
    list[(*n)++] = value;
    return true;
}

/* Store option `id`'s value v (NULL for flags) in o. */
static bool apply(CliOpt id, const char *a, const char *v, CliOptions *o, Error *err)
{
    int seed;
    switch (id) {
    case OPT_TECHNIQUE: o->technique = v; return true;
    case OPT_PARAM: return push(o->params, &o->num_params, a, v, err);
    case OPT_SET: return push(o->overrides, &o->num_overrides, a, v, err);
    case OPT_LIGHT: return parse_int(a, v, 1, 64, &o->light, err);
    case OPT_SAMPLES: return parse_int(a, v, 1, REFERENCE_MAX_SAMPLES, &o->ref.samples, err);
    case OPT_PATTERN: return sampling_pattern_parse(v, &o->ref.pattern, err);
    case OPT_SEED:
        if (!parse_int(a, v, 0, 2147483647, &seed, err)) return false;
        o->ref.seed = (uint32_t)seed;
        return true;
    case OPT_SAMPLE_SET:
        if (strcmp(v, "per_view_sample") != 0 && strcmp(v, "shared") != 0)
            return error_set(err, "%s '%s' is not one of: per_view_sample, shared", a, v);
        o->ref.shared_set = strcmp(v, "shared") == 0;
        return true;
    case OPT_MEASURE: return measure_parse(v, &o->ref.measure, err);
    case OPT_CACHE: o->cache_dir = v; return true;
    case OPT_NO_CACHE: o->no_cache = true; return true;
    case OPT_REPEAT: return parse_int(a, v, 1, 10000, &o->repeat, err);
    case OPT_WARMUP: return parse_int(a, v, 0, 1000, &o->warmup, err);
    case OPT_THREADS: return parse_int(a, v, 1, 1024, &o->threads, err);
    case OPT_OUT: o->out_dir = v; return true;
    case OPT_NO_PNG: o->no_png = true; return true;
    case OPT_FRUSTUM: return parse_int(a, v, 0, 256, &o->frustum, err);
    case OPT_JSON: o->json = true; return true;
    case OPT_MARKDOWN: o->markdown = true; return true;
    case OPT_README: o->readme = true; return true;
    case OPT_NAMES: o->names = true; return true;
    case OPT_CASE: o->case_filter = v; return true;
    case OPT_QUICK: o->quick = true; return true;
    case OPT_SAMPLE: return parse_sample(a, v, &o->sample_k, &o->sample_m, &o->sample_invert, err);
    case OPT_TIMEOUT: return parse_seconds(a, v, 1, 86400, &o->timeout_s, err);
    case OPT_JOBS: return parse_int(a, v, 1, 16, &o->jobs, err);
    case OPT_LIST: o->list = true; return true;
    case OPT_END: case OPT_COUNT: break;
    }
    return error_set(err, "internal: option %d has no parser", (int)id);
}

static CliOpt lookup(const char *a)
{
    for (int id = OPT_END + 1; id < OPT_COUNT; id++)
        if ((opts[id].short_name && strcmp(a, opts[id].short_name) == 0) || strcmp(a, opts[id].long_name) == 0)
            return (CliOpt)id;
    return OPT_END;
}

static bool accepts(const CliCommand *cmd, CliOpt id)
{
    for (const CliAccept *c = cmd->options; c->opt != OPT_END; c++)
        if (c->opt == id) return true;
    return false;
}

static bool parse_option(const CliCommand *cmd, char **argv, int *i, int argc, CliOptions *o, Error *err)
{
    const char *a = argv[*i];
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
        o->help = true;
        return true;
    }
    CliOpt id = lookup(a);
    if (id == OPT_END) return error_set(err, "unknown option '%s' (see shadowlab %s --help)", a, cmd->name);
    if (!accepts(cmd, id))
        return error_set(err, "option '%s' does not apply to `shadowlab %s` (see shadowlab %s --help)", a, cmd->name,
                         cmd->name);
    const char *v = NULL;
    if (opts[id].value) {
        if (*i + 1 >= argc) return error_set(err, "%s expects a value (%s)", a, opts[id].value);
        v = argv[++*i];
    }
    o->given |= 1ull << id;
    return apply(id, a, v, o, err);
}

bool cli_parse(const CliCommand *cmd, int argc, char **argv, CliOptions *o, Error *err)
{
    memset(o, 0, sizeof *o);
    o->repeat = 1;
    o->light = 1;
    o->frustum = 24;
    o->ref = (ReferenceParams){MEASURE_VISIBILITY, 1024, SAMPLING_R2, 1, false};
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1] != '\0') {
            if (!parse_option(cmd, argv, &i, argc, o, err)) return false;
        } else if (cmd->needs_scene && !o->scene) {
            o->scene = argv[i];
        } else {
            return error_set(err, "unexpected argument '%s'", argv[i]);
        }
    }
    if (cmd->needs_scene && !o->scene && !o->help)
        return error_set(err, "missing SCENE (a scene file, e.g. scenes/sphere-on-plane.lua)");
    return true;
}

bool cli_given(const CliOptions *o, CliOpt opt) { return (o->given >> opt) & 1u; }

/* A help text with '\n' continuation lines indented under the first. */
static void print_help_text(const char *text, FILE *fp)
{
    for (const char *s = text; *s; s++) {
        fputc(*s, fp);
        if (*s == '\n') fprintf(fp, "%25s", "");
    }
    fputc('\n', fp);
}

void cli_print_help(const CliCommand *cmd, FILE *fp)
{
    fprintf(fp, "usage: shadowlab %s %s\n", cmd->name, cmd->usage);
    if (cmd->about) fputs(cmd->about, fp);
    for (const CliAccept *c = cmd->options; c->opt != OPT_END; c++) {
        const OptDesc *d = &opts[c->opt];
        char left[64];
        snprintf(left, sizeof left, "%s%s%s%s%s", d->short_name ? d->short_name : "", d->short_name ? ", " : "",
                 d->long_name, d->value ? " " : "", d->value ? d->value : "");
        fprintf(fp, "  %-22s ", left);
        print_help_text(c->help ? c->help : d->help, fp);
    }
    fprintf(fp, "  %-22s this help\n", "-h, --help");
}

void cli_apply_threads(const CliOptions *o)
{
    if (o->threads > 0) omp_set_num_threads(o->threads);
    rt_set_threads(o->threads > 0 ? o->threads : omp_get_max_threads());
}
