/* scene_build.h -- internal interface between the scene-file reader
 * (scene_lua.c) and scene assembly (scene.c, models.c). */
#ifndef SL_SCENE_BUILD_H
#define SL_SCENE_BUILD_H
#include <lua.h>
#include "scene/sandbox.h"
#include "scene/scene.h"

typedef struct SceneLoadCtx {
    const char *path;   /* the scene file */
    char dir[SCENE_PATH_MAX]; /* its folder */
    Sandbox *sandbox;
} SceneLoadCtx;

bool scene_read_table(lua_State *L, int idx, const SceneLoadCtx *ctx, Scene *scene, Error *err);
/* Find the first of `names` on the model search path and load it. */
bool scene_load_model(const SceneLoadCtx *ctx, const char *const *names, int n, Object *o, Error *err);
bool scene_load_light_image(const SceneLoadCtx *ctx, const char *name, Light *l, Error *err);
/* Model search path as one string, for messages and docs. */
void scene_model_path(const SceneLoadCtx *ctx, char *out, size_t n);

mat34 transform_srt(vec3 scale, vec3 rotate_deg, vec3 translate);
void mesh_transform(Mesh *m, const mat34 *M);

#endif
