/* lrun.c -- the Run userdata: one finished render, reference or comparison.
 * It owns copies of its images (so it outlives its Lab) and carries the run's
 * record, the very JSON the CLI writes (lab/record.c), decoded into a table:
 * scene, technique and parameters, per-stage timings, resources built or
 * reused, metrics, reference samples and noise, threads, machine. */
#include <stdlib.h>
#include <string.h>
#include "lua/sl_lua.h"
#include "resources/standard.h"

typedef struct LuaRun {
    CompareResult res;        /* render and signed error owned; res.ref not used */
    Image ref_value, ref_stderr;
    Image sample_class;       /* SampleClass per view sample (scene/light.h), as floats */
    Image regions;            /* compared runs: each sample's Region (metrics_regions) */
} LuaRun;

static LuaRun *check_run(lua_State *L) { return luaL_checkudata(L, 1, SL_RUN_TYPE); }

static bool copy_image(const Image *src, Image *dst, Error *err)
{
    if (!image_init(dst, src->width, src->height, src->channels, err)) return false;
    memcpy(dst->data, src->data, image_count(src) * sizeof(float));
    return true;
}

/* The view samples' classes for the run's light as a one-channel image, so
 * scripts select lit candidates by class (their reference's standard error
 * is 0 wherever every batch agrees, lit or umbra alike). */
static bool copy_classes(const RunReport *rep, Image *dst, Error *err)
{
    ResourceManager *rm = lab_resources(rep->lab);
    const ViewSamples *vs = res_view_samples(rm, lab_scene(rep->lab), err);
    const uint8_t *cls = vs ? res_classes(rm, lab_scene(rep->lab), rep->light_index, err) : NULL;
    if (!cls || !image_init(dst, vs->width, vs->height, 1, err)) return false;
    for (int s = 0; s < vs->count; s++) dst->data[s] = cls[s];
    return true;
}

/* The record as JSON text in memory (malloc'd). */
static char *record_text(lua_State *L, const RunReport *rep, size_t *len)
{
    char *buf = NULL;
    FILE *fp = open_memstream(&buf, len);
    if (!fp) luaL_error(L, "out of memory writing the record");
    report_write_record_fp(rep, fp);
    fclose(fp);
    return buf;
}

/* json.decode(text) with lua/shadowlab/json.lua; frees json. */
static void push_decoded(lua_State *L, char *json, size_t len)
{
    lua_pushlstring(L, json, len);
    free(json);
    lua_getglobal(L, "require");
    lua_pushliteral(L, "shadowlab.json");
    lua_call(L, 1, 1);
    lua_getfield(L, -1, "decode");
    lua_replace(L, -2);
    lua_insert(L, -2);
    lua_call(L, 1, 1);
}

void sl_push_run(lua_State *L, CompareResult *res, const RunReport *rep)
{
    LuaRun *run = lua_newuserdatauv(L, sizeof *run, 1);
    memset(run, 0, sizeof *run);
    run->res = *res; /* moved: the caller's copy is no longer freed */
    luaL_setmetatable(L, SL_RUN_TYPE);
    Error err;
    if (res->ref && (!copy_image(&res->ref->value, &run->ref_value, &err) ||
                     !copy_image(&res->ref->std_error, &run->ref_stderr, &err)))
        sl_raise(L, &err);
    if (!copy_classes(rep, &run->sample_class, &err)) sl_raise(L, &err);
    if (res->compared) {
        ResourceManager *rm = lab_resources(rep->lab);
        const Scene *sc = lab_scene(rep->lab);
        const uint8_t *cls = res_classes(rm, sc, res->light_index, &err);
        const uint8_t *term = cls ? res_terminator(rm, sc, res->light_index, &err) : NULL;
        if (!term || !metrics_regions(res->ref, cls, term, &run->regions, &err)) sl_raise(L, &err);
    }
    /* Tell the collector about the images it cannot see, so a long sweep
     * collects finished Runs before their pixels pile up. */
    size_t pixels = image_count(&run->res.render.visibility) + image_count(&run->res.signed_error) +
                    image_count(&run->ref_value) + image_count(&run->ref_stderr) + image_count(&run->sample_class);
    lua_gc(L, LUA_GCSTEP, (int)(pixels * sizeof(float) / 1024));
    size_t len;
    char *json = record_text(L, rep, &len);
    run->res.ref = NULL;
    push_decoded(L, json, len);
    lua_setiuservalue(L, -2, 1);
}

/* run:record(): the record table (shared: copy it before changing it). */
static int run_record(lua_State *L)
{
    check_run(L);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

/* run:metrics(): the record's metrics, or nil when nothing was compared. */
static int run_metrics(lua_State *L)
{
    check_run(L);
    lua_getiuservalue(L, 1, 1);
    lua_getfield(L, -1, "metrics");
    return 1;
}

/* run:image(name): a copy of "visibility", "reference", "stderr", "error" or
 * "class" (SampleClass per sample: 1 is a lit candidate, the samples scored) or
 * "region" (compared runs: each sample's region: 0 not scored, 1 penumbra,
 * 2 umbra, 3 lit, 4 terminator, metrics.h's Region). */
static int run_image(lua_State *L)
{
    LuaRun *run = check_run(L);
    static const char *const names[] = {"visibility", "reference", "stderr", "error", "class", "region", NULL};
    const Image *images[] = {&run->res.render.visibility, &run->ref_value, &run->ref_stderr, &run->res.signed_error,
                             &run->sample_class, &run->regions};
    int which = luaL_checkoption(L, 2, NULL, names);
    if (!images[which]->data) return luaL_error(L, "run:image: this run has no %s image", names[which]);
    sl_push_image_copy(L, images[which]);
    return 1;
}

static int run_gc(lua_State *L)
{
    LuaRun *run = check_run(L);
    compare_result_free(&run->res);
    image_free(&run->ref_value);
    image_free(&run->ref_stderr);
    image_free(&run->sample_class);
    image_free(&run->regions);
    return 0;
}

static int run_tostring(lua_State *L)
{
    LuaRun *run = check_run(L);
    lua_pushfstring(L, "shadowlab.Run(%s)", run->res.tech ? run->res.tech->name : "reference");
    return 1;
}

void sl_register_run(lua_State *L)
{
    static const luaL_Reg methods[] = {
        {"record", run_record}, {"metrics", run_metrics}, {"image", run_image}, {NULL, NULL},
    };
    static const luaL_Reg meta[] = {{"__gc", run_gc}, {"__tostring", run_tostring}, {NULL, NULL}};
    luaL_newmetatable(L, SL_RUN_TYPE);
    luaL_setfuncs(L, meta, 0);
    luaL_newlib(L, methods);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
}
