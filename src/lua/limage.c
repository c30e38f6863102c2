/* limage.c -- the Image userdata: a float image (visibility, reference,
 * standard error or signed error) with its size, pixel access (1-based x, y
 * and channel, row 1 at the top) and saving as EXR (channels V or R,G,B) or,
 * by extension, as an 8-bit PNG/JPEG through the OpenImageIO plugin. */
#include <string.h>
#include "io/exr.h"
#include "io/image_file.h"
#include "lua/sl_lua.h"

static Image *check_image(lua_State *L) { return luaL_checkudata(L, 1, SL_IMAGE_TYPE); }

void sl_push_image_copy(lua_State *L, const Image *src)
{
    Image *img = lua_newuserdatauv(L, sizeof *img, 0);
    memset(img, 0, sizeof *img);
    luaL_setmetatable(L, SL_IMAGE_TYPE);
    Error err;
    if (!image_init(img, src->width, src->height, src->channels, &err)) sl_raise(L, &err);
    memcpy(img->data, src->data, image_count(src) * sizeof(float));
    lua_gc(L, LUA_GCSTEP, (int)(image_count(src) * sizeof(float) / 1024)); /* pixels the collector cannot see */
}

/* img:size() -> width, height, channels */
static int image_size(lua_State *L)
{
    Image *img = check_image(L);
    lua_pushinteger(L, img->width);
    lua_pushinteger(L, img->height);
    lua_pushinteger(L, img->channels);
    return 3;
}

/* img:get(x, y [, c]) with 1-based coordinates. */
static int image_get(lua_State *L)
{
    Image *img = check_image(L);
    lua_Integer x = luaL_checkinteger(L, 2), y = luaL_checkinteger(L, 3), c = luaL_optinteger(L, 4, 1);
    luaL_argcheck(L, x >= 1 && x <= img->width, 2, "x outside [1, width]");
    luaL_argcheck(L, y >= 1 && y <= img->height, 3, "y outside [1, height]");
    luaL_argcheck(L, c >= 1 && c <= img->channels, 4, "channel outside [1, channels]");
    lua_pushnumber(L, image_px(img, (int)x - 1, (int)y - 1)[c - 1]);
    return 1;
}

static bool ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* img:save(path): .exr keeps the floats; other extensions store 8 bits. */
static int image_save(lua_State *L)
{
    Image *img = check_image(L);
    const char *path = luaL_checkstring(L, 2);
    Error err;
    bool ok;
    if (ends_with(path, ".exr")) {
        static const char *const rgb[] = {"R", "G", "B"};
        ExrChannel ch[3];
        for (int c = 0; c < img->channels && c < 3; c++)
            ch[c] = (ExrChannel){img->channels == 1 ? "V" : rgb[c], img->data + c, img->channels};
        ok = exr_write(path, img->width, img->height, ch, img->channels < 3 ? img->channels : 3, NULL, 0, &err);
    } else {
        ok = image_write_ldr(path, img, false, &err);
    }
    if (!ok) sl_raise(L, &err);
    return 0;
}

static int image_gc(lua_State *L)
{
    image_free(check_image(L));
    return 0;
}

static int image_tostring(lua_State *L)
{
    Image *img = check_image(L);
    lua_pushfstring(L, "shadowlab.Image(%dx%d, %d channels)", img->width, img->height, img->channels);
    return 1;
}

void sl_register_image(lua_State *L)
{
    static const luaL_Reg methods[] = {{"size", image_size}, {"get", image_get}, {"save", image_save}, {NULL, NULL}};
    static const luaL_Reg meta[] = {{"__gc", image_gc}, {"__tostring", image_tostring}, {NULL, NULL}};
    luaL_newmetatable(L, SL_IMAGE_TYPE);
    luaL_setfuncs(L, meta, 0);
    luaL_newlib(L, methods);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
}
