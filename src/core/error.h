/* error.h -- the one error channel of the engine.
 * Functions that can fail return bool (true = ok) and fill an Error with a
 * message naming the file, key or parameter and the valid range. The CLI turns
 * it into exit status 1, the Lua layer into a Lua error. */
#ifndef SL_ERROR_H
#define SL_ERROR_H
#include <stdbool.h>

#define ERROR_MSG_MAX 1024

typedef struct Error {
    char msg[ERROR_MSG_MAX];
} Error;

/* Format the message into err (if non-NULL) and return false, so that
 * `return error_set(err, "...")` reads as a failing return. */
bool error_set(Error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Prefix an existing message, e.g. with the file name: "scene.lua: <msg>". */
bool error_prefix(Error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
