/* script.c -- `shadowlab run [--threads N] SCRIPT.lua [ARGS...]`: a Lua 5.4
 * interpreter with the shadowlab module loaded (src/lua/), the project's lua/
 * folder on package.path, and `arg` set as lua5.4 sets it (arg[0] the
 * script, arg[1..] its arguments). A Lua error exits 1 with its message (and
 * a traceback when it is the lab's own, see internal_error); the script's result is its exit status (nil: 0). The same
 * interpreter runs the Lua side of `merge`. */
#include <lauxlib.h>
#include <limits.h>
#include <lualib.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli/cli.h"
#include "lua/sl_lua.h"

/* ROOT = the folder above the executable's (build/shadowlab -> .). */
static void set_project_root(void)
{
    char exe[PATH_MAX], root[PATH_MAX + 4];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len <= 0) return;
    exe[len] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash) return;
    *slash = '\0';
    snprintf(root, sizeof root, "%s/..", exe);
    if (realpath(root, exe)) sl_lua_set_root(exe);
}

/* Whether an error message is the lab's own: it starts with a position in the
 * project's Lua helpers (lua/shadowlab/) or in a chunk that is not a file.
 * Errors at the user's line (the helpers raise a user's mistakes, such as a
 * parameter out of range, at the caller's level) and errors without a
 * position (a resume conflict, a refused override) are the user's. */
static bool internal_error(const char *msg)
{
    const char *colon = strchr(msg, ':');
    if (!colon || colon[1] < '0' || colon[1] > '9') return false; /* no "file:line:" position */
    size_t file_len = (size_t)(colon - msg);
    if (msg[0] == '[') return true;                               /* [C], [string "..."] */
    const char *helpers = "lua/shadowlab/";
    for (const char *p = msg; p + strlen(helpers) <= colon; p++)
        if (strncmp(p, helpers, strlen(helpers)) == 0) return true;
    return file_len == 0;
}

/* The message handler: the lab's own errors get a traceback (a bug to report);
 * a user's error prints as its message alone, pointing at their line. */
static int traceback(lua_State *L)
{
    const char *msg = lua_tostring(L, 1);
    if (!msg) msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    if (internal_error(msg)) luaL_traceback(L, L, msg, 1);
    else lua_pushstring(L, msg);
    return 1;
}

/* arg = {[0] = script, args...} */
static void set_args(lua_State *L, const char *script, int argc, char **argv)
{
    lua_createtable(L, argc, 1);
    lua_pushstring(L, script);
    lua_rawseti(L, -2, 0);
    for (int i = 0; i < argc; i++) {
        lua_pushstring(L, argv[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setglobal(L, "arg");
}

/* The exit status a script's result gives: nil (no return) 0, an integer in
 * [0, 255] itself; anything else (a string, a float, an integer a shell
 * would wrap to 0) is a mistake, never success: it prints and gives 1. */
static int exit_status_of(lua_State *L, const char *command)
{
    if (lua_isnoneornil(L, -1)) return EXIT_OK;
    if (lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 0 && lua_tointeger(L, -1) <= 255)
        return (int)lua_tointeger(L, -1);
    const char *what = luaL_tolstring(L, -1, NULL);
    fprintf(stderr, "shadowlab %s: the script returned %s (a %s), not an exit status: nil or an integer in "
                    "[0, 255]\n", command, what, luaL_typename(L, -2));
    return EXIT_RUNTIME;
}

/* Call the function on top of the stack with `arg`'s elements; the exit
 * status comes from its result (exit_status_of); errors print and give 1. */
static int call_main(lua_State *L, const char *command, int argc, char **argv)
{
    int fn = lua_gettop(L);
    lua_pushcfunction(L, traceback);
    lua_insert(L, fn);
    luaL_checkstack(L, argc, "too many arguments");
    for (int i = 0; i < argc; i++) lua_pushstring(L, argv[i]);
    if (lua_pcall(L, argc, 1, fn) != LUA_OK) {
        fprintf(stderr, "shadowlab %s: %s\n", command, lua_tostring(L, -1));
        return EXIT_RUNTIME;
    }
    return exit_status_of(L, command);
}

/* A state with the standard libraries and shadowlab; NULL (said on stderr)
 * when out of memory. */
static lua_State *open_state(const char *command)
{
    lua_State *L = luaL_newstate();
    if (!L) {
        fprintf(stderr, "shadowlab %s: cannot create a Lua state (out of memory)\n", command);
        return NULL;
    }
    luaL_openlibs(L);
    set_project_root();
    luaL_requiref(L, "shadowlab", luaopen_shadowlab, 0);
    lua_pop(L, 1);
    return L;
}

int cli_lua_module_main(const char *command, const char *module, int argc, char **argv)
{
    lua_State *L = open_state(command);
    if (!L) return EXIT_RUNTIME;
    set_args(L, command, argc, argv);
    lua_getglobal(L, "require");
    lua_pushstring(L, module);
    int status = lua_pcall(L, 1, 1, 0);
    if (status == LUA_OK) lua_getfield(L, -1, "main");
    if (status != LUA_OK || !lua_isfunction(L, -1)) {
        fprintf(stderr, "shadowlab %s: cannot load %s: %s\n", command, module,
                status != LUA_OK ? lua_tostring(L, -1) : "it has no main function");
        lua_close(L);
        return EXIT_RUNTIME;
    }
    status = call_main(L, command, argc, argv);
    lua_close(L);
    return status;
}

static const char *const run_help =
    "usage: shadowlab run [--threads N] SCRIPT.lua [ARGS...]\n"
    "  runs a Lua 5.4 script with `require \"shadowlab\"` and the helpers in lua/shadowlab/\n"
    "  (sweep, experiment, records, report, pareto, autotune) available; ARGS are in `arg`.\n"
    "  Scripts built on experiment:run take the options below (SCRIPT --help adds the script's\n"
    "  own; see README, \"The Lua lab\").\n";

/* run --help: the command, then the options of every experiment script,
 * printed from lua/shadowlab/experiment.lua's own usage (the one list). */
static int print_run_help(void)
{
    fputs(run_help, stdout);
    lua_State *L = open_state("run");
    if (!L) return EXIT_RUNTIME;
    int status = luaL_dostring(L, "io.stdout:write(require('shadowlab.experiment').usage, '\\n')");
    if (status != LUA_OK)
        fprintf(stderr, "shadowlab run: cannot list the experiment options: %s\n", lua_tostring(L, -1));
    lua_close(L);
    return status == LUA_OK ? EXIT_OK : EXIT_RUNTIME;
}

int cmd_run(int argc, char **argv)
{
    int i = 1, threads = 0;
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return print_run_help();
        char *end = NULL;
        long n = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : 0;
        if (strcmp(argv[i], "--threads") != 0 || !end || *end || n < 1 || n > 1024) {
            fprintf(stderr, "shadowlab run: %s: expected --threads N (N in [1, 1024]) or --help before SCRIPT\n",
                    argv[i]);
            return EXIT_USAGE;
        }
        threads = (int)n;
        i++;
    }
    if (i >= argc) {
        fprintf(stderr, "shadowlab run: missing SCRIPT.lua\n%s", run_help);
        return EXIT_USAGE;
    }
    CliOptions o = {.threads = threads};
    cli_apply_threads(&o);
    lua_State *L = open_state("run");
    if (!L) return EXIT_RUNTIME;
    const char *script = argv[i];
    set_args(L, script, argc - i - 1, argv + i + 1);
    int status;
    if (luaL_loadfile(L, script) != LUA_OK) {
        fprintf(stderr, "shadowlab run: %s\n", lua_tostring(L, -1));
        status = EXIT_RUNTIME;
    } else {
        status = call_main(L, "run", argc - i - 1, argv + i + 1);
    }
    lua_close(L);
    return status;
}
