/* models.c -- the model search path and loading of model files and light
 * images named by scene files. Search order: the scene's folder, its models/
 * subfolder, the project's scenes/models/ (next to the executable's build/),
 * each folder of $SHADOWLAB_MODEL_PATH (colon-separated), then Debian's
 * glmark2-data models folder. The first file found is used and recorded. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/fsutil.h"
#include "io/image_io.h"
#include "scene/scene_build.h"

#define GLMARK2_MODELS "/usr/share/glmark2/models"
#define MAX_DIRS 32

typedef struct SearchPath { char dirs[MAX_DIRS][SCENE_PATH_MAX]; int n; } SearchPath;

static void add_dir(SearchPath *sp, const char *dir)
{
    if (sp->n < MAX_DIRS && dir[0]) snprintf(sp->dirs[sp->n++], SCENE_PATH_MAX, "%s", dir);
}

static void project_models_dir(char *out, size_t n)
{
    char exe[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    out[0] = '\0';
    if (len <= 0) return;
    exe[len] = '\0';
    char *slash = strrchr(exe, '/');
    if (slash) *slash = '\0';
    snprintf(out, n, "%s/../scenes/models", exe);
}

static void search_path(const SceneLoadCtx *ctx, SearchPath *sp)
{
    char buf[SCENE_PATH_MAX];
    sp->n = 0;
    add_dir(sp, ctx->dir);
    snprintf(buf, sizeof buf, "%s/models", ctx->dir);
    add_dir(sp, buf);
    project_models_dir(buf, sizeof buf);
    add_dir(sp, buf);
    const char *env = getenv("SHADOWLAB_MODEL_PATH");
    while (env && *env) {
        const char *colon = strchr(env, ':');
        size_t len = colon ? (size_t)(colon - env) : strlen(env);
        snprintf(buf, sizeof buf, "%.*s", (int)len, env);
        add_dir(sp, buf);
        env = colon ? colon + 1 : NULL;
    }
    add_dir(sp, GLMARK2_MODELS);
}

void scene_model_path(const SceneLoadCtx *ctx, char *out, size_t n)
{
    SearchPath sp;
    search_path(ctx, &sp);
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < sp.n && used + 1 < n; i++)
        used += (size_t)snprintf(out + used, n - used, "%s%s", i ? ":" : "", sp.dirs[i]);
}

/* Resolve `name` (absolute, or relative to the search path) to an existing file. */
static bool find_file(const SceneLoadCtx *ctx, const char *name, char *out, size_t n)
{
    if (name[0] == '/') {
        snprintf(out, n, "%s", name);
        return file_exists(out);
    }
    SearchPath sp;
    search_path(ctx, &sp);
    for (int i = 0; i < sp.n; i++) {
        snprintf(out, n, "%s/%s", sp.dirs[i], name);
        if (file_exists(out)) return true;
    }
    return false;
}

bool scene_load_model(const SceneLoadCtx *ctx, const ModelChoice *choices, int n, Object *o, Error *err)
{
    char path[SCENE_PATH_MAX];
    for (int i = 0; i < n; i++) {
        if (!find_file(ctx, choices[i].name, path, sizeof path)) continue;
        snprintf(o->source, sizeof o->source, "%s", path);
        if (!mesh_load(path, &o->mesh, err)) return false;
        mesh_transform(&o->mesh, &choices[i].pre);
        return true;
    }
    char where[4096], tried[1024] = "";
    scene_model_path(ctx, where, sizeof where);
    for (int i = 0, used = 0; i < n && used < (int)sizeof tried - 2; i++)
        used += snprintf(tried + used, sizeof tried - (size_t)used, "%s%s", i ? ", " : "", choices[i].name);
    return error_set(err, "model not found: %s (searched %s; set SHADOWLAB_MODEL_PATH)", tried, where);
}

/* Emission weights visibility (reference.h): a NaN, infinite or negative
 * texel would spread into every sample's value, so it is refused here. */
static bool check_emission(const char *path, Image *img, Error *err)
{
    size_t n = image_count(img);
    for (size_t i = 0; i < n; i++) {
        float v = img->data[i];
        if (isfinite(v) && v >= 0.0f) continue;
        size_t px = i / (size_t)img->channels;
        error_set(err, "%s: texel (%zu, %zu) channel %zu = %g: emission must be finite and >= 0", path,
                  px % (size_t)img->width, px / (size_t)img->width, i % (size_t)img->channels, v);
        image_free(img);
        return false;
    }
    return true;
}

bool scene_load_light_image(const SceneLoadCtx *ctx, const char *name, Light *l, Error *err)
{
    char path[SCENE_PATH_MAX];
    if (!find_file(ctx, name, path, sizeof path)) {
        char where[4096];
        scene_model_path(ctx, where, sizeof where);
        return error_set(err, "image not found: %s (searched %s)", name, where);
    }
    snprintf(l->image_path, sizeof l->image_path, "%s", path);
    return image_load_any(path, &l->emission, err) && check_emission(path, &l->emission, err);
}
