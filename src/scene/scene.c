/* scene.c -- scene assembly: load the file through the sandbox and the
 * reader, then transform meshes to world space, compute bounds and the
 * content hashes that key resources and cached references. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "scene/scene_build.h"

mat34 transform_srt(vec3 s, vec3 rot_deg, vec3 t)
{
    mat34 M = {{{s.x, 0, 0, 0}, {0, s.y, 0, 0}, {0, 0, s.z, 0}}};
    float deg = (float)(M_PI / 180.0);
    float angles[3] = {rot_deg.x * deg, rot_deg.y * deg, rot_deg.z * deg};
    for (int axis = 0; axis < 3; axis++) {
        float c = cosf(angles[axis]), sn = sinf(angles[axis]);
        int i = (axis + 1) % 3, j = (axis + 2) % 3; /* rotate in the (i, j) plane */
        mat34 R = m34_identity();
        R.m[i][i] = c; R.m[i][j] = -sn;
        R.m[j][i] = sn; R.m[j][j] = c;
        M = m34_mul(&R, &M);
    }
    M.m[0][3] += t.x;
    M.m[1][3] += t.y;
    M.m[2][3] += t.z;
    return M;
}

void mesh_transform(Mesh *m, const mat34 *M)
{
    for (int i = 0; i < m->num_vertices; i++) m->positions[i] = m34_point(M, m->positions[i]);
    mesh_compute_normals(m);
}

static void hash_mesh(Hasher *h, const Object *o)
{
    hash_u64(h, (uint64_t)o->mesh.num_vertices);
    hash_bytes(h, o->mesh.positions, sizeof(vec3) * (size_t)o->mesh.num_vertices);
    hash_u64(h, (uint64_t)o->mesh.num_triangles);
    hash_bytes(h, o->mesh.indices, sizeof(uint32_t) * 3 * (size_t)o->mesh.num_triangles);
}

static uint64_t hash_light(const Light *l)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, (uint64_t)l->kind);
    const float f[] = {l->position.x, l->position.y, l->position.z, l->direction.x, l->direction.y, l->direction.z,
                       l->up.x, l->up.y, l->up.z, l->radius, l->width, l->height, l->cone_half_rad,
                       l->color.x, l->color.y, l->color.z, l->intensity};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) hash_f32(&h, f[i]);
    if (l->emission.data) {
        hash_u64(&h, (uint64_t)l->emission.width * 65536u + (uint64_t)l->emission.height);
        hash_bytes(&h, l->emission.data, sizeof(float) * image_count(&l->emission));
    }
    return hash_final(&h);
}

static uint64_t hash_camera(const Camera *c)
{
    Hasher h;
    hash_init(&h);
    const float f[] = {c->position.x, c->position.y, c->position.z, c->target.x, c->target.y, c->target.z,
                       c->up.x, c->up.y, c->up.z, c->fov_y_rad, c->near_dist, c->far_dist};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) hash_f32(&h, f[i]);
    hash_u64(&h, (uint64_t)c->width);
    hash_u64(&h, (uint64_t)c->height);
    hash_u64(&h, (uint64_t)c->supersample);
    return hash_final(&h);
}

static bool finalize(Scene *s, Error *err)
{
    Hasher geo, cast, all;
    hash_init(&geo);
    hash_init(&cast);
    s->bounds_min = v3(INFINITY, INFINITY, INFINITY);
    s->bounds_max = v3(-INFINITY, -INFINITY, -INFINITY);
    s->num_triangles = 0;
    for (int i = 0; i < s->num_objects; i++) {
        const Object *o = &s->objects[i];
        for (int v = 0; v < o->mesh.num_vertices; v++) {
            if (!v3_finite(o->mesh.positions[v]))
                return error_set(err, "%s: objects[%d]: vertex %d is not finite after its transform", s->path, i + 1, v);
            s->bounds_min = v3_min(s->bounds_min, o->mesh.positions[v]);
            s->bounds_max = v3_max(s->bounds_max, o->mesh.positions[v]);
        }
        if (o->mesh.num_triangles > INT32_MAX - s->num_triangles)
            return error_set(err, "%s: more than %d triangles in all", s->path, INT32_MAX);
        s->num_triangles += o->mesh.num_triangles;
        hash_mesh(&geo, o);
        const float flags[] = {o->caster, o->receiver, o->albedo.x, o->albedo.y, o->albedo.z};
        for (int k = 0; k < 5; k++) hash_f32(&geo, flags[k]);
        if (o->caster) hash_mesh(&cast, o);
    }
    s->hash_geometry = hash_final(&geo);
    s->hash_casters = hash_final(&cast);
    s->hash_camera = hash_camera(&s->camera);
    s->hash_lights = calloc((size_t)s->num_lights, sizeof(uint64_t));
    if (!s->hash_lights) return error_set(err, "out of memory");
    hash_init(&all);
    hash_u64(&all, s->hash_geometry);
    hash_u64(&all, s->hash_camera);
    for (int i = 0; i < s->num_lights; i++) {
        s->hash_lights[i] = hash_light(&s->lights[i]);
        hash_u64(&all, s->hash_lights[i]);
    }
    s->hash = hash_final(&all);
    return true;
}

static void dir_of(const char *path, char *out, size_t n)
{
    const char *slash = strrchr(path, '/');
    if (!slash) snprintf(out, n, ".");
    else snprintf(out, n, "%.*s", (int)(slash - path), path);
}

static void default_name(const char *path, char *out, size_t n)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    snprintf(out, n, "%.*s", dot ? (int)(dot - base) : (int)strlen(base), base);
}

/* Everything of a load that reads Lua values runs inside one protected call
 * (sandbox_protected): the overrides, the refusal of metatables and the
 * table reader. A memory or budget error raised by the Lua API while C code
 * reads becomes the load's error instead of reaching Lua's panic handler
 * (SIGABRT); metatables are refused before any read could run one. */
typedef struct ReadJob {
    SceneLoadCtx *ctx;
    const char *const *overrides;
    int num_overrides;
    Scene *scene;
    LuaReader reader;
    bool ok;
} ReadJob;

static int read_protected(lua_State *L)
{
    ReadJob *j = lua_touserdata(L, 2);
    lua_settop(L, 1); /* the scene table */
    Error *err = j->reader.err;
    j->ok = true;
    for (int i = 0; j->ok && i < j->num_overrides; i++) {
        j->ok = sandbox_apply_override(j->ctx->sandbox, j->overrides[i], err);
        if (!j->ok) error_prefix(err, "%s: ", j->ctx->path);
    }
    j->ok = j->ok && scene_read_table(&j->reader, 1, j->ctx, j->scene);
    return 0;
}

bool scene_load(const char *path, const char *const *overrides, int num_overrides, Scene *scene, Error *err)
{
    memset(scene, 0, sizeof *scene);
    snprintf(scene->path, sizeof scene->path, "%s", path);
    default_name(path, scene->name, sizeof scene->name);
    long long triangles = 0;
    SceneLoadCtx ctx = {.path = path, .triangles = &triangles};
    dir_of(path, ctx.dir, sizeof ctx.dir);
    ctx.sandbox = sandbox_open(err);
    if (!ctx.sandbox) return false;
    ReadJob job = {&ctx, overrides, num_overrides, scene, {.L = sandbox_state(ctx.sandbox), .file = path, .err = err}, false};
    bool ok = sandbox_run_file(ctx.sandbox, path, err);
    if (ok && !sandbox_protected(ctx.sandbox, read_protected, &job, path, err)) {
        ok = false;
        size_t n = strnlen(err->msg, sizeof err->msg);
        if (job.reader.path[0] && n < sizeof err->msg)
            snprintf(err->msg + n, sizeof err->msg - n, " (while reading %s)", job.reader.path);
    }
    ok = ok && job.ok && finalize(scene, err);
    sandbox_close(ctx.sandbox);
    if (!ok) scene_free(scene);
    return ok;
}

void scene_free(Scene *s)
{
    for (int i = 0; s->objects && i < s->num_objects; i++) mesh_free(&s->objects[i].mesh);
    for (int i = 0; s->lights && i < s->num_lights; i++) image_free(&s->lights[i].emission);
    free(s->objects);
    free(s->lights);
    free(s->hash_lights);
    s->objects = NULL;
    s->lights = NULL;
    s->hash_lights = NULL;
    s->num_objects = s->num_lights = 0;
}

float scene_extent(const Scene *s)
{
    float e = v3_len(v3_sub(s->bounds_max, s->bounds_min));
    return isfinite(e) && e > 1e-30f ? e : 1e-30f;
}

bool scene_all_cast(const Scene *s)
{
    for (int i = 0; i < s->num_objects; i++)
        if (!s->objects[i].caster) return false;
    return true;
}
