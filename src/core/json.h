/* json.h -- a small streaming JSON writer (records, `list --json`). Keys are
 * given with each value; pass NULL inside arrays. Non-finite numbers are
 * written as null, as JSON has no NaN. Output is indented, two spaces. */
#ifndef SL_JSON_H
#define SL_JSON_H
#include <stdbool.h>
#include <stdio.h>

#define JSON_MAX_DEPTH 32

typedef struct JsonWriter {
    FILE *fp;
    int depth;
    bool has_items[JSON_MAX_DEPTH];
} JsonWriter;

void json_init(JsonWriter *w, FILE *fp);
void json_object_begin(JsonWriter *w, const char *key);
void json_object_end(JsonWriter *w);
void json_array_begin(JsonWriter *w, const char *key);
void json_array_end(JsonWriter *w);
void json_string(JsonWriter *w, const char *key, const char *value);
void json_number(JsonWriter *w, const char *key, double value);
void json_int(JsonWriter *w, const char *key, long long value);
void json_bool(JsonWriter *w, const char *key, bool value);
/* Finish the document with a newline. */
void json_finish(JsonWriter *w);

#endif
