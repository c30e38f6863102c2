/* scene_build.h -- internal interface between the scene-file reader
 * (scene_lua.c) and scene assembly (scene.c, models.c). */
#ifndef SL_SCENE_BUILD_H
#define SL_SCENE_BUILD_H
#include <lua.h>
#include "scene/luaread.h"
#include "scene/sandbox.h"
#include "scene/scene.h"

typedef struct SceneLoadCtx {
    const char *path;   /* the scene file */
    char dir[SCENE_PATH_MAX]; /* its folder */
    Sandbox *sandbox;
    long long *triangles;     /* running total over the objects read so far */
} SceneLoadCtx;

/* Read the scene table at idx through r (its key path names the value being
 * read, also when a Lua error cuts the read short). */
bool scene_read_table(LuaReader *r, int idx, const SceneLoadCtx *ctx, Scene *scene);
/* One alternative file for a model, with the transform that maps it into the
 * frame of the scene's first alternative. */
#define MODEL_MAX_CHOICES 16
typedef struct ModelChoice {
    char name[SCENE_PATH_MAX];
    mat34 pre;
} ModelChoice;

/* Find the first of `choices` on the model search path, load it and apply its
 * pre-transform; the object's source records which file was used. */
bool scene_load_model(const SceneLoadCtx *ctx, const ModelChoice *choices, int n, Object *o, Error *err);
bool scene_load_light_image(const SceneLoadCtx *ctx, const char *name, Light *l, Error *err);
/* Model search path as one string, for messages and docs. */
void scene_model_path(const SceneLoadCtx *ctx, char *out, size_t n);

mat34 transform_srt(vec3 scale, vec3 rotate_deg, vec3 translate);
void mesh_transform(Mesh *m, const mat34 *M);

#endif
