/* luaread.c -- validated Lua table fields with key paths (see luaread.h). */
#include "scene/luaread.h"
#include <lauxlib.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const char *key_path(LuaReader *r, const char *key, char *buf, size_t n)
{
    if (!key) return r->path[0] ? r->path : "(scene)";
    snprintf(buf, n, "%s%s%s", r->path, r->path[0] ? "." : "", key);
    return buf;
}

bool rd_fail(LuaReader *r, const char *key, const char *fmt, ...)
{
    char where[600], msg[ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* "key = 3 outside ..." reads with a space; "key: <nested error>" without. */
    const char *sep = msg[0] == ':' ? "" : " ";
    return error_set(r->err, "%s: %s%s%s", r->file, key_path(r, key, where, sizeof where), sep, msg);
}

size_t rd_enter_key(LuaReader *r, const char *key)
{
    size_t n = strlen(r->path);
    snprintf(r->path + n, sizeof r->path - n, "%s%s", n ? "." : "", key);
    return n;
}

size_t rd_enter_index(LuaReader *r, int index)
{
    size_t n = strlen(r->path);
    snprintf(r->path + n, sizeof r->path - n, "[%d]", index);
    return n;
}

void rd_leave(LuaReader *r, size_t saved) { r->path[saved] = '\0'; }

static bool in_list(const char *s, const char *const *list)
{
    for (; *list; list++)
        if (strcmp(s, *list) == 0) return true;
    return false;
}

static void join_list(const char *const *list, char *buf, size_t n)
{
    buf[0] = '\0';
    for (size_t used = 0; *list && used + 2 < n; list++) {
        used += (size_t)snprintf(buf + used, n - used, "%s%s", used ? ", " : "", *list);
    }
}

bool rd_only_keys(LuaReader *r, int idx, const char *const *allowed)
{
    lua_State *L = r->L;
    idx = lua_absindex(L, idx);
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        lua_pop(L, 1);
        if (lua_type(L, -1) != LUA_TSTRING || !in_list(lua_tostring(L, -1), allowed)) {
            char valid[400], key[64];
            join_list(allowed, valid, sizeof valid);
            if (lua_type(L, -1) == LUA_TSTRING) snprintf(key, sizeof key, "%s", lua_tostring(L, -1));
            else snprintf(key, sizeof key, "[%s]", luaL_tolstring(L, -1, NULL));
            lua_settop(L, idx);
            return rd_fail(r, key, "is not a valid key here (valid: %s)", valid);
        }
    }
    return true;
}

/* Enter the path step of the key at the top of the stack (a string, an
 * integer index, or any other key by its type name). */
static size_t enter_any_key(LuaReader *r)
{
    lua_State *L = r->L;
    if (lua_type(L, -1) == LUA_TSTRING) return rd_enter_key(r, lua_tostring(L, -1));
    if (lua_isinteger(L, -1) && lua_tointeger(L, -1) >= INT_MIN && lua_tointeger(L, -1) <= INT_MAX)
        return rd_enter_index(r, (int)lua_tointeger(L, -1));
    size_t n = strlen(r->path);
    snprintf(r->path + n, sizeof r->path - n, "[%s key]", luaL_typename(L, -1));
    return n;
}

/* The walk behind rd_refuse_metatables: `seen` (a table at stack index
 * seen_idx) holds the tables already checked, so shared and cyclic tables are
 * walked once. The key path names the table being checked. */
static bool refuse_metatables_at(LuaReader *r, int idx, int seen_idx, int depth)
{
    lua_State *L = r->L;
    if (lua_getmetatable(L, idx)) {
        lua_pop(L, 1);
        return rd_fail(r, NULL, "has a metatable: metatables are not allowed in scene tables (their metamethods "
                                "would run while the scene is read)");
    }
    if (depth > RD_MAX_DEPTH) return rd_fail(r, NULL, "nests tables deeper than %d levels", RD_MAX_DEPTH);
    lua_pushvalue(L, idx);
    if (lua_rawget(L, seen_idx) != LUA_TNIL) { lua_pop(L, 1); return true; }
    lua_pop(L, 1);
    lua_pushvalue(L, idx);
    lua_pushboolean(L, 1);
    lua_rawset(L, seen_idx);
    luaL_checkstack(L, 4, "scene tables nest too deeply");
    lua_pushnil(L);
    while (lua_next(L, idx)) { /* key at -2, value at -1 */
        int top = lua_gettop(L);
        lua_pushvalue(L, top - 1);
        size_t saved = enter_any_key(r);
        lua_pop(L, 1);
        bool ok = (lua_type(L, top - 1) != LUA_TTABLE || refuse_metatables_at(r, top - 1, seen_idx, depth + 1)) &&
                  (lua_type(L, top) != LUA_TTABLE || refuse_metatables_at(r, top, seen_idx, depth + 1));
        rd_leave(r, saved);
        if (!ok) return false;
        lua_settop(L, top - 1);
    }
    return true;
}

bool rd_refuse_metatables(LuaReader *r, int idx)
{
    lua_State *L = r->L;
    int top = lua_gettop(L);
    idx = lua_absindex(L, idx);
    lua_newtable(L);
    bool ok = refuse_metatables_at(r, idx, lua_gettop(L), 0);
    lua_settop(L, top);
    return ok;
}

bool rd_get(LuaReader *r, int idx, const char *key)
{
    if (lua_getfield(r->L, idx, key) != LUA_TNIL) return true;
    lua_pop(r->L, 1);
    return false;
}

static bool in_range(double v, Range g)
{
    bool lo_ok = g.lo_open ? v > g.lo : v >= g.lo;
    bool hi_ok = g.hi_open ? v < g.hi : v <= g.hi;
    return isfinite(v) && lo_ok && hi_ok;
}

static void range_text(Range g, char *buf, size_t n)
{
    snprintf(buf, n, "%c%g, %g%c", g.lo_open ? '(' : '[', g.lo, g.hi, g.hi_open ? ')' : ']');
}

/* Number on top of the stack (popped), checked against range. */
static bool pop_number(LuaReader *r, const char *key, Range range, double *out)
{
    int isnum;
    double v = lua_tonumberx(r->L, -1, &isnum);
    const char *type = luaL_typename(r->L, -1);
    lua_pop(r->L, 1);
    if (!isnum) return rd_fail(r, key, "is a %s, expected a number", type);
    if (!in_range(v, range)) {
        char rt[80];
        range_text(range, rt, sizeof rt);
        return rd_fail(r, key, "= %g outside %s", v, rt);
    }
    *out = v;
    return true;
}

bool rd_number(LuaReader *r, int idx, const char *key, Range range, bool required, double def, double *out)
{
    if (!rd_get(r, idx, key)) {
        if (required) return rd_fail(r, key, "is missing");
        *out = def;
        return true;
    }
    if (lua_type(r->L, -1) != LUA_TNUMBER) {
        const char *type = luaL_typename(r->L, -1);
        lua_pop(r->L, 1);
        return rd_fail(r, key, "is a %s, expected a number", type);
    }
    return pop_number(r, key, range, out);
}

bool rd_int(LuaReader *r, int idx, const char *key, int lo, int hi, bool required, int def, int *out)
{
    double v;
    if (!rd_number(r, idx, key, RANGE_CLOSED(lo, hi), required, def, &v)) return false;
    if (v != floor(v)) return rd_fail(r, key, "= %g is not an integer in [%d, %d]", v, lo, hi);
    *out = (int)v;
    return true;
}

bool rd_bool(LuaReader *r, int idx, const char *key, bool def, bool *out)
{
    *out = def;
    if (!rd_get(r, idx, key)) return true;
    if (!lua_isboolean(r->L, -1)) {
        const char *type = luaL_typename(r->L, -1);
        lua_pop(r->L, 1);
        return rd_fail(r, key, "is a %s, expected true or false", type);
    }
    *out = lua_toboolean(r->L, -1);
    lua_pop(r->L, 1);
    return true;
}

bool rd_string(LuaReader *r, int idx, const char *key, const char *def, char *out, size_t n)
{
    if (!rd_get(r, idx, key)) {
        snprintf(out, n, "%s", def ? def : "");
        return true;
    }
    if (lua_type(r->L, -1) != LUA_TSTRING) {
        const char *type = luaL_typename(r->L, -1);
        lua_pop(r->L, 1);
        return rd_fail(r, key, "is a %s, expected a string", type);
    }
    size_t len;
    const char *s = lua_tolstring(r->L, -1, &len);
    bool fits = len < n;
    if (fits) memcpy(out, s, len + 1);
    lua_pop(r->L, 1);
    if (!fits) return rd_fail(r, key, "is longer than %zu characters", n - 1);
    return true;
}

bool rd_enum(LuaReader *r, int idx, const char *key, const char *const *names, bool required, int def, int *out)
{
    char s[64], valid[400];
    *out = def;
    join_list(names, valid, sizeof valid);
    if (!rd_get(r, idx, key)) return required ? rd_fail(r, key, "is missing (one of: %s)", valid) : true;
    lua_pop(r->L, 1);
    if (!rd_string(r, idx, key, NULL, s, sizeof s)) return false;
    for (int i = 0; names[i]; i++) {
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return true;
        }
    }
    return rd_fail(r, key, "= \"%s\" is not one of: %s", s, valid);
}

/* Read the list of n numbers on top of the stack (popped), named key. */
static bool rd_array(LuaReader *r, const char *key, Range range, int n, double *out)
{
    lua_State *L = r->L;
    if (!lua_istable(L, -1) || (int)lua_rawlen(L, -1) != n) {
        lua_pop(L, 1);
        return rd_fail(r, key, "must be a list of %d numbers", n);
    }
    size_t saved = rd_enter_key(r, key);
    bool ok = true;
    for (int i = 0; ok && i < n; i++) {
        size_t inner = rd_enter_index(r, i + 1);
        lua_rawgeti(L, -1, i + 1);
        if (lua_type(L, -1) != LUA_TNUMBER) {
            const char *type = luaL_typename(L, -1);
            lua_pop(L, 1);
            ok = rd_fail(r, NULL, "is a %s, expected a number", type);
        } else {
            ok = pop_number(r, NULL, range, &out[i]);
        }
        rd_leave(r, inner);
    }
    rd_leave(r, saved);
    lua_pop(L, 1);
    return ok;
}

bool rd_vec3(LuaReader *r, int idx, const char *key, Range range, bool required, vec3 def, vec3 *out)
{
    *out = def;
    if (!rd_get(r, idx, key)) return required ? rd_fail(r, key, "is missing") : true;
    double v[3];
    if (!rd_array(r, key, range, 3, v)) return false;
    *out = v3((float)v[0], (float)v[1], (float)v[2]);
    return true;
}

bool rd_vec2(LuaReader *r, int idx, const char *key, Range range, bool required, const double def[2], double out[2])
{
    out[0] = def[0];
    out[1] = def[1];
    if (!rd_get(r, idx, key)) return required ? rd_fail(r, key, "is missing") : true;
    return rd_array(r, key, range, 2, out);
}
