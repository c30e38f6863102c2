/* luaread.h -- validated reading of Lua tables with key paths in errors.
 * Every failure names the file, the key path (e.g. lights[1].radius), the
 * problem and the valid range: "scenes/x.lua: lights[1].radius = -1 outside
 * (0, 1e+07]". The reader keeps the current path as a string. */
#ifndef SL_LUAREAD_H
#define SL_LUAREAD_H
#include <lua.h>
#include "core/error.h"
#include "core/vec.h"

typedef struct LuaReader {
    lua_State *L;
    const char *file;
    char path[512];
    Error *err;
} LuaReader;

/* Range of a number: lo/hi with open or closed ends. */
typedef struct Range { double lo, hi; bool lo_open, hi_open; } Range;
#define RANGE_CLOSED(a, b) ((Range){(a), (b), false, false})
#define RANGE_POSITIVE(b) ((Range){0.0, (b), true, false})

bool rd_fail(LuaReader *r, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Path bookkeeping: rd_enter returns the old length to pass to rd_leave. */
size_t rd_enter_key(LuaReader *r, const char *key);
size_t rd_enter_index(LuaReader *r, int index);
void rd_leave(LuaReader *r, size_t saved);

/* Refuse a metatable on the table at idx or on any table reachable from it
 * (keys and values, at any depth): the reader's lua_getfield, luaL_len and
 * luaL_tolstring would run __index, __len or __tostring, and a metamethod
 * could error, loop or allocate where no protected call catches it. Nesting
 * deeper than RD_MAX_DEPTH is refused too (the walk recurses in C). Names the
 * key path of the offending table. */
#define RD_MAX_DEPTH 32
bool rd_refuse_metatables(LuaReader *r, int idx);

/* Refuse keys of the table at idx that are not in `allowed` (NULL-terminated). */
bool rd_only_keys(LuaReader *r, int idx, const char *const *allowed);
/* Push t[key]; returns false (nothing pushed) when absent. */
bool rd_get(LuaReader *r, int idx, const char *key);

bool rd_number(LuaReader *r, int idx, const char *key, Range range, bool required, double def, double *out);
bool rd_int(LuaReader *r, int idx, const char *key, int lo, int hi, bool required, int def, int *out);
bool rd_bool(LuaReader *r, int idx, const char *key, bool def, bool *out);
/* Optional string; *out = def when absent. */
bool rd_string(LuaReader *r, int idx, const char *key, const char *def, char *out, size_t n);
/* String chosen from names (NULL-terminated); *out is its index. */
bool rd_enum(LuaReader *r, int idx, const char *key, const char *const *names, bool required, int def, int *out);
/* {x, y, z} with each component in range. */
bool rd_vec3(LuaReader *r, int idx, const char *key, Range range, bool required, vec3 def, vec3 *out);
/* {a, b} pair. */
bool rd_vec2(LuaReader *r, int idx, const char *key, Range range, bool required, const double def[2], double out[2]);

#endif
