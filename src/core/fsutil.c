/* fsutil.c -- atomic writes and small filesystem helpers (POSIX). */
#define _POSIX_C_SOURCE 200809L
#include "core/fsutil.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void atomic_tmp_name(const char *path, char *out, size_t n)
{
    snprintf(out, n, "%s.tmp%ld", path, (long)getpid());
}

bool atomic_open(AtomicFile *af, const char *path, Error *err)
{
    if (strlen(path) + 32 >= sizeof af->path) return error_set(err, "%s: path too long", path);
    snprintf(af->path, sizeof af->path, "%s", path);
    atomic_tmp_name(path, af->tmp_path, sizeof af->tmp_path);
    af->fp = fopen(af->tmp_path, "wb");
    if (!af->fp) return error_set(err, "%s: cannot write: %s", af->tmp_path, strerror(errno));
    return true;
}

bool rename_into_place(const char *tmp_path, const char *path, Error *err)
{
    if (rename(tmp_path, path) != 0) {
        int e = errno;
        remove(tmp_path);
        return error_set(err, "%s: cannot rename into place: %s", path, strerror(e));
    }
    return true;
}

bool atomic_commit(AtomicFile *af, Error *err)
{
    bool ok = fflush(af->fp) == 0 && fsync(fileno(af->fp)) == 0 && !ferror(af->fp);
    int e = errno;
    ok = (fclose(af->fp) == 0) && ok;
    af->fp = NULL;
    if (!ok) {
        remove(af->tmp_path);
        return error_set(err, "%s: write failed: %s", af->path, strerror(e));
    }
    return rename_into_place(af->tmp_path, af->path, err);
}

void atomic_abort(AtomicFile *af)
{
    if (af->fp) fclose(af->fp);
    af->fp = NULL;
    remove(af->tmp_path);
}

bool mkdir_p(const char *dir, Error *err)
{
    char buf[4096];
    if (strlen(dir) >= sizeof buf) return error_set(err, "%s: path too long", dir);
    snprintf(buf, sizeof buf, "%s", dir);
    for (char *p = buf + 1;; p++) {
        bool end = *p == '\0';
        if (*p == '/' || end) {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return error_set(err, "%s: cannot create directory: %s", buf, strerror(errno));
            if (end) break;
            *p = '/';
        }
    }
    return true;
}

bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

char *file_read_all(const char *path, size_t *size, Error *err)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        error_set(err, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - n - 1, fp);
        if (n < cap - 1) break;
        char *nb = realloc(buf, cap * 2);
        if (!nb) { free(buf); buf = NULL; break; }
        buf = nb;
        cap *= 2;
    }
    bool failed = !buf || ferror(fp);
    fclose(fp);
    if (failed) {
        free(buf);
        error_set(err, "%s: read failed", path);
        return NULL;
    }
    buf[n] = '\0';
    if (size) *size = n;
    return buf;
}
