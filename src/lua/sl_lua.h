/* sl_lua.h -- the Lua bindings' internal interface (Lua 5.4 C API): the
 * userdata type names, the error bridge (an Error becomes a Lua error at the
 * caller's line), and what each binding file contributes to the module. The
 * bindings translate; lab/compare.h computes. */
#ifndef SL_LUA_H
#define SL_LUA_H
#include <lauxlib.h>
#include <lua.h>
#include "lab/compare.h"

#define SL_LAB_TYPE "shadowlab.Lab"
#define SL_RUN_TYPE "shadowlab.Run"
#define SL_IMAGE_TYPE "shadowlab.Image"

int luaopen_shadowlab(lua_State *L);
/* The project root (holding lua/ and scenes/) for modules opened after this
 * call; the CLI sets it from its executable, a plain `require` finds it from
 * the shared object's own path. */
void sl_lua_set_root(const char *root);

/* Raise err's message as a Lua error at the calling line; never returns. */
int sl_raise(lua_State *L, const Error *err);

/* ltechnique.c: the registry seen from Lua. */
void sl_push_technique(lua_State *L, const Technique *t);
const Technique *sl_check_technique(lua_State *L, int idx);
/* Defaults, then the table at idx (nil: defaults only); a wrong name or an
 * out-of-range value raises the registry's message (parameter and range). */
void sl_check_params(lua_State *L, int idx, const Technique *t, double *values);
/* name -> value: numbers, booleans, enum names. */
void sl_push_params(lua_State *L, const Technique *t, const double *values);
int sl_techniques(lua_State *L);
int sl_technique(lua_State *L);
int sl_params(lua_State *L);

/* llab.c: sl.open and the Lab methods. */
int sl_lab_open(lua_State *L);
void sl_register_lab(lua_State *L);
/* The open Lab of the userdata at idx (raises on a closed one). */
Lab *sl_check_lab(lua_State *L, int idx);
/* laliasing.c: lab:aliasing{...}, added to the Lab's methods. */
void sl_register_aliasing(lua_State *L);

/* lrun.c: a finished comparison (owns its images; independent of its Lab). */
void sl_register_run(lua_State *L);
/* Push a Run for `res` (moved into the userdata) and attach the record of
 * `rep` (decoded with shadowlab.json). */
void sl_push_run(lua_State *L, CompareResult *res, const RunReport *rep);

/* limage.c: float images. */
void sl_register_image(lua_State *L);
/* A new Image userdata holding a copy of img. */
void sl_push_image_copy(lua_State *L, const Image *img);

/* lfs.c: durable files for the records (fsync, atomic writes, listings). */
extern const luaL_Reg sl_fs_funcs[];

#endif
