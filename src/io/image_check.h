/* image_check.h -- checks of an image file before it is decoded (see
 * image_check.c): it exists, is a non-empty regular file, and a PNG's
 * chunks are whole up to IEND. Messages name the file and, for PNGs, the
 * chunk and byte offset. */
#ifndef SL_IMAGE_CHECK_H
#define SL_IMAGE_CHECK_H
#include <stdbool.h>
#include "core/error.h"

bool image_file_check(const char *path, Error *err);

#endif
