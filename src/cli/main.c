/* main.c -- shadowlab: dispatch to a command. */
#include <stdio.h>
#include <string.h>
#include "cli/cli.h"

static const struct { const char *name; int (*run)(int, char **); const char *summary; } commands[] = {
    {"list", cmd_list, "list techniques and their parameters (--json for machines)"},
    {"render", cmd_render, "render a technique's visibility for a scene"},
    {"reference", cmd_reference, "compute (or load from cache) the Embree ground truth"},
    {"compare", cmd_compare, "render, reference, metrics and every output"},
    {"stability", cmd_stability, "every technique on every extreme case: finite, in [0,1], clear refusals"},
    {"run", cmd_run, "run a Lua script or experiment (sweeps, records, reports)"},
    {"merge", cmd_merge, "merge the records of a sweep's shards (--shard I/N)"},
    {"aliasing", cmd_aliasing, "shadow-map sampling error of a technique's map: error maps, histogram, storage factor"},
};
#define NUM_COMMANDS (int)(sizeof commands / sizeof commands[0])

static void usage(FILE *fp)
{
    fprintf(fp, "usage: shadowlab COMMAND [options]   (shadowlab COMMAND --help for details)\n\ncommands:\n");
    for (int i = 0; i < NUM_COMMANDS; i++) fprintf(fp, "  %-10s %s\n", commands[i].name, commands[i].summary);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return EXIT_OK;
    }
    for (int i = 0; i < NUM_COMMANDS; i++)
        if (strcmp(argv[1], commands[i].name) == 0) return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "shadowlab: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return EXIT_USAGE;
}
