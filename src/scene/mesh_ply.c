/* mesh_ply.c -- PLY 1.0 reader (ascii, binary_little_endian, binary_big_endian).
 * Keeps x/y/z of element 'vertex' and the index list of element 'face'
 * (polygons fan-triangulated); every other property and element is read by
 * its declared type and dropped. Errors name "<path>:<line>:" in the header and
 * ascii data, "<path>: <element> <n>:" (0-based record) in binary data. */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "scene/mesh_builder.h"

enum { PLY_MAX_ELEMENTS = 16, PLY_MAX_PROPERTIES = 48, PLY_NAME_MAX = 64 };

typedef enum PlyType { T_INT8, T_UINT8, T_INT16, T_UINT16, T_INT32, T_UINT32, T_FLOAT32, T_FLOAT64, T_NONE } PlyType;

static const struct PlyTypeInfo {
    const char *name, *alias;
    int size;
    double min, max; /* integer types only */
} ply_types[] = {
    [T_INT8] = {"char", "int8", 1, -128.0, 127.0},
    [T_UINT8] = {"uchar", "uint8", 1, 0.0, 255.0},
    [T_INT16] = {"short", "int16", 2, -32768.0, 32767.0},
    [T_UINT16] = {"ushort", "uint16", 2, 0.0, 65535.0},
    [T_INT32] = {"int", "int32", 4, -2147483648.0, 2147483647.0},
    [T_UINT32] = {"uint", "uint32", 4, 0.0, 4294967295.0},
    [T_FLOAT32] = {"float", "float32", 4, 0.0, 0.0},
    [T_FLOAT64] = {"double", "float64", 8, 0.0, 0.0},
};

typedef enum PlyRole { ROLE_SKIP, ROLE_X, ROLE_Y, ROLE_Z, ROLE_INDICES } PlyRole;
typedef enum PlyFormat { PLY_ASCII, PLY_LE, PLY_BE } PlyFormat;

typedef struct PlyProperty {
    PlyType type;       /* scalar type, or list item type */
    PlyType count_type; /* list length type; T_NONE for scalars */
    PlyRole role;
    char name[PLY_NAME_MAX];
} PlyProperty;

typedef struct PlyElement {
    char name[PLY_NAME_MAX];
    long count;
    long line; /* of its declaration */
    int num_props;
    PlyProperty props[PLY_MAX_PROPERTIES];
} PlyElement;

/* Growable array; len and cap count elements of `size` bytes. */
typedef struct PlyReader {
    const char *path;
    Error *err;
    PlyFormat format;
    bool has_format;
    int num_elems;
    PlyElement elems[PLY_MAX_ELEMENTS];
    PlyElement *vertex, *face;
    char *p, *end;               /* next unread byte (binary) or line (text) */
    char *cur;                   /* position in the current ascii line */
    long line;                   /* current text line */
    const PlyElement *cur_elem;  /* element being read; NULL in the header */
    long record;
    MeshBuilder mb;              /* vertices and triangles read so far */
} PlyReader;

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

static char *skip_space(char *s)
{
    while (is_space(*s)) s++;
    return s;
}

static bool ply_is_int(PlyType t) { return t <= T_UINT32; }

/* Error at the current place: header line, ascii record line, or binary record. */
static bool ply_fail(PlyReader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static bool ply_fail(PlyReader *r, const char *fmt, ...)
{
    char msg[ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (!r->cur_elem) return error_set(r->err, "%s:%ld: %s", r->path, r->line, msg);
    if (r->format == PLY_ASCII)
        return error_set(r->err, "%s:%ld: %s %ld: %s", r->path, r->line, r->cur_elem->name, r->record, msg);
    return error_set(r->err, "%s: %s %ld: %s", r->path, r->cur_elem->name, r->record, msg);
}

static bool ply_truncated(PlyReader *r)
{
    return error_set(r->err, "%s: file truncated in element '%s' (record %ld of %ld)", r->path,
                     r->cur_elem->name, r->record, r->cur_elem->count);
}

/* Next text line from r->p, NUL-terminated in place: 1, 0 at end of data,
 * -1 on error. */
static int ply_line(PlyReader *r, char **line)
{
    if (r->p >= r->end) return 0;
    char *s = r->p;
    char *nl = memchr(s, '\n', (size_t)(r->end - s));
    char *stop = nl ? nl : r->end;
    *stop = '\0';
    r->p = nl ? nl + 1 : r->end;
    r->line++;
    if (strlen(s) != (size_t)(stop - s)) {
        ply_fail(r, "unexpected NUL byte in text");
        return -1;
    }
    *line = s;
    return 1;
}

/* ---- header ---- */

/* Split s in place into at most max whitespace-separated tokens; returns
 * their number, or max + 1 if there are more. */
static int ply_split(char *s, char **tok, int max)
{
    int n = 0;
    for (s = skip_space(s); *s; s = skip_space(s)) {
        if (n == max) return max + 1;
        tok[n++] = s;
        while (*s && !is_space(*s)) s++;
        if (*s) *s++ = '\0';
    }
    return n;
}

static PlyElement *ply_find_element(PlyReader *r, const char *name)
{
    for (int i = 0; i < r->num_elems; i++)
        if (strcmp(r->elems[i].name, name) == 0) return &r->elems[i];
    return NULL;
}

static PlyProperty *ply_find_property(PlyElement *el, const char *name)
{
    for (int i = 0; i < el->num_props; i++)
        if (strcmp(el->props[i].name, name) == 0) return &el->props[i];
    return NULL;
}

static bool ply_name(PlyReader *r, char *dst, const char *name)
{
    size_t n = strlen(name);
    if (n >= PLY_NAME_MAX) return ply_fail(r, "name '%.40s...' too long (limit %d)", name, PLY_NAME_MAX - 1);
    memcpy(dst, name, n + 1);
    return true;
}

static bool ply_type(PlyReader *r, const char *name, PlyType *out)
{
    for (int t = 0; t < T_NONE; t++) {
        if (strcmp(name, ply_types[t].name) == 0 || strcmp(name, ply_types[t].alias) == 0) {
            *out = (PlyType)t;
            return true;
        }
    }
    return ply_fail(r, "unknown property type '%s'", name);
}

static bool ply_format(PlyReader *r, char **t, int n)
{
    static const char *const names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    if (r->has_format) return ply_fail(r, "duplicate format line");
    if (n != 3 || strcmp(t[2], "1.0") != 0)
        return ply_fail(r, "expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
    for (int i = 0; i < 3; i++) {
        if (strcmp(t[1], names[i]) == 0) {
            r->format = (PlyFormat)i;
            r->has_format = true;
            return true;
        }
    }
    return ply_fail(r, "unknown format '%s'", t[1]);
}

static bool ply_element(PlyReader *r, char **t, int n)
{
    if (n != 3) return ply_fail(r, "expected 'element <name> <count>'");
    if (r->num_elems == PLY_MAX_ELEMENTS) return ply_fail(r, "more than %d elements", PLY_MAX_ELEMENTS);
    if (ply_find_element(r, t[1])) return ply_fail(r, "duplicate element '%s'", t[1]);
    char *e;
    long count = strtol(t[2], &e, 10);
    if (e == t[2] || *e || count < 0 || count > INT_MAX)
        return ply_fail(r, "element count '%s' is not an integer in [0, %d]", t[2], INT_MAX);
    PlyElement *el = &r->elems[r->num_elems];
    if (!ply_name(r, el->name, t[1])) return false;
    el->count = count;
    el->line = r->line;
    el->num_props = 0;
    r->num_elems++;
    return true;
}

static bool ply_property(PlyReader *r, char **t, int n)
{
    if (r->num_elems == 0) return ply_fail(r, "property before any element");
    PlyElement *el = &r->elems[r->num_elems - 1];
    if (el->num_props == PLY_MAX_PROPERTIES)
        return ply_fail(r, "element '%s' has more than %d properties", el->name, PLY_MAX_PROPERTIES);
    PlyProperty *p = &el->props[el->num_props];
    *p = (PlyProperty){.count_type = T_NONE, .role = ROLE_SKIP};
    bool list = n >= 2 && strcmp(t[1], "list") == 0;
    if (list && n != 5) return ply_fail(r, "expected 'property list <count type> <item type> <name>'");
    if (!list && n != 3) return ply_fail(r, "expected 'property <type> <name>'");
    if (list && !ply_type(r, t[2], &p->count_type)) return false;
    if (list && !ply_is_int(p->count_type))
        return ply_fail(r, "list length type '%s' is not an integer type", t[2]);
    if (!ply_type(r, t[n - 2], &p->type) || !ply_name(r, p->name, t[n - 1])) return false;
    el->num_props++;
    return true;
}

static bool ply_header_line(PlyReader *r, char *line, bool *done)
{
    char *t[5];
    int n = ply_split(line, t, 5);
    if (n == 0) return ply_fail(r, "empty header line");
    if (strcmp(t[0], "comment") == 0 || strcmp(t[0], "obj_info") == 0) return true;
    if (strcmp(t[0], "format") == 0) return ply_format(r, t, n);
    if (strcmp(t[0], "element") == 0) return ply_element(r, t, n);
    if (strcmp(t[0], "property") == 0) return ply_property(r, t, n);
    if (strcmp(t[0], "end_header") != 0) return ply_fail(r, "unknown header keyword '%.40s'", t[0]);
    if (n != 1) return ply_fail(r, "unexpected text after 'end_header'");
    *done = true;
    return true;
}

static bool ply_bind_coordinate(PlyReader *r, PlyElement *el, const char *name, PlyRole role)
{
    PlyProperty *p = ply_find_property(el, name);
    if (!p || p->count_type != T_NONE) {
        r->line = el->line;
        return ply_fail(r, "element 'vertex' has no scalar property '%s'", name);
    }
    p->role = role;
    return true;
}

static bool ply_bind_indices(PlyReader *r, PlyElement *el)
{
    PlyProperty *p = ply_find_property(el, "vertex_indices");
    if (!p) p = ply_find_property(el, "vertex_index");
    if (!p || p->count_type == T_NONE || !ply_is_int(p->type)) {
        r->line = el->line;
        return ply_fail(r, "element 'face' has no integer list property 'vertex_indices' or 'vertex_index'");
    }
    p->role = ROLE_INDICES;
    return true;
}

/* Records without properties take no bytes: refuse them rather than spin. */
static bool ply_check_elements(PlyReader *r)
{
    for (int i = 0; i < r->num_elems; i++) {
        if (r->elems[i].count > 0 && r->elems[i].num_props == 0) {
            r->line = r->elems[i].line;
            return ply_fail(r, "element '%s' has records but no properties", r->elems[i].name);
        }
    }
    return true;
}

/* Find 'vertex' and 'face' and mark the properties the mesh is built from. */
static bool ply_bind(PlyReader *r)
{
    r->vertex = ply_find_element(r, "vertex");
    r->face = ply_find_element(r, "face");
    if (!r->vertex) return error_set(r->err, "%s: no 'vertex' element", r->path);
    if (!r->face || r->face->count == 0) return error_set(r->err, "%s: no triangles", r->path);
    PlyElement *v = r->vertex;
    return ply_bind_coordinate(r, v, "x", ROLE_X) && ply_bind_coordinate(r, v, "y", ROLE_Y) &&
           ply_bind_coordinate(r, v, "z", ROLE_Z) && ply_bind_indices(r, r->face);
}

static bool ply_header(PlyReader *r)
{
    char *line, *t[2];
    int got = ply_line(r, &line);
    if (got < 0) return false;
    if (got == 0 || ply_split(line, t, 1) != 1 || strcmp(t[0], "ply") != 0)
        return ply_fail(r, "not a PLY file (first line is not 'ply')");
    for (bool done = false; !done;) {
        got = ply_line(r, &line);
        if (got <= 0) return got == 0 ? ply_fail(r, "header has no end_header line") : false;
        if (!ply_header_line(r, line, &done)) return false;
    }
    if (!r->has_format) return ply_fail(r, "header has no format line");
    return ply_check_elements(r) && ply_bind(r);
}

/* ---- data ---- */

static double sign_extend(uint64_t u, int bits) { return u >> (bits - 1) ? (double)u - ldexp(1.0, bits) : (double)u; }

static bool ply_binary_value(PlyReader *r, PlyType t, double *out)
{
    int n = ply_types[t].size;
    if (r->end - r->p < n) return ply_truncated(r);
    const unsigned char *b = (const unsigned char *)r->p;
    uint64_t u = 0;
    for (int i = 0; i < n; i++) u = u << 8 | b[r->format == PLY_BE ? i : n - 1 - i];
    r->p += n;
    if (t == T_FLOAT32) {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, sizeof f);
        *out = f;
    } else if (t == T_FLOAT64) {
        memcpy(out, &u, sizeof *out);
    } else {
        *out = (t == T_INT8 || t == T_INT16 || t == T_INT32) ? sign_extend(u, 8 * n) : (double)u;
    }
    return true;
}

static bool ply_ascii_value(PlyReader *r, PlyType t, double *out)
{
    char *s = skip_space(r->cur), *e;
    if (!*s) return ply_fail(r, "too few values on the line");
    double v = ply_is_int(t) ? (double)strtoll(s, &e, 10) : strtod(s, &e);
    if (e == s || (*e && !is_space(*e))) {
        size_t len = strcspn(s, " \t\r\v\f");
        return ply_fail(r, "malformed %s value '%.*s'", ply_types[t].name, len > 40 ? 40 : (int)len, s);
    }
    if (ply_is_int(t) && (v < ply_types[t].min || v > ply_types[t].max))
        return ply_fail(r, "value %.0f out of range for type '%s'", v, ply_types[t].name);
    *out = v;
    r->cur = e;
    return true;
}

static bool ply_value(PlyReader *r, PlyType t, double *out)
{
    return r->format == PLY_ASCII ? ply_ascii_value(r, t, out) : ply_binary_value(r, t, out);
}

static bool ply_triangle(PlyReader *r, uint32_t a, uint32_t b, uint32_t c)
{
    const char *why = mb_add_triangle(&r->mb, a, b, c);
    return !why || ply_fail(r, "%s", why);
}

/* The n indices of one face, fan-triangulated around the first. */
static bool ply_polygon(PlyReader *r, PlyType t, double n)
{
    if (n < 3) return ply_fail(r, "polygon has %.0f vertices, need at least 3", n);
    uint32_t first = 0, prev = 0;
    for (double i = 0; i < n; i++) {
        double v;
        if (!ply_value(r, t, &v)) return false;
        if (v < 0 || v >= (double)r->vertex->count)
            return ply_fail(r, "index %.0f out of range [0, %ld]", v, r->vertex->count - 1);
        uint32_t k = (uint32_t)v;
        if (i >= 2 && !ply_triangle(r, first, prev, k)) return false;
        if (i == 0) first = k;
        prev = k;
    }
    return true;
}

static bool ply_list(PlyReader *r, const PlyProperty *p)
{
    double n, unused;
    if (!ply_value(r, p->count_type, &n)) return false;
    if (n < 0) return ply_fail(r, "list '%s' has negative length %.0f", p->name, n);
    if (p->role == ROLE_INDICES) return ply_polygon(r, p->type, n);
    for (double i = 0; i < n; i++)
        if (!ply_value(r, p->type, &unused)) return false;
    return true;
}

static bool ply_scalar(PlyReader *r, const PlyProperty *p)
{
    double v;
    if (!ply_value(r, p->type, &v)) return false;
    if (p->role == ROLE_SKIP) return true;
    if (!(fabs(v) <= FLT_MAX)) return ply_fail(r, "coordinate '%s' is not finite (%g)", p->name, v);
    vec3 *pos = &r->mb.pos[r->mb.num_pos - 1];
    float f = (float)v;
    if (p->role == ROLE_X) pos->x = f;
    else if (p->role == ROLE_Y) pos->y = f;
    else pos->z = f;
    return true;
}

/* ascii records are one non-blank line each. */
static bool ply_ascii_begin(PlyReader *r)
{
    for (;;) {
        int got = ply_line(r, &r->cur);
        if (got <= 0) return got == 0 ? ply_truncated(r) : false;
        if (*skip_space(r->cur)) return true;
    }
}

static bool ply_record(PlyReader *r, const PlyElement *el)
{
    if (r->format == PLY_ASCII && !ply_ascii_begin(r)) return false;
    if (el == r->vertex) {
        const char *why = mb_add_vertex(&r->mb, v3(0, 0, 0));
        if (why) return ply_fail(r, "%s", why);
    }
    for (int i = 0; i < el->num_props; i++) {
        const PlyProperty *p = &el->props[i];
        if (!(p->count_type == T_NONE ? ply_scalar(r, p) : ply_list(r, p))) return false;
    }
    if (r->format == PLY_ASCII && *skip_space(r->cur)) return ply_fail(r, "too many values on the line");
    return true;
}

/* After the last element: nothing but blank lines (ascii) or nothing (binary). */
static bool ply_trailing(PlyReader *r)
{
    if (r->format != PLY_ASCII) {
        if (r->p == r->end) return true;
        return error_set(r->err, "%s: %td bytes of unexpected data after the last element", r->path,
                         r->end - r->p);
    }
    char *line;
    int got;
    while ((got = ply_line(r, &line)) > 0)
        if (*skip_space(line)) return ply_fail(r, "unexpected data after the last element");
    return got == 0;
}

static bool ply_body(PlyReader *r)
{
    for (int i = 0; i < r->num_elems; i++) {
        r->cur_elem = &r->elems[i];
        for (r->record = 0; r->record < r->cur_elem->count; r->record++)
            if (!ply_record(r, r->cur_elem)) return false;
    }
    r->cur_elem = NULL;
    return ply_trailing(r);
}

bool mesh_load_ply(const char *path, Mesh *mesh, Error *err)
{
    memset(mesh, 0, sizeof *mesh);
    size_t size;
    char *buf = file_read_all(path, &size, err);
    if (!buf) return false;
    PlyReader *r = calloc(1, sizeof *r);
    if (!r) {
        free(buf);
        return error_set(err, "%s: out of memory", path);
    }
    r->path = path;
    r->err = err;
    r->p = buf;
    r->end = buf + size;
    bool ok = ply_header(r) && ply_body(r) && mb_finish(&r->mb, path, mesh, err);
    mb_free(&r->mb);
    free(r);
    free(buf);
    return ok;
}
