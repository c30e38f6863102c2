/* lfs.c -- the file operations the Lua records need and plain Lua lacks:
 * fsync of an open file and of a folder (a row survives power loss once
 * appended), atomic whole-file writes (core/fsutil.h), mkdir -p, and sorted
 * folder listings (merge reads shard folders). Failures raise errors naming
 * the path. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "core/fsutil.h"
#include "lua/sl_lua.h"

/* sl.fsync(file): flush a Lua file handle and fsync it. */
static int fs_fsync(lua_State *L)
{
    luaL_Stream *s = luaL_checkudata(L, 1, LUA_FILEHANDLE);
    if (!s->closef) return luaL_error(L, "sl.fsync: the file is closed");
    if (fflush(s->f) != 0 || fsync(fileno(s->f)) != 0) return luaL_error(L, "sl.fsync: %s", strerror(errno));
    return 0;
}

/* sl.fsync_dir(path): make a new file's directory entry durable. */
static int fs_fsync_dir(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    int fd = open(path, O_RDONLY | O_DIRECTORY);
    if (fd < 0) return luaL_error(L, "%s: %s", path, strerror(errno));
    int rc = fsync(fd);
    int e = errno;
    close(fd);
    if (rc != 0) return luaL_error(L, "%s: fsync: %s", path, strerror(e));
    return 0;
}

/* sl.write_file(path, text): temporary sibling, fsync, rename. */
static int fs_write_file(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    size_t len;
    const char *text = luaL_checklstring(L, 2, &len);
    AtomicFile af;
    Error err;
    if (!atomic_open(&af, path, &err)) return sl_raise(L, &err);
    if (fwrite(text, 1, len, af.fp) != len) {
        atomic_abort(&af);
        return luaL_error(L, "%s: write failed: %s", path, strerror(errno));
    }
    if (!atomic_commit(&af, &err)) return sl_raise(L, &err);
    return 0;
}

static int fs_mkdir(lua_State *L)
{
    Error err;
    if (!mkdir_p(luaL_checkstring(L, 1), &err)) return sl_raise(L, &err);
    return 0;
}

static int fs_isdir(lua_State *L)
{
    struct stat st;
    lua_pushboolean(L, stat(luaL_checkstring(L, 1), &st) == 0 && S_ISDIR(st.st_mode));
    return 1;
}

static int compare_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* sl.dir(path): the entries' names, sorted, without . and ..; nil, message
 * when the folder cannot be read. */
static int fs_dir(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    DIR *d = opendir(path);
    if (!d) {
        lua_pushnil(L);
        lua_pushfstring(L, "%s: %s", path, strerror(errno));
        return 2;
    }
    char **names = NULL;
    size_t n = 0, cap = 0;
    bool ok = true;
    for (struct dirent *e; ok && (e = readdir(d));) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 32;
            char **nn = realloc(names, cap * sizeof *nn);
            ok = nn != NULL;
            if (ok) names = nn;
        }
        if (ok) ok = (names[n] = strdup(e->d_name)) != NULL;
        if (ok) n++;
    }
    closedir(d);
    if (ok) qsort(names, n, sizeof *names, compare_names);
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        lua_pushstring(L, names[i]);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
        free(names[i]);
    }
    free(names);
    if (!ok) return luaL_error(L, "%s: out of memory listing the folder", path);
    return 1;
}

const luaL_Reg sl_fs_funcs[] = {
    {"fsync", fs_fsync},   {"fsync_dir", fs_fsync_dir}, {"write_file", fs_write_file},
    {"mkdir", fs_mkdir},   {"isdir", fs_isdir},         {"dir", fs_dir},
    {NULL, NULL},
};
