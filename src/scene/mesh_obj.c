/* mesh_obj.c -- strict Wavefront OBJ reader. Reads the whole file and parses
 * it in place, line by line: v, vt, vn and f (v, v/vt, v//vn, v/vt/vn, negative
 * indices, polygons fan-triangulated); o, g, s, usemtl, mtllib, l, p ignored.
 * Anything else stops the load with "<path>:<line>: <problem>". */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "scene/mesh_builder.h"

/* Growable array; len and cap count elements of `size` bytes. */
typedef struct ObjReader {
    const char *path;
    Error *err;
    long line;
    MeshBuilder mb;              /* vertices and triangles read so far */
    size_t num_texcoords;   /* counted only to check face references */
    size_t num_normals;
} ObjReader;

static const char *const obj_ignored[] = {"o", "g", "s", "usemtl", "mtllib", "l", "p"};

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
static bool at_end(char c) { return c == '\0' || c == '#'; }
static bool at_token_end(char c) { return at_end(c) || is_space(c); }
static bool is_digit(char c) { return c >= '0' && c <= '9'; }

static const char *skip_space(const char *s)
{
    while (is_space(*s)) s++;
    return s;
}

/* Length of the token at s, capped for quoting in messages. */
static int token_len(const char *s)
{
    int n = 0;
    while (n < 40 && !at_token_end(s[n])) n++;
    return n;
}

static bool obj_fail(ObjReader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static bool obj_fail(ObjReader *r, const char *fmt, ...)
{
    char msg[ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return error_set(r->err, "%s:%ld: %s", r->path, r->line, msg);
}

/* Parse min..max finite numbers after keyword kw into out; `what` names them
 * in the message for a non-finite value. */
static bool obj_numbers(ObjReader *r, const char *s, const char *kw, const char *what, int min, int max,
                        float *out)
{
    int n = 0;
    for (s = skip_space(s); !at_end(*s); s = skip_space(s)) {
        if (n == max) return obj_fail(r, "expected at most %d numbers after '%s'", max, kw);
        char *e;
        float v = strtof(s, &e);
        if (e == s || !at_token_end(*e))
            return obj_fail(r, "malformed number '%.*s' after '%s'", token_len(s), s, kw);
        if (!isfinite(v)) return obj_fail(r, "%s is not finite (%.*s)", what, token_len(s), s);
        out[n++] = v;
        s = e;
    }
    if (n < min) return obj_fail(r, "expected %d number%s after '%s', got %d", min, min == 1 ? "" : "s", kw, n);
    return true;
}

static bool obj_vertex(ObjReader *r, const char *s)
{
    float v[4];
    if (!obj_numbers(r, s, "v", "vertex coordinate", 3, 4, v)) return false;
    const char *why = mb_add_vertex(&r->mb, v3(v[0], v[1], v[2]));
    return !why || obj_fail(r, "%s", why);
}

/* vt or vn: validated and counted, values unused. */
static bool obj_attribute(ObjReader *r, const char *s, const char *kw, const char *what, int min,
                          size_t *count)
{
    float v[3];
    if (!obj_numbers(r, s, kw, what, min, 3, v)) return false;
    (*count)++;
    return true;
}

/* One index of a face vertex token `tok`, checked against the `count` items
 * defined so far (1-based, or negative = relative); *out is 0-based. */
static bool obj_index(ObjReader *r, const char **sp, const char *tok, const char *what, size_t count,
                      size_t *out)
{
    const char *s = *sp;
    char *e = (char *)s;
    long v = (*s == '-' || is_digit(*s)) ? strtol(s, &e, 10) : 0;
    if (e == s) return obj_fail(r, "malformed face vertex '%.*s'", token_len(tok), tok);
    long n = (long)count;
    long i = v > 0 ? v - 1 : n + v;
    if (v < 0 && i < 0) return obj_fail(r, "%s index %ld out of range [-%ld, -1]", what, v, n);
    if (i < 0 || i >= n) return obj_fail(r, "%s index %ld out of range [1, %ld]", what, v, n);
    *out = (size_t)i;
    *sp = e;
    return true;
}

/* A face vertex: v, v/vt, v//vn or v/vt/vn. */
static bool obj_face_vertex(ObjReader *r, const char **sp, uint32_t *out)
{
    const char *tok = *sp, *s = tok;
    size_t v, unused;
    if (!obj_index(r, &s, tok, "face", r->mb.num_pos, &v)) return false;
    if (*s == '/') {
        s++;
        if (*s != '/' && !obj_index(r, &s, tok, "texture", r->num_texcoords, &unused)) return false;
        if (*s == '/') {
            s++;
            if (!obj_index(r, &s, tok, "normal", r->num_normals, &unused)) return false;
        }
    }
    if (!at_token_end(*s)) return obj_fail(r, "malformed face vertex '%.*s'", token_len(tok), tok);
    *out = (uint32_t)v;
    *sp = s;
    return true;
}

static bool obj_triangle(ObjReader *r, uint32_t a, uint32_t b, uint32_t c)
{
    const char *why = mb_add_triangle(&r->mb, a, b, c);
    return !why || obj_fail(r, "%s", why);
}

/* f: a polygon of three or more vertices, fan-triangulated around the first. */
static bool obj_face(ObjReader *r, const char *s)
{
    uint32_t first = 0, prev = 0;
    long n = 0;
    for (s = skip_space(s); !at_end(*s); s = skip_space(s), n++) {
        uint32_t v = 0;
        if (!obj_face_vertex(r, &s, &v)) return false;
        if (n >= 2 && !obj_triangle(r, first, prev, v)) return false;
        if (n == 0) first = v;
        prev = v;
    }
    if (n < 3) return obj_fail(r, "face has %ld vertices, need at least 3", n);
    return true;
}

static bool word_is(const char *w, size_t n, const char *kw) { return strlen(kw) == n && memcmp(w, kw, n) == 0; }

static bool obj_statement(ObjReader *r, const char *s)
{
    s = skip_space(s);
    if (at_end(*s)) return true;
    const char *kw = s;
    while (!at_token_end(*s)) s++;
    size_t n = (size_t)(s - kw);
    if (word_is(kw, n, "v")) return obj_vertex(r, s);
    if (word_is(kw, n, "f")) return obj_face(r, s);
    if (word_is(kw, n, "vt")) return obj_attribute(r, s, "vt", "texture coordinate", 1, &r->num_texcoords);
    if (word_is(kw, n, "vn")) return obj_attribute(r, s, "vn", "normal component", 3, &r->num_normals);
    for (size_t i = 0; i < sizeof obj_ignored / sizeof obj_ignored[0]; i++)
        if (word_is(kw, n, obj_ignored[i])) return true;
    return obj_fail(r, "unknown keyword '%.*s'", token_len(kw), kw);
}

/* Split buf into NUL-terminated lines in place and parse each. */
static bool obj_parse(ObjReader *r, char *buf, size_t size)
{
    char *end = buf + size;
    for (char *line = buf; line < end;) {
        char *nl = memchr(line, '\n', (size_t)(end - line));
        char *stop = nl ? nl : end;
        *stop = '\0';
        r->line++;
        if (strlen(line) != (size_t)(stop - line)) return obj_fail(r, "unexpected NUL byte (binary file?)");
        if (!obj_statement(r, line)) return false;
        line = stop + 1;
    }
    return true;
}

bool mesh_load_obj(const char *path, Mesh *mesh, Error *err)
{
    memset(mesh, 0, sizeof *mesh);
    size_t size;
    char *buf = file_read_all(path, &size, err);
    if (!buf) return false;
    ObjReader r = {.path = path, .err = err};
    bool ok = obj_parse(&r, buf, size) && mb_finish(&r.mb, path, mesh, err);
    free(buf);
    mb_free(&r.mb);
    return ok;
}
