/* llab.c -- the Lab userdata: sl.open(scene, overrides) loads a scene once.
 * Every Lab of a Lua state shares one resource manager (resources are keyed
 * by content), so the renders, references and comparisons of a sweep reuse
 * what earlier ones built, across scene variants too: a light-radius sweep
 * renders its shadow map once. Methods mirror the CLI commands
 * (render, reference, compare) with the same options as a table; unknown
 * options and out-of-range values raise errors naming them. Closed by
 * lab:close(), a to-be-closed variable, or the garbage collector. */
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "core/hash.h"
#include "lua/sl_lua.h"
#include "resources/refcache.h"

typedef struct LuaLab { Lab *lab; } LuaLab;

Lab *sl_check_lab(lua_State *L, int idx)
{
    LuaLab *ll = luaL_checkudata(L, idx, SL_LAB_TYPE);
    if (!ll->lab) luaL_error(L, "the lab is closed");
    return ll->lab;
}

static Lab *check_lab(lua_State *L) { return sl_check_lab(L, 1); }

/* ---- the state's resource manager ----------------------------------------- */

#define SL_RM_TYPE "shadowlab.ResourceManager"     /* the metatable's registry name */
#define SL_RM_STATE "shadowlab.state_resources"   /* the one instance's registry key */
typedef struct LuaRm { ResourceManager *rm; } LuaRm;

static int rm_gc(lua_State *L)
{
    LuaRm *r = luaL_checkudata(L, 1, SL_RM_TYPE);
    rm_destroy(r->rm);
    r->rm = NULL;
    return 0;
}

/* Push the state's manager, making it on first use. It is marked for
 * finalisation before any Lab that uses it, so Lua finalises it after them
 * (reverse order of marking); each Lab also holds it as its user value. */
static ResourceManager *push_state_rm(lua_State *L)
{
    if (lua_getfield(L, LUA_REGISTRYINDEX, SL_RM_STATE) == LUA_TUSERDATA)
        return ((LuaRm *)lua_touserdata(L, -1))->rm;
    lua_pop(L, 1);
    LuaRm *r = lua_newuserdatauv(L, sizeof *r, 0);
    r->rm = NULL;
    if (luaL_newmetatable(L, SL_RM_TYPE)) {
        lua_pushcfunction(L, rm_gc);
        lua_setfield(L, -2, "__gc");
    }
    lua_setmetatable(L, -2);
    r->rm = rm_create();
    if (!r->rm) luaL_error(L, "out of memory");
    lua_pushvalue(L, -1);
    lua_setfield(L, LUA_REGISTRYINDEX, SL_RM_STATE);
    return r->rm;
}

/* ---- sl.open ------------------------------------------------------------ */

/* Bounded appends: once the text is full, further appends do nothing and
 * *used stays >= n, which the caller reports. */
static void append(char *out, size_t n, size_t *used, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void append(char *out, size_t n, size_t *used, const char *fmt, ...)
{
    if (*used >= n) return;
    va_list ap;
    va_start(ap, fmt);
    *used += (size_t)vsnprintf(out + *used, n - *used, fmt, ap);
    va_end(ap);
}

/* A double in the fewest significant digits (15 to 17) that read back as the
 * same value, so an override of 0.1 is recorded as 0.1, not 0.10000000000000001. */
static void append_double(char *out, size_t n, size_t *used, double v)
{
    char text[32];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, v);
        if (strtod(text, NULL) == v) break;
    }
    append(out, n, used, "%s", text);
}

/* Append override `key`'s value as the Lua expression the scene sandbox
 * evaluates: numbers, booleans, quoted strings, arrays of these. A NaN or
 * infinite number has no such text (%g writes "nan", read back as a
 * string): it is refused here, by name. */
static void override_text(lua_State *L, const char *key, int idx, char *out, size_t n, size_t *used)
{
    idx = lua_absindex(L, idx);
    switch (lua_type(L, idx)) {
    case LUA_TNUMBER: {
        double v = lua_tonumber(L, idx);
        if (lua_isinteger(L, idx)) append(out, n, used, "%lld", (long long)lua_tointeger(L, idx));
        else if (isfinite(v)) append_double(out, n, used, v);
        else luaL_error(L, "scene override '%s' is %s, expected a finite number", key, isnan(v) ? "NaN" : "infinite");
        break;
    }
    case LUA_TBOOLEAN: append(out, n, used, "%s", lua_toboolean(L, idx) ? "true" : "false"); break;
    case LUA_TSTRING:
        append(out, n, used, "\"");
        for (const char *c = lua_tostring(L, idx); *c; c++)
            append(out, n, used, (*c == '"' || *c == '\\') ? "\\%c" : "%c", *c);
        append(out, n, used, "\"");
        break;
    case LUA_TTABLE:
        append(out, n, used, "{");
        for (lua_Integer i = 1, len = (lua_Integer)lua_rawlen(L, idx); i <= len; i++) {
            lua_rawgeti(L, idx, i);
            override_text(L, key, -1, out, n, used);
            lua_pop(L, 1);
            append(out, n, used, "%s", i < len ? "," : "");
        }
        append(out, n, used, "}");
        break;
    default:
        luaL_error(L, "scene override values are numbers, strings, booleans or arrays, got a %s", luaL_typename(L, idx));
    }
}

/* Overrides {["lights[1].radius"] = 0.3, ...} as "key=value" strings, in
 * sorted key order, kept alive in a table left on the stack. */
static int collect_overrides(lua_State *L, int idx, const char **out, int max)
{
    lua_newtable(L); /* the strings' owner */
    int owner = lua_gettop(L), n = 0;
    if (lua_isnoneornil(L, idx)) return 0;
    luaL_checktype(L, idx, LUA_TTABLE);
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        if (lua_type(L, -2) != LUA_TSTRING) luaL_error(L, "scene override keys are strings like 'lights[1].radius'");
        if (n == max) luaL_error(L, "more than %d scene overrides", max);
        char text[1001];
        size_t used = (size_t)snprintf(text, sizeof text, "%s=", lua_tostring(L, -2));
        if (used >= sizeof text) luaL_error(L, "scene override key too long");
        override_text(L, lua_tostring(L, -2), -1, text, sizeof text, &used);
        if (used >= sizeof text) luaL_error(L, "scene override '%s' longer than %d characters", lua_tostring(L, -2),
                                            (int)sizeof text - 1);
        lua_pushstring(L, text);
        lua_rawseti(L, owner, ++n);
        lua_pop(L, 1);
    }
    lua_getglobal(L, "table");
    lua_getfield(L, -1, "sort");
    lua_pushvalue(L, owner);
    lua_call(L, 1, 0);
    lua_pop(L, 1);
    for (int i = 0; i < n; i++) {
        lua_rawgeti(L, owner, i + 1);
        out[i] = lua_tostring(L, -1);
        lua_pop(L, 1);
    }
    return n;
}

#define MAX_OVERRIDES 64

int sl_lab_open(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    const char *overrides[MAX_OVERRIDES];
    int n = collect_overrides(L, 2, overrides, MAX_OVERRIDES);
    ResourceManager *rm = push_state_rm(L);
    LuaLab *ll = lua_newuserdatauv(L, sizeof *ll, 1);
    ll->lab = NULL;
    luaL_setmetatable(L, SL_LAB_TYPE);
    lua_rotate(L, -2, 1); /* lab, rm */
    lua_setiuservalue(L, -2, 1);
    Error err;
    ll->lab = lab_open_shared(path, overrides, n, rm, &err);
    if (!ll->lab) sl_raise(L, &err);
    return 1;
}

/* ---- options ------------------------------------------------------------ */

static const char *const option_names[] = {"technique", "params", "light", "repeats", "warmup", "samples", "pattern",
                                           "seed", "sample_set", "measure", "cache", "out", "png", "exr", "print",
                                           "time_budget", "error_scale", NULL};

static void check_option_names(lua_State *L, int idx, const char *method)
{
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        bool known = false;
        for (int i = 0; option_names[i] && lua_type(L, -2) == LUA_TSTRING; i++)
            known = known || strcmp(lua_tostring(L, -2), option_names[i]) == 0;
        if (!known) {
            char list[512];
            size_t used = 0;
            for (int i = 0; option_names[i]; i++) append(list, sizeof list, &used, "%s%s", i ? ", " : "", option_names[i]);
            const char *key = luaL_tolstring(L, -2, NULL);
            luaL_error(L, "lab:%s: unknown option '%s' (options: %s)", method, key, list);
        }
        lua_pop(L, 1);
    }
}

/* A numeric option in [lo, hi] (integral when `integer`); raises naming it
 * and its range. (lua_pushfstring has no %g: the message is formatted here.) */
static double opt_value(lua_State *L, int idx, const char *name, double def, double lo, double hi, bool integer)
{
    lua_getfield(L, idx, name);
    int isnum = 0;
    double v = lua_isnil(L, -1) ? def : lua_tonumberx(L, -1, &isnum);
    bool present = !lua_isnil(L, -1);
    char value[64];
    if (present && !isnum) snprintf(value, sizeof value, "a %s", luaL_typename(L, -1));
    else snprintf(value, sizeof value, "%g", v);
    lua_pop(L, 1);
    if ((present && !isnum) || !(v >= lo && v <= hi) || (integer && v != floor(v))) {
        char msg[256];
        snprintf(msg, sizeof msg, integer ? "option %s = %s is invalid: expected an integer in [%.0f, %.0f]"
                                          : "option %s = %s is invalid: expected a number in [%g, %g]",
                 name, value, lo, hi);
        luaL_error(L, "%s", msg);
    }
    return v;
}

static double opt_number(lua_State *L, int idx, const char *name, double def, double lo, double hi)
{
    return opt_value(L, idx, name, def, lo, hi, false);
}

static int opt_int(lua_State *L, int idx, const char *name, int def, int lo, int hi)
{
    return (int)opt_value(L, idx, name, def, lo, hi, true);
}

static bool opt_bool(lua_State *L, int idx, const char *name, bool def)
{
    lua_getfield(L, idx, name);
    bool v = lua_isnil(L, -1) ? def : lua_toboolean(L, -1);
    lua_pop(L, 1);
    return v;
}

/* A string option; NULL when absent. The string lives in the options table. */
static const char *opt_string(lua_State *L, int idx, const char *name)
{
    lua_getfield(L, idx, name);
    if (!lua_isnil(L, -1) && lua_type(L, -1) != LUA_TSTRING) luaL_error(L, "option %s must be a string", name);
    const char *s = lua_tostring(L, -1);
    lua_pop(L, 1);
    return s;
}

typedef struct Options {
    CompareRequest req;
    double params[TECH_MAX_PARAMS];
    char cache_dir[1024];
    const char *out;
    bool png, exr, print;
} Options;

static void read_reference_options(lua_State *L, int idx, Options *o)
{
    Error err;
    o->req.ref = (ReferenceParams){MEASURE_VISIBILITY, 1024, SAMPLING_R2, 1, false};
    o->req.ref.samples = opt_int(L, idx, "samples", 1024, 1, REFERENCE_MAX_SAMPLES);
    o->req.ref.seed = (uint32_t)opt_int(L, idx, "seed", 1, 0, 2147483647);
    const char *pattern = opt_string(L, idx, "pattern"), *measure = opt_string(L, idx, "measure");
    if (pattern && !sampling_pattern_parse(pattern, &o->req.ref.pattern, &err)) sl_raise(L, &err);
    if (measure && !measure_parse(measure, &o->req.ref.measure, &err)) sl_raise(L, &err);
    const char *set = opt_string(L, idx, "sample_set");
    if (set && strcmp(set, "shared") != 0 && strcmp(set, "per_view_sample") != 0)
        luaL_error(L, "sample_set '%s' is not one of: per_view_sample, shared", set);
    o->req.ref.shared_set = set && strcmp(set, "shared") == 0;
    lua_getfield(L, idx, "cache");
    if (lua_isnil(L, -1) || (lua_isboolean(L, -1) && lua_toboolean(L, -1))) {
        refcache_default_dir(o->cache_dir, sizeof o->cache_dir);
        o->req.cache_dir = o->cache_dir;
    } else if (lua_type(L, -1) == LUA_TSTRING) {
        snprintf(o->cache_dir, sizeof o->cache_dir, "%s", lua_tostring(L, -1));
        o->req.cache_dir = o->cache_dir;
    } else if (!lua_isboolean(L, -1)) {
        luaL_error(L, "option cache must be a folder, true (the default cache) or false (no cache)");
    }
    lua_pop(L, 1);
}

/* Options common to the three methods; `stages` says which apply. */
static void read_options(lua_State *L, Lab *lab, const char *method, bool render, bool reference, Options *o)
{
    memset(o, 0, sizeof *o);
    int idx = 2;
    if (lua_isnoneornil(L, idx)) lua_newtable(L), lua_replace(L, idx);
    luaL_checktype(L, idx, LUA_TTABLE);
    check_option_names(L, idx, method);
    Error err;
    if (!lab_light_index(lab, opt_int(L, idx, "light", 1, 1, 64), &o->req.light_index, &err)) sl_raise(L, &err);
    if (render) {
        lua_getfield(L, idx, "technique");
        if (lua_isnil(L, -1)) luaL_error(L, "lab:%s: option technique is required (see shadowlab.techniques())", method);
        o->req.tech = sl_check_technique(L, -1);
        lua_pop(L, 1);
        lua_getfield(L, idx, "params");
        sl_check_params(L, -1, o->req.tech, o->params);
        lua_pop(L, 1);
        o->req.params = o->params;
        o->req.repeat = opt_int(L, idx, "repeats", 1, 1, 10000);
        o->req.warmup = opt_int(L, idx, "warmup", 0, 0, 1000);
        o->req.time_budget_s = opt_number(L, idx, "time_budget", 0.0, 0.0, 1e6);
        o->req.error_scale = opt_number(L, idx, "error_scale", 0.0, 0.0, 1e6); /* 0: per image */
    }
    o->req.reference = reference;
    read_reference_options(L, idx, o);
    o->out = opt_string(L, idx, "out");
    o->png = opt_bool(L, idx, "png", true);
    o->exr = opt_bool(L, idx, "exr", true);
    o->print = opt_bool(L, idx, "print", false);
}

/* ---- render / reference / compare --------------------------------------- */

/* The outputs of the CLI (EXR, PNGs, record) or, with exr = false, the
 * previews and the record only (what a sweep's report shows). */
static bool write_outputs(const Options *o, RunReport *rep, Error *err)
{
    if (o->exr) return report_write_all(rep, o->out, o->png, err);
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.json", o->out, report_stem(rep));
    return mkdir_p(o->out, err) && (!o->png || report_write_previews(rep, o->out, err)) &&
           report_write_record(rep, path, err);
}

static int run_method(lua_State *L, const char *method, bool render, bool reference)
{
    Lab *lab = check_lab(L);
    Options o;
    read_options(L, lab, method, render, reference, &o);
    Error err;
    CompareResult res;
    if (!lab_compare(lab, &o.req, &res, &err)) sl_raise(L, &err);
    RunReport rep = compare_report(lab, &res, method, omp_get_max_threads());
    if (o.out && !write_outputs(&o, &rep, &err)) {
        compare_result_free(&res);
        sl_raise(L, &err);
    }
    if (o.print) report_print(&rep, stdout);
    sl_push_run(L, &res, &rep);
    return 1;
}

static int lab_render_m(lua_State *L) { return run_method(L, "render", true, false); }
static int lab_reference_m(lua_State *L) { return run_method(L, "reference", false, true); }
static int lab_compare_m(lua_State *L) { return run_method(L, "compare", true, true); }

/* ---- the rest ----------------------------------------------------------- */

/* lab:key(technique, params [, light]): the configuration's stable key. */
static int lab_key_m(lua_State *L)
{
    Lab *lab = check_lab(L);
    const Technique *t = sl_check_technique(L, 2);
    double params[TECH_MAX_PARAMS];
    sl_check_params(L, 3, t, params);
    int light;
    Error err;
    if (!lab_light_index(lab, (int)luaL_optinteger(L, 4, 1), &light, &err)) sl_raise(L, &err);
    char hex[17];
    hash_hex(lab_config_key(lab, t, params, light), hex);
    lua_pushstring(L, hex);
    return 1;
}

static void set_number(lua_State *L, const char *key, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, key);
}

static void push_lights(lua_State *L, const Scene *sc)
{
    lua_createtable(L, sc->num_lights, 0);
    for (int i = 0; i < sc->num_lights; i++) {
        lua_createtable(L, 0, 2);
        lua_pushstring(L, light_kind_name(sc->lights[i].kind));
        lua_setfield(L, -2, "type");
        set_number(L, "radius", sc->lights[i].radius);
        lua_rawseti(L, -2, i + 1);
    }
}

/* lab:info(): the loaded scene (name, file, content hash, size, lights). */
static int lab_info_m(lua_State *L)
{
    Lab *lab = check_lab(L);
    const Scene *sc = lab_scene(lab);
    char hex[17];
    lua_createtable(L, 0, 10);
    lua_pushstring(L, sc->name);
    lua_setfield(L, -2, "name");
    lua_pushstring(L, sc->path);
    lua_setfield(L, -2, "path");
    hash_hex(sc->hash, hex);
    lua_pushstring(L, hex);
    lua_setfield(L, -2, "hash");
    lua_pushinteger(L, sc->num_triangles);
    lua_setfield(L, -2, "triangles");
    lua_pushinteger(L, sc->camera.width);
    lua_setfield(L, -2, "width");
    lua_pushinteger(L, sc->camera.height);
    lua_setfield(L, -2, "height");
    lua_pushinteger(L, sc->camera.supersample);
    lua_setfield(L, -2, "supersample");
    set_number(L, "load_s", lab_scene_load_seconds(lab));
    lua_pushinteger(L, rm_count(lab_resources(lab)));
    lua_setfield(L, -2, "resources_held");
    set_number(L, "resource_bytes", (double)rm_bytes(lab_resources(lab)));
    push_lights(L, sc);
    lua_setfield(L, -2, "lights");
    return 1;
}

/* lab:drop_resources(): free every resource the state's Labs hold (their
 * scenes stay): what comes next shares nothing with what was built. */
static int lab_drop_m(lua_State *L)
{
    rm_clear(lab_resources(check_lab(L)));
    return 0;
}

static int lab_close_m(lua_State *L)
{
    LuaLab *ll = luaL_checkudata(L, 1, SL_LAB_TYPE);
    lab_close(ll->lab);
    ll->lab = NULL;
    return 0;
}

static int lab_tostring(lua_State *L)
{
    LuaLab *ll = luaL_checkudata(L, 1, SL_LAB_TYPE);
    if (ll->lab) lua_pushfstring(L, "shadowlab.Lab(%s)", lab_scene(ll->lab)->path);
    else lua_pushliteral(L, "shadowlab.Lab(closed)");
    return 1;
}

void sl_register_lab(lua_State *L)
{
    static const luaL_Reg methods[] = {
        {"render", lab_render_m}, {"reference", lab_reference_m}, {"compare", lab_compare_m},
        {"key", lab_key_m},       {"info", lab_info_m},           {"close", lab_close_m},
        {"drop_resources", lab_drop_m},
        {NULL, NULL},
    };
    static const luaL_Reg meta[] = {
        {"__gc", lab_close_m}, {"__close", lab_close_m}, {"__tostring", lab_tostring}, {NULL, NULL},
    };
    luaL_newmetatable(L, SL_LAB_TYPE);
    luaL_setfuncs(L, meta, 0);
    luaL_newlib(L, methods);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
}
