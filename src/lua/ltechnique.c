/* ltechnique.c -- the technique registry seen from Lua: descriptions of every
 * technique and parameter (the same table `shadowlab list` prints), and Lua
 * tables of parameter values checked by the registry's own parser, so a
 * wrong name or value is refused with the parameter's valid range. */
#include <string.h>
#include "lua/sl_lua.h"

/* A value in its Lua form: enum name, boolean, integer or float. */
static void push_value(lua_State *L, const ParamDesc *p, double v)
{
    switch (p->type) {
    case PARAM_ENUM: lua_pushstring(L, p->choices[(int)v]); break;
    case PARAM_BOOL: lua_pushboolean(L, v != 0.0); break;
    case PARAM_INT: lua_pushinteger(L, (lua_Integer)v); break;
    case PARAM_FLOAT: lua_pushnumber(L, v); break;
    }
}

static void push_param(lua_State *L, const ParamDesc *p)
{
    char range[256];
    lua_createtable(L, 0, 9);
    lua_pushstring(L, p->name);
    lua_setfield(L, -2, "name");
    lua_pushstring(L, param_type_name(p->type));
    lua_setfield(L, -2, "type");
    push_value(L, p, p->def);
    lua_setfield(L, -2, "default");
    lua_pushnumber(L, p->min);
    lua_setfield(L, -2, "min");
    lua_pushnumber(L, p->max);
    lua_setfield(L, -2, "max");
    tech_param_range(p, range, sizeof range);
    lua_pushstring(L, range);
    lua_setfield(L, -2, "range");
    lua_pushstring(L, p->unit);
    lua_setfield(L, -2, "unit");
    lua_pushstring(L, p->doc);
    lua_setfield(L, -2, "doc");
    if (p->type == PARAM_ENUM) {
        lua_newtable(L);
        for (int c = 0; p->choices[c]; c++) {
            lua_pushstring(L, p->choices[c]);
            lua_rawseti(L, -2, c + 1);
        }
        lua_setfield(L, -2, "choices");
    }
}

static void push_string_list(lua_State *L, const char *const *items)
{
    lua_newtable(L);
    for (int i = 0; items[i]; i++) {
        lua_pushstring(L, items[i]);
        lua_rawseti(L, -2, i + 1);
    }
}

void sl_push_technique(lua_State *L, const Technique *t)
{
    lua_createtable(L, 0, 8);
    const char *fields[][2] = {{"name", t->name}, {"family", t->family}, {"source", t->source}, {"summary", t->summary}};
    for (int i = 0; i < 4; i++) {
        lua_pushstring(L, fields[i][1]);
        lua_setfield(L, -2, fields[i][0]);
    }
    lua_pushboolean(L, t->rgb);
    lua_setfield(L, -2, "rgb");
    if (t->main_param) {
        lua_pushstring(L, t->main_param);
        lua_setfield(L, -2, "main"); /* nil when the technique declares none */
    }
    lua_newtable(L);
    for (int k = LIGHT_POINT, n = 0; k <= LIGHT_TEXTURED_RECT; k++)
        if (t->lights & LIGHT_BIT(k)) {
            lua_pushstring(L, light_kind_name((LightKind)k));
            lua_rawseti(L, -2, ++n);
        }
    lua_setfield(L, -2, "lights");
    push_string_list(L, t->resources);
    lua_setfield(L, -2, "resources");
    /* params: the list in registry order; param: the same tables by name
       (desc.param.K), the one lookup every script uses. */
    lua_createtable(L, t->num_params, 0);
    lua_createtable(L, 0, t->num_params);
    for (int i = 0, n = 0; i < t->num_params; i++) {
        if (!tech_param_offered(t, i)) continue; /* not the technique's (registry.h) */
        push_param(L, &t->params[i]);
        if (tech_param_when(t, i)) {
            lua_pushstring(L, tech_param_when(t, i));
            lua_setfield(L, -2, "acts_when"); /* nil: always */
        }
        lua_pushvalue(L, -1);
        lua_setfield(L, -3, t->params[i].name);
        lua_rawseti(L, -3, ++n);
    }
    lua_setfield(L, -3, "param");
    lua_setfield(L, -2, "params");
}

const Technique *sl_check_technique(lua_State *L, int idx)
{
    Error err;
    const Technique *t = tech_find(luaL_checkstring(L, idx), &err);
    if (!t) sl_raise(L, &err);
    return t;
}

/* One `name = value` entry of a parameter table. */
static bool set_param(lua_State *L, const Technique *t, double *values, Error *err)
{
    if (lua_type(L, -2) != LUA_TSTRING)
        return error_set(err, "%s: parameter names are strings, got a %s key", t->name, luaL_typename(L, -2));
    const char *name = lua_tostring(L, -2);
    switch (lua_type(L, -1)) {
    case LUA_TNUMBER: return tech_param_set(t, name, lua_tonumber(L, -1), values, err);
    case LUA_TBOOLEAN: return tech_param_set(t, name, lua_toboolean(L, -1) ? 1.0 : 0.0, values, err);
    case LUA_TSTRING: {
        char assignment[512];
        snprintf(assignment, sizeof assignment, "%s=%s", name, lua_tostring(L, -1));
        return tech_param_parse(t, assignment, values, err);
    }
    default:
        return error_set(err, "%s: parameter %s must be a number, boolean or string, got a %s", t->name, name,
                         luaL_typename(L, -1));
    }
}

void sl_check_params(lua_State *L, int idx, const Technique *t, double *values)
{
    tech_params_default(t, values);
    if (lua_isnoneornil(L, idx)) return;
    idx = lua_absindex(L, idx);
    if (!lua_istable(L, idx)) luaL_error(L, "%s: parameters must be a table of name = value", t->name);
    Error err;
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        if (!set_param(L, t, values, &err)) sl_raise(L, &err);
        lua_pop(L, 1);
    }
}

void sl_push_params(lua_State *L, const Technique *t, const double *values)
{
    lua_createtable(L, 0, t->num_params);
    for (int i = 0; i < t->num_params; i++) {
        push_value(L, &t->params[i], values[i]);
        lua_setfield(L, -2, t->params[i].name);
    }
}

/* sl.techniques(): every registered technique, in registry order. */
int sl_techniques(lua_State *L)
{
    lua_createtable(L, tech_count(), 0);
    for (int i = 0; i < tech_count(); i++) {
        sl_push_technique(L, tech_at(i));
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* sl.technique(name): one description; unknown names raise the known list. */
int sl_technique(lua_State *L)
{
    sl_push_technique(L, sl_check_technique(L, 1));
    return 1;
}

/* sl.params(name, values): every parameter's value, checked, defaults filled. */
int sl_params(lua_State *L)
{
    const Technique *t = sl_check_technique(L, 1);
    double values[TECH_MAX_PARAMS];
    sl_check_params(L, 2, t, values);
    sl_push_params(L, t, values);
    return 1;
}
