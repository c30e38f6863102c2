/* scene_lua.c -- scene files: run the Lua file in the sandbox, apply the
 * command-line overrides, then validate every field into a Scene. Unknown
 * keys, wrong types and out-of-range values are errors naming the key path
 * and the valid range. Lengths are world units, angles degrees. */
#include <lauxlib.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "scene/luaread.h"
#include "scene/sandbox.h"
#include "scene/scene_build.h"

#define MAX_OBJECTS 100000
#define MAX_LIGHTS 64
/* Triangles per scene: procedural shapes could otherwise ask for gigabytes
 * (100000 spheres of 4096 segments) before anything refuses them. */
#define MAX_TRIANGLES (1 << 24)
#define MAX_COORD 1e9
#define MAX_LENGTH 1e7

static const Range ANY_COORD = {-MAX_COORD, MAX_COORD, false, false};
static const Range POS_LENGTH = {0.0, MAX_LENGTH, true, false};

/* ---- camera ----------------------------------------------------------- */

static bool read_camera(LuaReader *r, int idx, Camera *cam)
{
    static const char *const keys[] = {"position", "target", "up", "fov", "near", "far",
                                       "width", "height", "supersample", NULL};
    double fov_deg, near_d, far_d;
    if (!rd_only_keys(r, idx, keys) ||
        !rd_vec3(r, idx, "position", ANY_COORD, true, v3(0, 0, 0), &cam->position) ||
        !rd_vec3(r, idx, "target", ANY_COORD, true, v3(0, 0, 0), &cam->target) ||
        !rd_vec3(r, idx, "up", ANY_COORD, false, v3(0, 1, 0), &cam->up) ||
        !rd_number(r, idx, "fov", (Range){0.0, 180.0, true, true}, false, 45.0, &fov_deg) ||
        !rd_number(r, idx, "near", POS_LENGTH, false, 0.01, &near_d) ||
        !rd_number(r, idx, "far", POS_LENGTH, false, 1000.0, &far_d) ||
        !rd_int(r, idx, "width", 1, 16384, false, 640, &cam->width) ||
        !rd_int(r, idx, "height", 1, 16384, false, 480, &cam->height) ||
        !rd_int(r, idx, "supersample", 1, 16, false, 1, &cam->supersample))
        return false;
    if (far_d <= near_d) return rd_fail(r, "far", "= %g must exceed near = %g", far_d, near_d);
    vec3 view = v3_sub(cam->target, cam->position);
    if (v3_len(view) <= 0.0f) return rd_fail(r, "target", "coincides with position");
    if (v3_len(v3_cross(view, cam->up)) <= 1e-12f * v3_len(view) * v3_len(cam->up))
        return rd_fail(r, "up", "is zero or parallel to the view direction");
    cam->fov_y_rad = (float)(fov_deg * M_PI / 180.0);
    cam->near_dist = (float)near_d;
    cam->far_dist = (float)far_d;
    return true;
}

/* ---- lights ----------------------------------------------------------- */

static const char *const light_kinds[] = {"point", "spot", "directional", "sphere", "rect", "disk", "textured_rect", NULL};

const char *light_kind_name(LightKind kind) { return light_kinds[kind]; }

/* Keys each light kind accepts (after "type"). */
static const char *const *light_keys(LightKind kind)
{
    static const char *const point[] = {"type", "position", "color", "intensity", NULL};
    static const char *const spot[] = {"type", "position", "direction", "target", "cone_angle", "color", "intensity", NULL};
    static const char *const dir[] = {"type", "direction", "color", "intensity", NULL};
    static const char *const sphere[] = {"type", "position", "radius", "color", "intensity", NULL};
    static const char *const rect[] = {"type", "position", "direction", "target", "up", "width", "height", "color", "intensity", NULL};
    static const char *const disk[] = {"type", "position", "direction", "target", "radius", "color", "intensity", NULL};
    static const char *const textured[] = {"type", "position", "direction", "target", "up", "width", "height", "image", "color", "intensity", NULL};
    static const char *const *const table[] = {point, spot, dir, sphere, rect, disk, textured};
    return table[kind];
}

/* Unit direction from "direction", or from position toward "target". */
static bool read_direction(LuaReader *r, int idx, Light *l)
{
    bool has_dir = rd_get(r, idx, "direction"), has_target = rd_get(r, idx, "target");
    lua_pop(r->L, (int)has_dir + (int)has_target);
    if (has_dir == has_target) return rd_fail(r, "direction", "or target: give exactly one");
    vec3 d, t;
    if (has_dir) {
        if (!rd_vec3(r, idx, "direction", ANY_COORD, true, v3(0, 0, 0), &d)) return false;
    } else {
        if (!rd_vec3(r, idx, "target", ANY_COORD, true, v3(0, 0, 0), &t)) return false;
        d = v3_sub(t, l->position);
    }
    if (!(v3_len(d) > 0.0f)) return rd_fail(r, has_dir ? "direction" : "target", "gives a zero-length direction");
    l->direction = v3_normalize_or(d, v3(0, -1, 0));
    return true;
}

/* "up" orthonormalised against the emitting normal (rectangles). */
static bool read_up(LuaReader *r, int idx, Light *l)
{
    vec3 up;
    vec3 def = fabsf(l->direction.y) < 0.9f ? v3(0, 1, 0) : v3(0, 0, 1);
    if (!rd_vec3(r, idx, "up", ANY_COORD, false, def, &up)) return false;
    vec3 ortho = v3_sub(up, v3_scale(l->direction, v3_dot(up, l->direction)));
    if (!(v3_len(ortho) > 1e-6f * v3_len(up))) return rd_fail(r, "up", "is zero or parallel to the light's normal");
    l->up = v3_normalize_or(ortho, def);
    return true;
}

static bool read_light_shape(LuaReader *r, int idx, Light *l, const SceneLoadCtx *ctx)
{
    double v;
    LightKind k = l->kind;
    bool has_pos = k != LIGHT_DIRECTIONAL, has_dir = k != LIGHT_POINT && k != LIGHT_SPHERE;
    if (has_pos && !rd_vec3(r, idx, "position", ANY_COORD, true, v3(0, 0, 0), &l->position)) return false;
    if (has_dir && !read_direction(r, idx, l)) return false;
    if (k == LIGHT_SPHERE || k == LIGHT_DISK) {
        if (!rd_number(r, idx, "radius", POS_LENGTH, true, 0, &v)) return false;
        l->radius = (float)v;
    }
    if (k == LIGHT_SPOT) {
        if (!rd_number(r, idx, "cone_angle", (Range){0.0, 90.0, true, true}, false, 30.0, &v)) return false;
        l->cone_half_rad = (float)(v * M_PI / 180.0);
    }
    if (k == LIGHT_RECT || k == LIGHT_TEXTURED_RECT) {
        double w, h;
        if (!read_up(r, idx, l) || !rd_number(r, idx, "width", POS_LENGTH, true, 0, &w) ||
            !rd_number(r, idx, "height", POS_LENGTH, true, 0, &h))
            return false;
        l->width = (float)w;
        l->height = (float)h;
    }
    if (k == LIGHT_TEXTURED_RECT) {
        char name[SCENE_PATH_MAX];
        if (!rd_string(r, idx, "image", NULL, name, sizeof name)) return false;
        if (!name[0]) return rd_fail(r, "image", "is missing (an image file for the emission)");
        if (!scene_load_light_image(ctx, name, l, r->err)) return rd_fail(r, "image", ": %s", r->err->msg);
    }
    return true;
}

static bool read_light(LuaReader *r, int idx, Light *l, const SceneLoadCtx *ctx)
{
    int kind;
    double intensity;
    if (!rd_enum(r, idx, "type", light_kinds, true, 0, &kind)) return false;
    l->kind = (LightKind)kind;
    if (!rd_only_keys(r, idx, light_keys(l->kind)) || !read_light_shape(r, idx, l, ctx) ||
        !rd_vec3(r, idx, "color", RANGE_CLOSED(0, 1e6), false, v3(1, 1, 1), &l->color) ||
        !rd_number(r, idx, "intensity", RANGE_CLOSED(0, 1e12), false, 1.0, &intensity))
        return false;
    l->intensity = (float)intensity;
    return true;
}

/* ---- objects ---------------------------------------------------------- */

enum Shape { SHAPE_PLANE, SHAPE_BOX, SHAPE_SPHERE, SHAPE_CYLINDER, SHAPE_CONE, SHAPE_TORUS, SHAPE_DISK,
             SHAPE_HEIGHTFIELD, SHAPE_MESH };
static const char *const shape_names[] = {"plane", "box", "sphere", "cylinder", "cone", "torus", "disk",
                                          "heightfield", "mesh", NULL};

static const char *const *shape_keys(int shape)
{
#define COMMON "name", "shape", "translate", "rotate", "scale", "caster", "receiver", "albedo"
    static const char *const plane[] = {COMMON, "size", NULL};
    static const char *const box[] = {COMMON, "size", NULL};
    static const char *const sphere[] = {COMMON, "radius", "segments", NULL};
    static const char *const cyl[] = {COMMON, "radius", "height", "segments", NULL};
    static const char *const torus[] = {COMMON, "major", "minor", "segments", NULL};
    static const char *const disk[] = {COMMON, "radius", "segments", NULL};
    static const char *const hf[] = {COMMON, "size", "resolution", "elevation", NULL};
    static const char *const mesh[] = {COMMON, "model", NULL};
#undef COMMON
    static const char *const *const table[] = {plane, box, sphere, cyl, cyl, torus, disk, hf, mesh};
    return table[shape];
}

/* Heightfield: elevation(x, z) evaluated in the sandbox at every grid vertex. */
static bool build_heightfield(LuaReader *r, int idx, Mesh *m, const SceneLoadCtx *ctx)
{
    double size[2], res[2];
    static const double def_size[2] = {1, 1}, def_res[2] = {64, 64};
    if (!rd_vec2(r, idx, "size", POS_LENGTH, true, def_size, size) ||
        !rd_vec2(r, idx, "resolution", RANGE_CLOSED(1, 4096), false, def_res, res))
        return false;
    int nx = (int)res[0], nz = (int)res[1];
    if (!rd_get(r, idx, "elevation") || !lua_isfunction(r->L, -1)) {
        lua_settop(r->L, idx);
        return rd_fail(r, "elevation", "must be a function(x, z) returning the height");
    }
    float *h = malloc(sizeof(float) * (size_t)(nx + 1) * (size_t)(nz + 1));
    if (!h) return rd_fail(r, "resolution", "needs too much memory");
    bool ok = true;
    for (int j = 0; ok && j <= nz; j++) {
        for (int i = 0; ok && i <= nx; i++) {
            double xz[2] = {((double)i / nx - 0.5) * size[0], ((double)j / nz - 0.5) * size[1]}, y;
            ok = sandbox_call_number(ctx->sandbox, -1, xz, 2, &y, r->err);
            if (ok && !(fabs(y) <= MAX_COORD)) ok = error_set(r->err, "returned %g at (%g, %g)", y, xz[0], xz[1]);
            if (ok) h[j * (nx + 1) + i] = (float)y;
        }
    }
    lua_pop(r->L, 1);
    if (!ok) {
        free(h);
        return rd_fail(r, "elevation", ": %s", r->err->msg);
    }
    ok = prim_heightfield(m, (float)size[0], (float)size[1], nx, nz, h, r->err);
    free(h);
    return ok || rd_fail(r, NULL, ": %s", r->err->msg);
}

/* One alternative of `model`: a file name, or {file = NAME, scale = k,
 * translate = {x, y, z}} whose transform maps that file into the frame of
 * the first alternative (two scans of one object stored at different scales). */
static bool read_model_choice(LuaReader *r, int idx, ModelChoice *c)
{
    static const char *const keys[] = {"file", "scale", "translate", NULL};
    lua_State *L = r->L;
    c->pre = m34_identity();
    if (lua_type(L, idx) == LUA_TSTRING) {
        snprintf(c->name, sizeof c->name, "%s", lua_tostring(L, idx));
        return true;
    }
    if (!lua_istable(L, idx)) return rd_fail(r, NULL, "must be a file name or {file = ..., scale = ..., translate = ...}");
    double k;
    vec3 t;
    if (!rd_only_keys(r, idx, keys) || !rd_string(r, idx, "file", "", c->name, sizeof c->name) ||
        !rd_number(r, idx, "scale", POS_LENGTH, false, 1, &k) ||
        !rd_vec3(r, idx, "translate", ANY_COORD, false, v3(0, 0, 0), &t))
        return false;
    if (!c->name[0]) return rd_fail(r, "file", "is missing (a .obj or .ply file name)");
    c->pre = transform_srt(v3((float)k, (float)k, (float)k), v3(0, 0, 0), t);
    return true;
}

/* `model`: one alternative, or a list of them tried in order. */
static bool build_model(LuaReader *r, int idx, Object *o, const SceneLoadCtx *ctx)
{
    lua_State *L = r->L;
    if (!rd_get(r, idx, "model")) return rd_fail(r, "model", "is missing (a .obj or .ply file name)");
    ModelChoice choices[MODEL_MAX_CHOICES];
    int n = 0, list = lua_gettop(L);
    size_t saved = rd_enter_key(r, "model");
    bool ok = true;
    if (lua_type(L, list) == LUA_TSTRING || (lua_istable(L, list) && rd_get(r, list, "file"))) {
        lua_settop(L, list);
        ok = read_model_choice(r, list, &choices[n++]);
    } else if (lua_istable(L, list)) {
        int len = (int)luaL_len(L, list);
        if (len < 1 || len > MODEL_MAX_CHOICES) ok = rd_fail(r, NULL, "has %d alternatives, expected 1 to %d", len, MODEL_MAX_CHOICES);
        for (int i = 1; ok && i <= len; i++) {
            size_t inner = rd_enter_index(r, i);
            lua_rawgeti(L, list, i);
            ok = read_model_choice(r, lua_gettop(L), &choices[n++]);
            lua_settop(L, list);
            rd_leave(r, inner);
        }
    } else {
        ok = rd_fail(r, NULL, "must be a file name or a list of alternatives");
    }
    rd_leave(r, saved);
    lua_settop(L, idx);
    if (ok && !scene_load_model(ctx, choices, n, o, r->err)) ok = rd_fail(r, "model", ": %s", r->err->msg);
    return ok;
}

static bool build_shape(LuaReader *r, int idx, int shape, Object *o, const SceneLoadCtx *ctx)
{
    double a = 1, b = 1;
    int seg = 64;
    vec3 size3;
    double size2[2];
    static const double def2[2] = {1, 1};
    Mesh *m = &o->mesh;
    Error *e = r->err;
    bool ok;
    switch (shape) {
    case SHAPE_PLANE:
        ok = rd_vec2(r, idx, "size", POS_LENGTH, false, def2, size2) && prim_plane(m, (float)size2[0], (float)size2[1], e);
        break;
    case SHAPE_BOX:
        ok = rd_vec3(r, idx, "size", POS_LENGTH, false, v3(1, 1, 1), &size3) && prim_box(m, size3, e);
        break;
    case SHAPE_SPHERE:
    case SHAPE_DISK:
        ok = rd_number(r, idx, "radius", POS_LENGTH, false, 1, &a) && rd_int(r, idx, "segments", 3, 4096, false, 64, &seg) &&
             (shape == SHAPE_SPHERE ? prim_sphere(m, (float)a, seg, e) : prim_disk(m, (float)a, seg, e));
        break;
    case SHAPE_CYLINDER:
    case SHAPE_CONE:
        ok = rd_number(r, idx, "radius", POS_LENGTH, false, 1, &a) && rd_number(r, idx, "height", POS_LENGTH, false, 1, &b) &&
             rd_int(r, idx, "segments", 3, 4096, false, 64, &seg) &&
             (shape == SHAPE_CYLINDER ? prim_cylinder(m, (float)a, (float)b, seg, e) : prim_cone(m, (float)a, (float)b, seg, e));
        break;
    case SHAPE_TORUS:
        ok = rd_number(r, idx, "major", POS_LENGTH, false, 1, &a) && rd_number(r, idx, "minor", POS_LENGTH, false, 0.25, &b) &&
             rd_int(r, idx, "segments", 3, 4096, false, 64, &seg) && prim_torus(m, (float)a, (float)b, seg, e);
        break;
    case SHAPE_HEIGHTFIELD: return build_heightfield(r, idx, m, ctx);
    default: return build_model(r, idx, o, ctx);
    }
    if (shape != SHAPE_MESH) snprintf(o->source, sizeof o->source, "procedural:%s", shape_names[shape]);
    return ok;
}

/* scale (number or {x,y,z}), then rotate {x,y,z} degrees about X, Y, Z in
 * that order, then translate. */
static bool read_transform(LuaReader *r, int idx, mat34 *M)
{
    vec3 t, rot, s = v3(1, 1, 1);
    if (!rd_vec3(r, idx, "translate", ANY_COORD, false, v3(0, 0, 0), &t) ||
        !rd_vec3(r, idx, "rotate", RANGE_CLOSED(-1e6, 1e6), false, v3(0, 0, 0), &rot))
        return false;
    if (rd_get(r, idx, "scale")) {
        bool scalar = lua_type(r->L, -1) == LUA_TNUMBER;
        lua_pop(r->L, 1);
        double k;
        if (scalar && !rd_number(r, idx, "scale", POS_LENGTH, true, 1, &k)) return false;
        if (!scalar && !rd_vec3(r, idx, "scale", POS_LENGTH, true, s, &s)) return false;
        if (scalar) s = v3((float)k, (float)k, (float)k);
    }
    *M = transform_srt(s, rot, t);
    return true;
}

/* A procedural sphere (object space: centred at the origin) keeps its
 * analytic form when M scales it uniformly: M's columns then have one length. */
static void record_sphere(Object *o, const mat34 *M)
{
    float len[3], r_object = 0.0f;
    for (int c = 0; c < 3; c++) len[c] = v3_len(v3(M->m[0][c], M->m[1][c], M->m[2][c]));
    if (fabsf(len[1] - len[0]) > 1e-6f * len[0] || fabsf(len[2] - len[0]) > 1e-6f * len[0]) return;
    for (int v = 0; v < o->mesh.num_vertices; v++) r_object = fmaxf(r_object, v3_len(o->mesh.positions[v]));
    o->is_sphere = true;
    o->sphere_center_world = v3(M->m[0][3], M->m[1][3], M->m[2][3]);
    o->sphere_radius_world = len[0] * r_object;
}

static bool read_object(LuaReader *r, int idx, Object *o, int index, const SceneLoadCtx *ctx)
{
    int shape;
    mat34 M;
    snprintf(o->name, sizeof o->name, "object%d", index);
    if (!rd_enum(r, idx, "shape", shape_names, true, 0, &shape) || !rd_only_keys(r, idx, shape_keys(shape)) ||
        !rd_string(r, idx, "name", o->name, o->name, sizeof o->name) ||
        !rd_bool(r, idx, "caster", true, &o->caster) || !rd_bool(r, idx, "receiver", true, &o->receiver) ||
        !rd_vec3(r, idx, "albedo", RANGE_CLOSED(0, 1), false, v3(0.8f, 0.8f, 0.8f), &o->albedo) ||
        !read_transform(r, idx, &M) || !build_shape(r, idx, shape, o, ctx))
        return false;
    *ctx->triangles += o->mesh.num_triangles;
    if (*ctx->triangles > MAX_TRIANGLES)
        return rd_fail(r, NULL, "brings the scene to %lld triangles, over its budget of %d", *ctx->triangles,
                       MAX_TRIANGLES);
    if (shape == SHAPE_SPHERE) record_sphere(o, &M);
    mesh_transform(&o->mesh, &M);
    return true;
}

/* ---- top level -------------------------------------------------------- */

/* Read t[key] as a list, calling fn on each element table. `alloc` gives the
 * scene its zeroed array of n elements before any element is read, so a load
 * cut short by a Lua error still frees what was built (scene_free). */
typedef bool (*ElementFn)(LuaReader *r, int idx, void *elem, int index, const SceneLoadCtx *ctx);
typedef void *(*ListAllocFn)(Scene *scene, int n);

static bool read_list(LuaReader *r, int idx, const char *key, int max, Scene *scene, ListAllocFn alloc,
                      size_t elem_size, ElementFn fn, const SceneLoadCtx *ctx)
{
    lua_State *L = r->L;
    if (!rd_get(r, idx, key) || !lua_istable(L, -1)) {
        lua_settop(L, idx);
        return rd_fail(r, key, "must be a list of tables");
    }
    int n = (int)luaL_len(L, -1);
    if (n < 1 || n > max) {
        lua_settop(L, idx);
        return rd_fail(r, key, "has %d entries, expected 1 to %d", n, max);
    }
    char *elems = alloc(scene, n);
    if (!elems) return rd_fail(r, key, "needs too much memory");
    int list = lua_gettop(L);
    size_t saved = rd_enter_key(r, key);
    bool ok = true;
    for (int i = 1; ok && i <= n; i++) {
        size_t inner = rd_enter_index(r, i);
        lua_rawgeti(L, list, i);
        ok = lua_istable(L, -1) ? fn(r, lua_gettop(L), elems + (size_t)(i - 1) * elem_size, i, ctx)
                                : rd_fail(r, NULL, "must be a table");
        lua_settop(L, list);
        rd_leave(r, inner);
    }
    rd_leave(r, saved);
    lua_settop(L, idx);
    return ok;
}

static void *alloc_lights(Scene *scene, int n)
{
    scene->lights = calloc((size_t)n, sizeof *scene->lights);
    scene->num_lights = scene->lights ? n : 0;
    return scene->lights;
}

static void *alloc_objects(Scene *scene, int n)
{
    scene->objects = calloc((size_t)n, sizeof *scene->objects);
    scene->num_objects = scene->objects ? n : 0;
    return scene->objects;
}

static bool light_elem(LuaReader *r, int idx, void *elem, int index, const SceneLoadCtx *ctx)
{
    (void)index;
    return read_light(r, idx, elem, ctx);
}

static bool object_elem(LuaReader *r, int idx, void *elem, int index, const SceneLoadCtx *ctx)
{
    return read_object(r, idx, elem, index, ctx);
}

bool scene_read_table(LuaReader *r, int idx, const SceneLoadCtx *ctx, Scene *scene)
{
    static const char *const keys[] = {"name", "camera", "lights", "objects", NULL};
    lua_State *L = r->L;
    idx = lua_absindex(L, idx);
    if (!rd_refuse_metatables(r, idx) || !rd_only_keys(r, idx, keys) ||
        !rd_string(r, idx, "name", scene->name, scene->name, sizeof scene->name))
        return false;
    if (!rd_get(r, idx, "camera") || !lua_istable(L, -1)) {
        lua_settop(L, idx);
        return rd_fail(r, "camera", "must be a table");
    }
    size_t saved = rd_enter_key(r, "camera");
    bool ok = read_camera(r, lua_gettop(L), &scene->camera);
    rd_leave(r, saved);
    lua_settop(L, idx);
    ok = ok && read_list(r, idx, "lights", MAX_LIGHTS, scene, alloc_lights, sizeof(Light), light_elem, ctx);
    ok = ok && read_list(r, idx, "objects", MAX_OBJECTS, scene, alloc_objects, sizeof(Object), object_elem, ctx);
    return ok;
}
