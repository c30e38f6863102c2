/* image_io.h -- read an image of any supported format into a float Image:
 * EXR through OpenEXR's C API (exr.c), everything else through the
 * OpenImageIO plugin (image_file.c), so reading an EXR never loads OIIO. */
#ifndef SL_IMAGE_IO_H
#define SL_IMAGE_IO_H
#include "core/image.h"

/* EXR: channels R, G, B (or Y, or the first channel) become 3 or 1 channels. */
bool image_load_any(const char *path, Image *img, Error *err);
bool path_has_ext(const char *path, const char *ext); /* case-insensitive, ext with the dot */

#endif
