/* image_file.h -- PNG/JPEG/HDR/EXR/... files through OpenImageIO, which lives
 * in the plugin build/libshadowlab_oiio.so (see io/oiio_plugin.h) and is
 * dlopened on first use, so a run that touches no such file never loads it.
 * The plugin is looked up in $SHADOWLAB_PLUGIN_DIR if set, else next to the
 * running executable. All functions are thread-safe. */
#ifndef SL_IMAGE_FILE_H
#define SL_IMAGE_FILE_H
#include <stdbool.h>
#include "core/error.h"
#include "core/image.h"

/* Write an Image (float, 1/3/4 channels, values clamped to [0,1], NaN to 0)
 * as 8 bits per channel in the format given by the extension (.png, .jpg,
 * ...). Colour channels are sRGB-encoded if `srgb`, else stored as
 * round(v * 255); alpha (channel 4, straight, not premultiplied) is always
 * stored linearly. Written atomically (a temporary sibling with the same
 * extension, renamed into place), so a failure leaves no file. */
bool image_write_ldr(const char *path, const Image *img, bool srgb, Error *err);

/* Read an image into a float Image, channels as stored, with the
 * OpenImageIO reader its extension names (no other reader is tried: a
 * ".png" that is not a PNG is refused). Empty, truncated or corrupt files
 * are refused with a message naming the file, also where the decoder would
 * fill in the missing pixels; sizes beyond image_init's limits are refused
 * before any pixel is decoded. Files of the display formats (.png, .jpg, .jpeg, .bmp, .gif, .tga, .ppm,
 * .pgm, .pnm, .webp) are taken as sRGB-encoded and their colour channels
 * linearised; alpha (2nd of 2 or 4th of 4 channels) stays as stored and
 * straight. Other formats (.exr, .hdr, .tif, ...) are returned as stored. On
 * failure img is left empty (data NULL). */
bool image_read(const char *path, Image *img, Error *err);

/* True once the plugin has been loaded in this process (for tests/records). */
bool image_plugin_loaded(void);

#endif
