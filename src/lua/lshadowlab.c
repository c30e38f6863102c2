/* lshadowlab.c -- luaopen_shadowlab: the `shadowlab` Lua 5.4 module, built
 * into the CLI (`shadowlab run SCRIPT.lua`) and as build/shadowlab.so for a
 * plain lua5.4 (`package.cpath = "build/?.so;" .. package.cpath`). It
 * registers the registry functions, sl.open (Labs), the file helpers, and
 * puts the project's lua/ folder on package.path so `shadowlab.sweep` and
 * the other pure-Lua helpers load next to it. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <limits.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/hash.h"
#include "core/machine.h"
#include "core/timer.h"
#include "lua/sl_lua.h"
#include "resources/refcache.h"
#include "rt/rt.h"
#include "version.h"

static char project_root[PATH_MAX];

void sl_lua_set_root(const char *root) { snprintf(project_root, sizeof project_root, "%s", root); }

int sl_raise(lua_State *L, const Error *err) { return luaL_error(L, "%s", err->msg); }

/* The folder of the object holding this code: build/ for shadowlab.so. When
 * the OIIO plugin's folder is not set, it is this one (lua5.4 is not next to
 * it the way build/shadowlab is). */
static void find_root(void)
{
    if (project_root[0]) return;
    Dl_info info;
    char real[PATH_MAX];
    if (!dladdr((void *)luaopen_shadowlab, &info) || !info.dli_fname || !realpath(info.dli_fname, real)) return;
    char *slash = strrchr(real, '/');
    if (!slash) return;
    *slash = '\0';
    setenv("SHADOWLAB_PLUGIN_DIR", real, 0);
    snprintf(project_root, sizeof project_root, "%s/..", real);
    if (realpath(project_root, real)) snprintf(project_root, sizeof project_root, "%s", real);
}

/* Put ROOT/lua/?.lua first on package.path unless it is there already. */
static void add_lua_path(lua_State *L)
{
    lua_getglobal(L, "package");
    if (!lua_istable(L, -1)) {
        lua_pop(L, 1);
        return;
    }
    lua_getfield(L, -1, "path");
    const char *path = lua_isstring(L, -1) ? lua_tostring(L, -1) : "";
    char entry[PATH_MAX + 16];
    snprintf(entry, sizeof entry, "%s/lua/?.lua", project_root);
    if (!strstr(path, entry)) {
        lua_pushfstring(L, "%s;%s", entry, path);
        lua_setfield(L, -3, "path");
    }
    lua_pop(L, 2);
}

/* sl.threads([n]): set the worker threads (OpenMP and Embree); returns the count. */
static int sl_threads(lua_State *L)
{
    if (!lua_isnoneornil(L, 1)) {
        lua_Integer n = luaL_checkinteger(L, 1);
        luaL_argcheck(L, n >= 1 && n <= 1024, 1, "threads outside [1, 1024]");
        omp_set_num_threads((int)n);
        rt_set_threads((int)n);
    }
    lua_pushinteger(L, omp_get_max_threads());
    return 1;
}

/* sl.hash(text): 16 hex digits of the engine's FNV-1a hash. */
static int sl_hash(lua_State *L)
{
    size_t len;
    const char *s = luaL_checklstring(L, 1, &len);
    Hasher h;
    hash_init(&h);
    hash_bytes(&h, s, len);
    char hex[17];
    hash_hex(hash_final(&h), hex);
    lua_pushstring(L, hex);
    return 1;
}

static int sl_now(lua_State *L)
{
    lua_pushnumber(L, timer_now_s());
    return 1;
}

static int sl_default_cache(lua_State *L)
{
    char dir[1024];
    refcache_default_dir(dir, sizeof dir);
    lua_pushstring(L, dir);
    return 1;
}

/* sl.machine(): what this process would record of its build and machine,
 * {commit, cpu, arch, host, threads}, the fields a record's "machine" holds:
 * experiments compare it with recorded rows before mixing new rows in. */
static int sl_machine(lua_State *L)
{
    MachineInfo m;
    machine_info(&m);
    lua_createtable(L, 0, 5);
    lua_pushstring(L, SHADOWLAB_COMMIT);
    lua_setfield(L, -2, "commit");
    lua_pushstring(L, m.cpu);
    lua_setfield(L, -2, "cpu");
    if (m.named) {
        lua_pushstring(L, m.arch);
        lua_setfield(L, -2, "arch");
        lua_pushstring(L, m.host);
        lua_setfield(L, -2, "host");
    }
    lua_pushinteger(L, omp_get_max_threads());
    lua_setfield(L, -2, "threads");
    return 1;
}

int luaopen_shadowlab(lua_State *L)
{
    static const luaL_Reg funcs[] = {
        {"techniques", sl_techniques}, {"technique", sl_technique}, {"params", sl_params},
        {"open", sl_lab_open},         {"threads", sl_threads},     {"hash", sl_hash},
        {"now", sl_now},               {"default_cache", sl_default_cache}, {"machine", sl_machine},
        {NULL, NULL},
    };
    find_root();
    add_lua_path(L);
    sl_register_lab(L);
    sl_register_aliasing(L);
    sl_register_run(L);
    sl_register_image(L);
    luaL_newlib(L, funcs);
    luaL_setfuncs(L, sl_fs_funcs, 0);
    lua_pushstring(L, project_root);
    lua_setfield(L, -2, "root");
    lua_pushstring(L, SHADOWLAB_COMMIT);
    lua_setfield(L, -2, "commit");
    return 1;
}
