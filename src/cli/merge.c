/* merge.c -- `shadowlab merge [-o OUT] DIR...`: the records of a sweep's
 * shards (--shard I/N) merged into one results folder, refusing duplicate
 * configurations and shards of different experiments. The work is Lua
 * (lua/shadowlab/merge.lua, on the same records reader as --resume). */
#include "cli/cli.h"

int cmd_merge(int argc, char **argv) { return cli_lua_module_main("merge", "shadowlab.merge", argc - 1, argv + 1); }
