/* json.c -- streaming JSON writer (see json.h). */
#include "core/json.h"
#include <math.h>

void json_init(JsonWriter *w, FILE *fp)
{
    w->fp = fp;
    w->depth = 0;
    w->has_items[0] = false;
}

static void write_escaped(FILE *fp, const char *s)
{
    fputc('"', fp);
    for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++) {
        if (*p == '"' || *p == '\\') fprintf(fp, "\\%c", *p);
        else if (*p == '\n') fputs("\\n", fp);
        else if (*p == '\t') fputs("\\t", fp);
        else if (*p < 0x20) fprintf(fp, "\\u%04x", *p);
        else fputc(*p, fp);
    }
    fputc('"', fp);
}

/* Comma, newline, indentation and "key": before a value. */
static void item(JsonWriter *w, const char *key)
{
    if (w->depth > 0) {
        fputs(w->has_items[w->depth] ? ",\n" : "\n", w->fp);
        w->has_items[w->depth] = true;
        for (int i = 0; i < w->depth; i++) fputs("  ", w->fp);
    }
    if (key) {
        write_escaped(w->fp, key);
        fputs(": ", w->fp);
    }
}

static void scope_open(JsonWriter *w, const char *key, char c)
{
    item(w, key);
    fputc(c, w->fp);
    if (w->depth + 1 < JSON_MAX_DEPTH) w->depth++;
    w->has_items[w->depth] = false;
}

static void scope_close(JsonWriter *w, char c)
{
    bool had = w->has_items[w->depth];
    if (w->depth > 0) w->depth--;
    if (had) {
        fputc('\n', w->fp);
        for (int i = 0; i < w->depth; i++) fputs("  ", w->fp);
    }
    fputc(c, w->fp);
}

void json_object_begin(JsonWriter *w, const char *key) { scope_open(w, key, '{'); }
void json_object_end(JsonWriter *w) { scope_close(w, '}'); }
void json_array_begin(JsonWriter *w, const char *key) { scope_open(w, key, '['); }
void json_array_end(JsonWriter *w) { scope_close(w, ']'); }

void json_string(JsonWriter *w, const char *key, const char *value)
{
    item(w, key);
    write_escaped(w->fp, value);
}

void json_number(JsonWriter *w, const char *key, double value)
{
    item(w, key);
    if (isfinite(value)) fprintf(w->fp, "%.9g", value);
    else fputs("null", w->fp);
}

void json_int(JsonWriter *w, const char *key, long long value)
{
    item(w, key);
    fprintf(w->fp, "%lld", value);
}

void json_bool(JsonWriter *w, const char *key, bool value)
{
    item(w, key);
    fputs(value ? "true" : "false", w->fp);
}

void json_finish(JsonWriter *w) { fputc('\n', w->fp); }
