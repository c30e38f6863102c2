/* cli.h -- the command-line front end: option parsing shared by every
 * command, and the commands themselves (list, render, reference, compare).
 * Exit status: 0 success, 1 runtime error, 2 usage error. */
#ifndef SL_CLI_H
#define SL_CLI_H
#include "lab/report.h"

enum { EXIT_OK = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2 };

#define CLI_MAX_ASSIGN 64

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
    bool no_cache, no_png, json, names, markdown, help;
} CliOptions;

/* Parse argv after the command name; usage errors are reported in err.
 * `needs_scene` requires one positional SCENE argument. */
bool cli_parse(int argc, char **argv, bool needs_scene, CliOptions *o, Error *err);
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
