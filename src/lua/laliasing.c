/* laliasing.c -- lab:aliasing{...}: the sampling-error analysis of course
 * §3.1 (resources/analysis/aliasing.h) from Lua, on the Lab's resources (a sweep
 * reuses maps and view samples like render and compare do):
 *   lab:aliasing{technique = "sm", params = {projection = "lispsm", fit = "body"},
 *                light = 1, axis = {1, 2, 5, ...}, frustum = 24, image = false}
 * returns { samples = SUMMARY, frustum = SUMMARY (when frustum > 0),
 *           axis = {{z, cascade, m_s, m_t, e_x, e_y}, ...} (per depth asked),
 *           map = {res, faces, projection, splits, width, height, pixel, near, far,
 *                  margin_texels (the border every fit adds on each side)},
 *           image = Image with channels m, m_s, m_t, proj, cascade (when asked) }
 * SUMMARY = {measured, undersampled, undersampled_share, singular (edge-on to the
 *            light, left out of the statistics), m_max, m_mean, m_s_max,
 *            m_t_max, m_s_mean, m_t_mean, storage_factor (frustum: Lloyd's,
 *            perspective aliasing) or total_aliasing_storage (samples:
 *            projection aliasing included), faces = {{measured, m_s_max,
 *            m_t_max}, ...}, hist = {{lo, hi, count}, ...}, depth = {{z_lo,
 *            z_hi, count, m_s_mean, m_t_mean, m_s_max, m_t_max, persp_s_mean,
 *            persp_t_mean}, ...}}. */
#include <string.h>
#include "lua/sl_lua.h"
#include "resources/analysis/aliasing.h"
#include "techniques/smap.h"

static const char *const option_names[] = {"technique", "params", "light", "axis", "frustum", "image", NULL};

static void set_num(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

static void push_rows(lua_State *L, const char *key, int n, int cols, const char *const *names, const double *v)
{
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        lua_createtable(L, 0, cols);
        for (int c = 0; c < cols; c++) set_num(L, names[c], v[(size_t)i * cols + c]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -2, key);
}

static void push_summary(lua_State *L, const AliasingSummary *s)
{
    lua_createtable(L, 0, 16);
    set_num(L, "measured", (double)s->measured);
    set_num(L, "undersampled", (double)s->undersampled);
    set_num(L, "undersampled_share", s->measured ? (double)s->undersampled / s->measured : 0.0);
    set_num(L, "singular", (double)s->singular);
    set_num(L, "m_max", s->m_max);
    set_num(L, "m_mean", s->m_mean);
    set_num(L, "m_s_max", s->m_s_max);
    set_num(L, "m_t_max", s->m_t_max);
    set_num(L, "m_s_mean", s->m_s_mean);
    set_num(L, "m_t_mean", s->m_t_mean);
    set_num(L, aliasing_storage_name(s), s->storage);
    static const char *const face_cols[] = {"measured", "m_s_max", "m_t_max"};
    double faces[LIGHTVIEW_MAX_FACES * 3];
    for (int f = 0; f < s->num_faces; f++) {
        faces[f * 3] = (double)s->face_count[f];
        faces[f * 3 + 1] = s->face_m_s_max[f];
        faces[f * 3 + 2] = s->face_m_t_max[f];
    }
    push_rows(L, "faces", s->num_faces, 3, face_cols, faces);
    static const char *const hist_cols[] = {"lo", "hi", "count"};
    double hist[ALIASING_HIST_BINS * 3];
    for (int b = 0; b < ALIASING_HIST_BINS; b++) {
        hist[b * 3] = b ? aliasing_hist_edge(b) : 0.0;
        hist[b * 3 + 1] = b < ALIASING_HIST_BINS - 1 ? aliasing_hist_edge(b + 1) : HUGE_VAL;
        hist[b * 3 + 2] = (double)s->hist[b];
    }
    push_rows(L, "hist", ALIASING_HIST_BINS, 3, hist_cols, hist);
    static const char *const depth_cols[] = {"z_lo",    "z_hi",    "count",        "m_s_mean",    "m_t_mean",
                                             "m_s_max", "m_t_max", "persp_s_mean", "persp_t_mean"};
    double depth[ALIASING_DEPTH_BINS * 9], r = s->depth_hi / s->depth_lo;
    for (int k = 0; k < ALIASING_DEPTH_BINS; k++) {
        const double row[9] = {s->depth_lo * pow(r, (double)k / ALIASING_DEPTH_BINS),
                               s->depth_lo * pow(r, (double)(k + 1) / ALIASING_DEPTH_BINS),
                               (double)s->depth_count[k], s->depth_m_s[k], s->depth_m_t[k], s->depth_m_s_max[k],
                               s->depth_m_t_max[k], s->depth_persp_s[k], s->depth_persp_t[k]};
        memcpy(depth + k * 9, row, sizeof row);
    }
    push_rows(L, "depth", ALIASING_DEPTH_BINS, 9, depth_cols, depth);
}

static void push_axis(lua_State *L, const LightView *lv, const Scene *sc, const Light *light, int idx)
{
    AliasingView av = aliasing_view(&sc->camera);
    int n = (int)lua_rawlen(L, idx);
    lua_createtable(L, n, 0);
    for (int i = 1; i <= n; i++) {
        lua_rawgeti(L, idx, i);
        int isnum = 0;
        double z = lua_tonumberx(L, -1, &isnum);
        lua_pop(L, 1);
        if (!isnum || !(z > 0.0)) luaL_error(L, "lab:aliasing: axis[%d] must be a positive view depth", i);
        AliasingPoint p;
        bool ok = aliasing_on_axis(lv, &av, light, z, &p);
        double ex = NAN, ey = NAN;
        if (ok) aliasing_normalised(&av, lv->res, &p, &ex, &ey);
        lua_createtable(L, 0, 6);
        set_num(L, "z", z);
        set_num(L, "cascade", ok ? p.face + 1 : 0);
        set_num(L, "m_s", ok ? p.m_s : NAN);
        set_num(L, "m_t", ok ? p.m_t : NAN);
        set_num(L, "e_x", ex);
        set_num(L, "e_y", ey);
        lua_rawseti(L, -2, i);
    }
}

static void push_map(lua_State *L, const ShadowMap *m, const Scene *sc)
{
    AliasingView av = aliasing_view(&sc->camera);
    lua_createtable(L, 0, 10);
    set_num(L, "res", m->res);
    set_num(L, "faces", m->num_faces);
    lua_pushstring(L, map_projection_name(m->view.projection));
    lua_setfield(L, -2, "projection");
    lua_createtable(L, m->view.num_cascades + 1, 0);
    for (int i = 0; m->view.num_cascades > 1 && i <= m->view.num_cascades; i++) {
        lua_pushnumber(L, m->view.split[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -2, "splits");
    set_num(L, "width", sc->camera.width);
    set_num(L, "height", sc->camera.height);
    set_num(L, "pixel", av.pixel);
    set_num(L, "near", sc->camera.near_dist);
    set_num(L, "far", sc->camera.far_dist);
    set_num(L, "margin_texels", LIGHTVIEW_MARGIN_TEXELS);
}

static void push_image(lua_State *L, const AliasingMap *a)
{
    Image img = {0};
    Error err;
    if (!image_init(&img, a->width, a->height, 5, &err)) sl_raise(L, &err);
    for (int s = 0; s < a->width * a->height; s++) {
        float *p = img.data + (size_t)s * 5;
        p[0] = fmaxf(a->m_s[s], a->m_t[s]);
        p[1] = a->m_s[s];
        p[2] = a->m_t[s];
        p[3] = a->proj[s];
        p[4] = (float)(a->face[s] + 1);
    }
    sl_push_image_copy(L, &img);
    image_free(&img);
}

static const Technique *check_map_technique(lua_State *L, int opts)
{
    lua_getfield(L, opts, "technique");
    const char *name = lua_isnil(L, -1) ? "aliasing" : luaL_checkstring(L, -1);
    Error err;
    const Technique *t = tech_find(name, &err);
    if (!t) sl_raise(L, &err);
    if (!smap_has_map_params(t)) luaL_error(L, "lab:aliasing: %s renders no shadow map with the shared map parameters", name);
    lua_pop(L, 1);
    return t;
}

static int lab_aliasing_m(lua_State *L)
{
    Lab *lab = sl_check_lab(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    for (lua_pushnil(L); lua_next(L, 2); lua_pop(L, 1)) {
        const char *k = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : "";
        int i = 0;
        while (option_names[i] && strcmp(option_names[i], k) != 0) i++;
        if (!option_names[i]) luaL_error(L, "lab:aliasing: unknown option '%s'", k);
    }
    const Technique *t = check_map_technique(L, 2);
    double params[TECH_MAX_PARAMS];
    lua_getfield(L, 2, "params");
    sl_check_params(L, lua_gettop(L), t, params);
    lua_pop(L, 1);
    lua_getfield(L, 2, "light");
    int number = (int)luaL_optinteger(L, -1, 1), light;
    lua_getfield(L, 2, "frustum");
    lua_Integer frustum = luaL_optinteger(L, -1, 0);
    luaL_argcheck(L, frustum >= 0 && frustum <= 256, 2, "frustum outside [0, 256]");
    lua_getfield(L, 2, "image");
    bool image = lua_toboolean(L, -1);
    lua_pop(L, 3);
    Error err;
    if (!lab_light_index(lab, number, &light, &err)) sl_raise(L, &err);
    const Scene *sc = lab_scene(lab);
    ShadowMapSpec spec = smap_spec(params);
    const ShadowMap *map = res_shadow_map(lab_resources(lab), sc, light, &spec, &err);
    const AliasingMap *an = map ? res_aliasing(lab_resources(lab), sc, light, map, &err) : NULL;
    if (!an) sl_raise(L, &err);
    lua_createtable(L, 0, 5);
    push_summary(L, &an->sum);
    lua_setfield(L, -2, "samples");
    if (frustum > 0) {
        AliasingSummary fr;
        aliasing_frustum(&map->view, sc, &sc->lights[light], (int)frustum, (int)frustum, (int)frustum, &fr);
        push_summary(L, &fr);
        lua_setfield(L, -2, "frustum");
    }
    lua_getfield(L, 2, "axis");
    if (!lua_isnil(L, -1)) {
        luaL_checktype(L, -1, LUA_TTABLE);
        push_axis(L, &map->view, sc, &sc->lights[light], lua_gettop(L));
        lua_setfield(L, -3, "axis");
    }
    lua_pop(L, 1);
    push_map(L, map, sc);
    lua_setfield(L, -2, "map");
    if (image) {
        push_image(L, an);
        lua_setfield(L, -2, "image");
    }
    return 1;
}

void sl_register_aliasing(lua_State *L)
{
    luaL_getmetatable(L, SL_LAB_TYPE);
    lua_getfield(L, -1, "__index");
    lua_pushcfunction(L, lab_aliasing_m);
    lua_setfield(L, -2, "aliasing");
    lua_pop(L, 2);
}
