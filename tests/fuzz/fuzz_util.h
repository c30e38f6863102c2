/* fuzz_util.h -- shared by the libFuzzer harnesses: the engine's parsers
 * read files by path, so each input is written to one scratch file per
 * process (in $TMPDIR, default /tmp) with the extension the parser expects. */
#ifndef SL_FUZZ_UTIL_H
#define SL_FUZZ_UTIL_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* Path of the scratch file holding data[0, n), or NULL. */
static const char *fuzz_file(const uint8_t *data, size_t n, const char *ext)
{
    static char path[512];
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/shadowlab-fuzz-%ld.%s", tmp && *tmp ? tmp : "/tmp", (long)getpid(), ext);
    FILE *fp = fopen(path, "wb");
    if (!fp) return NULL;
    size_t w = fwrite(data, 1, n, fp);
    if (fclose(fp) != 0 || w != n) return NULL;
    return path;
}

#endif
