/* test_lua_bindings.c -- the shadowlab Lua module under the sanitizers: a
 * sweep-like loop of comparisons, images and records, bad parameters raised
 * as Lua errors naming the parameter and its range, a Run that outlives its
 * closed Lab, and lua_close collecting every Lab, Run and Image (LeakSanitizer
 * checks that nothing is left at exit). */
#include <lauxlib.h>
#include <lualib.h>
#include <unistd.h>
#include "fixtures.h"
#include "lua/sl_lua.h"
#include "test.h"

static const char *const lua_scene =
    "return {\n"
    "  camera = { position = {0, 3, 5}, target = {0, 0.4, 0}, width = 40, height = 30 },\n"
    "  lights = { { type = 'sphere', position = {1, 4, 1}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane', size = {8, 8} }, { shape = 'sphere', radius = 0.5, translate = {0, 0.8, 0} } },\n"
    "}\n";

static const char *const lua_code =
    "local sl = require 'shadowlab'\n"
    "local lab = sl.open(SCENE, { ['lights[1].radius'] = 0.3 })\n"
    "local keys = {}\n"
    "for i = 1, 12 do\n"
    "  local run = lab:compare{ technique = 'hard', params = { offset_scale = i }, samples = 8, cache = false,\n"
    "                           repeats = 2, warmup = 1 }\n"
    "  local rec = run:record()\n"
    "  assert(rec.technique.params.offset_scale == i, 'params in the record')\n"
    "  assert(rec.timings_s['repeat'] == 2 and rec.timings_s.warmup == 1, 'repeats and warm-up recorded')\n"
    "  assert(rec.resource_cache == (i == 1 and 'cold' or 'warm'), 'cold first, then warm: ' .. rec.resource_cache)\n"
    "  assert(#rec.technique_resources == 1 and rec.timings_s.frame >= rec.timings_s.technique_build)\n"
    "  assert(type(run:metrics().all.rmse) == 'number')\n"
    "  local w, h, c = run:image('visibility'):size()\n"
    "  assert(w == 40 and h == 30 and c == 1)\n"
    "  keys[lab:key('hard', { offset_scale = i })] = true\n"
    "end\n"
    "local n = 0 for _ in pairs(keys) do n = n + 1 end\n"
    "assert(n == 12, 'distinct keys per parameter value')\n"
    "assert(lab:key('hard', { offset_scale = 1 }) == lab:key('hard', { offset_scale = 1.0 }))\n"
    "assert(lab:key('hard', {}) == lab:key('hard', { offset_scale = 1 }), 'defaults are part of the key')\n"
    "local ok, msg = pcall(lab.compare, lab, { technique = 'hard', params = { offset_scale = -2 }, samples = 4 })\n"
    "assert(not ok and msg:find('offset_scale', 1, true) and msg:find('[0, 10000]', 1, true), msg)\n"
    "ok, msg = pcall(lab.compare, lab, { technique = 'hard', params = { nope = 1 } })\n"
    "assert(not ok and msg:find(\"unknown parameter 'nope'\", 1, true), msg)\n"
    "ok, msg = pcall(lab.compare, lab, { technique = 'hard', sample = 4 })\n"
    "assert(not ok and msg:find(\"unknown option 'sample'\", 1, true), msg)\n"
    "local rotate_when\n"
    "for _, p in ipairs(sl.technique('pcss').params) do\n"
    "  if p.name == 'rotate' then rotate_when = p.acts_when end\n"
    "  assert(p.name ~= 'warp_n', 'a parameter pcss cannot use is not listed')\n"
    "end\n"
    "assert(rotate_when == 'sampling=poisson', 'the condition in the description')\n"
    "ok, msg = pcall(sl.open, SCENE, { ['lights[1].radius'] = 0/0 })\n"
    "assert(not ok and msg:find('lights[1].radius', 1, true) and msg:find('is NaN', 1, true), msg)\n"
    "local ref = lab:reference{ samples = 8, cache = false }\n"
    "local img = ref:image('reference')\n"
    "lab:close()\n"
    "assert(img:get(1, 1) >= 0 and ref:record().reference.samples == 8, 'runs outlive their lab')\n"
    "assert(not pcall(lab.info, lab), 'a closed lab refuses work')\n"
    "collectgarbage() collectgarbage()\n";

TEST(test_lua_bindings_sweep_errors_and_collection)
{
    char cwd[4096];
    CHECK(getcwd(cwd, sizeof cwd));
    sl_lua_set_root(cwd); /* the suite runs from the project root (tests/run.sh) */
    lua_State *L = luaL_newstate();
    CHECK(L);
    luaL_openlibs(L);
    luaL_requiref(L, "shadowlab", luaopen_shadowlab, 0);
    lua_pop(L, 1);
    lua_pushstring(L, fixture_file("lua-scene.lua", lua_scene));
    lua_setglobal(L, "SCENE");
    int status = luaL_dostring(L, lua_code);
    const char *msg = status == LUA_OK ? "" : lua_tostring(L, -1);
    char copy[1024];
    snprintf(copy, sizeof copy, "%s", msg ? msg : "(no message)");
    lua_close(L);
    CHECK_MSG(status == LUA_OK, "%s", copy);
}
