/* sandbox.h -- a Lua 5.4 state for untrusted scene files: only the base
 * (minus file and code loading), math, string, table and utf8 libraries; text
 * chunks only; a memory cap, an instruction budget and a time limit, so a
 * colleague's scene file cannot run commands, hang or exhaust memory. Library
 * functions whose C loops the instruction count cannot see are removed
 * (string.dump, the pattern functions, table.move) or charged their work
 * (string.rep, table.insert/remove); finalizers (__gc), which run with the
 * instruction hook off, are refused; once a limit is hit every further
 * instruction raises, so pcall cannot swallow it. */
#ifndef SL_SANDBOX_H
#define SL_SANDBOX_H
#include <stddef.h>
#include <lua.h>
#include "core/error.h"

#define SANDBOX_MEMORY_LIMIT ((size_t)64 << 20)  /* bytes: one VM instruction on the largest strings stays ~10 ms */
#define SANDBOX_INSTRUCTION_LIMIT 100000000L     /* Lua VM instructions per sandbox (~2 s), plus charged C work */
#define SANDBOX_TIME_LIMIT_S 20.0                /* wall clock, for instructions that copy or compare long strings */

typedef struct Sandbox Sandbox;

Sandbox *sandbox_open(Error *err);
void sandbox_close(Sandbox *sb);
lua_State *sandbox_state(Sandbox *sb);

/* Run a scene file; on success its returned table is on top of the stack. */
bool sandbox_run_file(Sandbox *sb, const char *path, Error *err);
/* Apply "a.b[2].c=value" to the table on top of the stack. The value is read
 * as a Lua expression (number, boolean, {1,2,3}, "text"); a bare word that is
 * not one is taken as a string. The path is followed and set raw (no
 * metamethod runs); it may raise a memory error, so call it inside
 * sandbox_protected. */
bool sandbox_apply_override(Sandbox *sb, const char *spec, Error *err);
/* Call fn(t, ud) protected, with t the table on top of the stack (left there)
 * and ud a light userdata; a Lua error raised inside (the memory cap, the
 * instruction budget, any error of a library call) becomes err, prefixed with
 * `path` as a scene file's own errors are. Returns false on such an error;
 * fn reports its own failures through ud. */
bool sandbox_protected(Sandbox *sb, lua_CFunction fn, void *ud, const char *path, Error *err);
/* Call the function at stack index fn_idx with nargs numbers; the number it
 * returns goes to *out. The instruction budget still applies. */
bool sandbox_call_number(Sandbox *sb, int fn_idx, const double *args, int nargs, double *out, Error *err);

#endif
