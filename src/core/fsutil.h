/* fsutil.h -- files written atomically (temporary file, fsync, rename) so an
 * interrupted run never leaves a half-written output; directory creation. */
#ifndef SL_FSUTIL_H
#define SL_FSUTIL_H
#include <stdio.h>
#include "core/error.h"

typedef struct AtomicFile {
    FILE *fp;
    char path[4096];     /* final name */
    char tmp_path[4096]; /* name while writing */
} AtomicFile;

/* Open `path`'s temporary sibling for writing. */
bool atomic_open(AtomicFile *af, const char *path, Error *err);
/* Flush, fsync and rename onto the final path. */
bool atomic_commit(AtomicFile *af, Error *err);
/* Close and delete the temporary file (on any error path). */
void atomic_abort(AtomicFile *af);
/* A temporary sibling name for libraries that open files themselves
 * (OpenEXR, OpenImageIO): write there, then rename_into_place(). */
void atomic_tmp_name(const char *path, char *out, size_t n);
bool rename_into_place(const char *tmp_path, const char *path, Error *err);

/* mkdir -p; fails with the path on error. */
bool mkdir_p(const char *dir, Error *err);
bool file_exists(const char *path);
/* Read a whole file (NUL-terminated); *size excludes the NUL. free() it. */
char *file_read_all(const char *path, size_t *size, Error *err);

#endif
