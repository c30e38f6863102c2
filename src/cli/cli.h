/* cli.h -- the command-line front end: option parsing shared by every
 * command, and the commands themselves (list, render, reference, compare).
 * Each command declares the options that act on it (a CliCommand); the
 * parser refuses any other and --help lists exactly those.
 * Exit status: 0 success, 1 runtime error, 2 usage error. */
#ifndef SL_CLI_H
#define SL_CLI_H
#include "lab/report.h"

enum { EXIT_OK = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2 };

#define CLI_MAX_ASSIGN 64

/* Every option of any command; a command accepts a subset (CliAccept). */
typedef enum CliOpt {
    OPT_END, /* ends a CliAccept table */
    OPT_TECHNIQUE, OPT_PARAM, OPT_SET, OPT_LIGHT,
    OPT_SAMPLES, OPT_PATTERN, OPT_SEED, OPT_SAMPLE_SET, OPT_MEASURE, OPT_CACHE, OPT_NO_CACHE,
    OPT_REPEAT, OPT_WARMUP, OPT_THREADS, OPT_OUT, OPT_NO_PNG, OPT_FRUSTUM,
    OPT_JSON, OPT_MARKDOWN, OPT_README, OPT_NAMES,
    OPT_CASE, OPT_QUICK, OPT_SAMPLE, OPT_TIMEOUT, OPT_JOBS, OPT_LIST,
    OPT_COUNT
} CliOpt;

/* One accepted option and its help line for this command (NULL: the
 * option's own line, args.c); a '\n' in it starts an indented line. */
typedef struct CliAccept {
    CliOpt opt;
    const char *help;
} CliAccept;

typedef struct CliCommand {
    const char *name;
    const char *usage;          /* after "usage: shadowlab NAME " */
    bool needs_scene;           /* one positional SCENE */
    const CliAccept *options;   /* OPT_END-terminated; --help is always accepted */
    const char *about;          /* lines printed under the usage line; NULL: none */
} CliCommand;

typedef struct CliOptions {
    const char *scene;
    const char *technique;
    const char *params[CLI_MAX_ASSIGN];
    int num_params;
    const char *overrides[CLI_MAX_ASSIGN];
    int num_overrides;
    const char *out_dir;
    int threads, repeat, light;
    int warmup;            /* untimed evaluations before the timed ones */
    ReferenceParams ref;
    const char *cache_dir; /* NULL: default */
    bool no_cache, no_png, json, names, markdown, readme, help;
    int frustum;           /* aliasing: Lloyd's measure at N^3 points (default 24, 0: off) */
    const char *case_filter; /* stability: cases whose name contains this */
    bool quick, list;      /* stability */
    double timeout_s;      /* stability: per run (0: the suite's default) */
    int jobs;              /* stability: runs at once (0: 1) */
    int sample_k, sample_m; /* stability: --sample K/M, the runs of hash class K of M (m 0: all) */
    bool sample_invert;     /* --sample !K/M: the runs of every class but K */
    unsigned long long given; /* bit (1ull << CliOpt) of every option given */
} CliOptions;

/* Parse argv after the command name against the command's table; usage
 * errors (an option the command does not take, a bad value, a missing
 * SCENE) are reported in err, naming the option and the command. */
bool cli_parse(const CliCommand *cmd, int argc, char **argv, CliOptions *o, Error *err);
bool cli_given(const CliOptions *o, CliOpt opt);
/* "usage: shadowlab NAME USAGE", `about`, then one line per accepted option. */
void cli_print_help(const CliCommand *cmd, FILE *fp);
void cli_apply_threads(const CliOptions *o);

int cmd_list(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_reference(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_stability(int argc, char **argv); /* stability.c: the extreme-case suite */
int cmd_run(int argc, char **argv);   /* script.c: a Lua script with the shadowlab module */
int cmd_merge(int argc, char **argv); /* merge.c: shard records into one results folder */
int cmd_aliasing(int argc, char **argv); /* aliasing.c: the sampling-error analysis of a map (course §3.1) */
/* Run require(module).main(...) with the command's arguments; its integer result is the exit status. */
int cli_lua_module_main(const char *command, const char *module, int argc, char **argv);

#endif
