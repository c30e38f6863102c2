/* fixtures.c -- scratch scene files and labs for the tests. */
#include "fixtures.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"

const char *fixture_file(const char *name, const char *text)
{
    static char paths[8][1024];
    static int next;
    char *path = paths[next++ % 8];
    snprintf(path, 1024, "%s/%s", test_tmpdir(), name);
    FILE *fp = fopen(path, "wb");
    if (!fp) return NULL;
    fputs(text, fp);
    fclose(fp);
    return path;
}

Lab *fixture_lab(const char *name, const char *scene_text)
{
    Error err;
    const char *path = fixture_file(name, scene_text);
    Lab *lab = path ? lab_open(path, NULL, 0, &err) : NULL;
    if (!lab) printf("    fixture_lab(%s): %s\n", name, path ? err.msg : "cannot write");
    return lab;
}
