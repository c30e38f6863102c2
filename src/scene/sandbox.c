/* sandbox.c -- the restricted Lua state behind scene files (see sandbox.h).
 * Limits: a counting allocator refuses growth past SANDBOX_MEMORY_LIMIT and a
 * count hook raises an error past SANDBOX_INSTRUCTION_LIMIT instructions (C
 * library loops charged as instructions) or SANDBOX_TIME_LIMIT_S seconds. */
#include "scene/sandbox.h"
#include <ctype.h>
#include <lauxlib.h>
#include <lualib.h>
#include <stdlib.h>
#include <string.h>
#include "core/timer.h"

#define HOOK_EVERY 1000

struct Sandbox {
    lua_State *L;
    size_t mem_used;
    long instructions;
    double start_s;
};

static void *sandbox_alloc(void *ud, void *ptr, size_t osize, size_t nsize)
{
    Sandbox *sb = ud;
    size_t old = ptr ? osize : 0;
    if (nsize == 0) {
        free(ptr);
        sb->mem_used -= old;
        return NULL;
    }
    if (nsize > old && sb->mem_used - old + nsize > SANDBOX_MEMORY_LIMIT) return NULL;
    void *p = realloc(ptr, nsize);
    if (p) sb->mem_used = sb->mem_used - old + nsize;
    return p;
}

static Sandbox *sandbox_of(lua_State *L)
{
    void *sb;
    lua_getallocf(L, &sb);
    return sb;
}

static void count_hook(lua_State *L, lua_Debug *ar);

/* Add `work` to the budget; past a limit, raise, and arm the hook on every
 * instruction so that the error escapes any pcall around it. */
static void charge(lua_State *L, long work)
{
    Sandbox *sb = sandbox_of(L);
    sb->instructions += work <= SANDBOX_INSTRUCTION_LIMIT ? work : SANDBOX_INSTRUCTION_LIMIT + 1;
    bool over_count = sb->instructions > SANDBOX_INSTRUCTION_LIMIT;
    if (!over_count && timer_now_s() - sb->start_s <= SANDBOX_TIME_LIMIT_S) return;
    lua_sethook(L, count_hook, LUA_MASKCOUNT, 1);
    if (over_count)
        luaL_error(L, "instruction limit exceeded (%d million): does the scene loop forever?",
                   (int)(SANDBOX_INSTRUCTION_LIMIT / 1000000));
    luaL_error(L, "time limit exceeded (%.0f s): does the scene loop forever?", SANDBOX_TIME_LIMIT_S);
}

static void count_hook(lua_State *L, lua_Debug *ar)
{
    (void)ar;
    charge(L, HOOK_EVERY);
}

/* Call the wrapped library function (upvalue 1) with this call's arguments. */
static int call_wrapped(lua_State *L)
{
    int n = lua_gettop(L);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, n, LUA_MULTRET);
    return lua_gettop(L);
}

/* string.rep loops n times in C, even for an empty string. */
static int rep_charged(lua_State *L)
{
    lua_Integer n = lua_tointeger(L, 2);
    charge(L, n > 0 ? (long)(n <= SANDBOX_INSTRUCTION_LIMIT ? n : SANDBOX_INSTRUCTION_LIMIT + 1) : 0);
    return call_wrapped(L);
}

/* table.insert(t, pos, v) and table.remove(t, pos) shift up to #t elements
 * in C, and #t can be a border far beyond the table's real size. */
static int shift_charged(lua_State *L)
{
    lua_Integer len = lua_gettop(L) >= 2 && lua_istable(L, 1) ? luaL_len(L, 1) : 0;
    charge(L, len > 0 ? (long)(len <= SANDBOX_INSTRUCTION_LIMIT ? len : SANDBOX_INSTRUCTION_LIMIT + 1) : 0);
    return call_wrapped(L);
}

/* Finalizers run during garbage collection with hooks off: refused. */
static int setmetatable_checked(lua_State *L)
{
    if (lua_istable(L, 2)) {
        lua_pushliteral(L, "__gc");
        bool has_gc = lua_rawget(L, 2) != LUA_TNIL;
        lua_pop(L, 1);
        if (has_gc) return luaL_error(L, "setmetatable: __gc (finalizers) is not allowed in scene files");
    }
    return call_wrapped(L);
}

static void wrap(lua_State *L, const char *lib, const char *name, lua_CFunction fn)
{
    lua_getglobal(L, lib);
    lua_getfield(L, -1, name);
    lua_pushcclosure(L, fn, 1);
    lua_setfield(L, -2, name);
    lua_pop(L, 1);
}

static void remove_field(lua_State *L, const char *lib, const char *name)
{
    lua_getglobal(L, lib);
    lua_pushnil(L);
    lua_setfield(L, -2, name);
    lua_pop(L, 1);
}

static void open_safe_libs(lua_State *L)
{
    static const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},       {LUA_MATHLIBNAME, luaopen_math},
                                    {LUA_STRLIBNAME, luaopen_string}, {LUA_TABLIBNAME, luaopen_table},
                                    {LUA_UTF8LIBNAME, luaopen_utf8}};
    for (size_t i = 0; i < sizeof libs / sizeof libs[0]; i++) {
        luaL_requiref(L, libs[i].name, libs[i].func, 1);
        lua_pop(L, 1);
    }
    /* Code loading, output, and C loops the instruction count cannot bound. */
    static const char *const unsafe[][2] = {
        {LUA_GNAME, "dofile"},  {LUA_GNAME, "loadfile"},  {LUA_GNAME, "load"},     {LUA_GNAME, "require"},
        {LUA_GNAME, "collectgarbage"}, {LUA_GNAME, "print"}, {LUA_GNAME, "warn"},
        {LUA_STRLIBNAME, "dump"}, {LUA_STRLIBNAME, "find"}, {LUA_STRLIBNAME, "match"},
        {LUA_STRLIBNAME, "gmatch"}, {LUA_STRLIBNAME, "gsub"}, {LUA_TABLIBNAME, "move"}};
    for (size_t i = 0; i < sizeof unsafe / sizeof unsafe[0]; i++) remove_field(L, unsafe[i][0], unsafe[i][1]);
    wrap(L, LUA_STRLIBNAME, "rep", rep_charged);
    wrap(L, LUA_TABLIBNAME, "insert", shift_charged);
    wrap(L, LUA_TABLIBNAME, "remove", shift_charged);
    wrap(L, LUA_GNAME, "setmetatable", setmetatable_checked);
    /* Deterministic scenes: math.random is seeded with a fixed value. */
    if (luaL_dostring(L, "math.randomseed(20090101)") != LUA_OK) lua_pop(L, 1);
}

Sandbox *sandbox_open(Error *err)
{
    Sandbox *sb = calloc(1, sizeof *sb);
    if (!sb) { error_set(err, "out of memory"); return NULL; }
    sb->L = lua_newstate(sandbox_alloc, sb);
    if (!sb->L) { free(sb); error_set(err, "cannot create Lua state"); return NULL; }
    sb->start_s = timer_now_s();
    open_safe_libs(sb->L);
    lua_sethook(sb->L, count_hook, LUA_MASKCOUNT, HOOK_EVERY);
    return sb;
}

void sandbox_close(Sandbox *sb)
{
    if (!sb) return;
    lua_close(sb->L);
    free(sb);
}

lua_State *sandbox_state(Sandbox *sb) { return sb->L; }

/* Run the function on the stack; errors are prefixed with the file when Lua
 * gave no position (errors raised from the hook or the allocator). */
static bool pcall_or_error(lua_State *L, const char *path, int nargs, int nres, Error *err)
{
    int st = lua_pcall(L, nargs, nres, 0);
    if (st == LUA_OK) return true;
    const char *msg = lua_tostring(L, -1);
    if (st == LUA_ERRMEM)
        error_set(err, "%s: out of memory: the scene exceeds the sandbox's %zu MiB limit", path,
                  SANDBOX_MEMORY_LIMIT >> 20);
    else if (msg && strncmp(msg, path, strlen(path)) == 0) error_set(err, "%s", msg);
    else error_set(err, "%s: %s", path, msg ? msg : "error (no message)");
    lua_pop(L, 1);
    return false;
}

bool sandbox_run_file(Sandbox *sb, const char *path, Error *err)
{
    lua_State *L = sb->L;
    int st = luaL_loadfilex(L, path, "t");
    if (st != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        error_set(err, "%s", msg ? msg : path);
        lua_pop(L, 1);
        return false;
    }
    if (!pcall_or_error(L, path, 0, 1, err)) return false;
    if (!lua_istable(L, -1)) {
        lua_pop(L, 1);
        return error_set(err, "%s: the scene file must return a table", path);
    }
    return true;
}

bool sandbox_protected(Sandbox *sb, lua_CFunction fn, void *ud, const char *path, Error *err)
{
    lua_State *L = sb->L;
    int table = lua_gettop(L);
    if (!lua_checkstack(L, 3)) return error_set(err, "%s: out of Lua stack", path);
    lua_pushcfunction(L, fn);
    lua_pushvalue(L, table);
    lua_pushlightuserdata(L, ud);
    return pcall_or_error(L, path, 2, 0, err);
}

/* Push the value of an override's right-hand side. */
static void push_override_value(lua_State *L, const char *text)
{
    char chunk[1100];
    snprintf(chunk, sizeof chunk, "return %s", text);
    int top = lua_gettop(L);
    if (luaL_loadbufferx(L, chunk, strlen(chunk), "=override", "t") == LUA_OK &&
        lua_pcall(L, 0, 1, 0) == LUA_OK && !lua_isnil(L, -1))
        return;
    lua_settop(L, top);
    lua_pushstring(L, text);
}

/* Parse one path step at *s: ".name", "name" (first) or "[N]"; pushes the
 * key. Returns false on a malformed path. */
static bool push_path_key(lua_State *L, const char **s, bool first)
{
    const char *p = *s;
    if (*p == '[') {
        char *end;
        long i = strtol(p + 1, &end, 10);
        if (end == p + 1 || *end != ']') return false;
        lua_pushinteger(L, i);
        *s = end + 1;
        return true;
    }
    if (!first) {
        if (*p != '.') return false;
        p++;
    }
    const char *start = p;
    while (isalnum((unsigned char)*p) || *p == '_') p++;
    if (p == start) return false;
    lua_pushlstring(L, start, (size_t)(p - start));
    *s = p;
    return true;
}

bool sandbox_apply_override(Sandbox *sb, const char *spec, Error *err)
{
    lua_State *L = sb->L;
    const char *eq = strchr(spec, '=');
    if (!eq || eq == spec || strlen(spec) > 1000)
        return error_set(err, "override '%s': expected key.path=value", spec);
    char path[1024];
    snprintf(path, sizeof path, "%.*s", (int)(eq - spec), spec);
    int top = lua_gettop(L);
    lua_pushvalue(L, -1); /* the table being walked */
    const char *s = path;
    for (bool first = true;; first = false) {
        if (!push_path_key(L, &s, first)) {
            lua_settop(L, top);
            return error_set(err, "override '%s': malformed key path near '%s'", spec, s);
        }
        if (*s == '\0') break;
        lua_rawget(L, -2);
        if (!lua_istable(L, -1)) {
            lua_settop(L, top);
            return error_set(err, "override '%s': '%.*s' is not a table in the scene", spec, (int)(s - path), path);
        }
        lua_remove(L, -2);
    }
    push_override_value(L, eq + 1);
    lua_rawset(L, -3);
    lua_settop(L, top);
    return true;
}

bool sandbox_call_number(Sandbox *sb, int fn_idx, const double *args, int nargs, double *out, Error *err)
{
    lua_State *L = sb->L;
    fn_idx = lua_absindex(L, fn_idx);
    lua_pushvalue(L, fn_idx);
    for (int i = 0; i < nargs; i++) lua_pushnumber(L, args[i]);
    if (!pcall_or_error(L, "function", nargs, 1, err)) return false;
    int isnum;
    *out = lua_tonumberx(L, -1, &isnum);
    if (!isnum) error_set(err, "function returned a %s, expected a number", luaL_typename(L, -1));
    lua_pop(L, 1);
    return isnum != 0;
}
