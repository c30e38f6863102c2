/* exr.h -- float32 OpenEXR files through OpenEXRCore's C API: scanline ZIP
 * output of any set of named channels plus string header attributes, and
 * planar float input of every channel of a float/half scanline file. */
#ifndef SL_EXR_H
#define SL_EXR_H
#include "core/error.h"

/* One channel to write: the value of pixel i (rows top to bottom, i = y *
 * width + x) is data[i * stride], so interleaved buffers need no copy. */
typedef struct ExrChannel {
    const char *name;
    const float *data;
    int stride;
} ExrChannel;

/* A string attribute of the header. */
typedef struct ExrAttr {
    const char *name;
    const char *value;
} ExrAttr;

/* Write a scanline float32 EXR (ZIP compression) with the given channels (any
 * order; EXR stores them sorted by name) and string header attributes.
 * Written atomically: to a temporary sibling (atomic_tmp_name), synced, then
 * rename_into_place (core/fsutil.h), so a failure leaves no file at `path`. */
bool exr_write(const char *path, int width, int height, const ExrChannel *channels, int num_channels,
               const ExrAttr *attrs, int num_attrs, Error *err);

/* A whole image read back: data holds num_channels planes of width * height
 * floats (plane c is channel names[c], in file order, i.e. sorted by name);
 * attr_names/attr_values are the num_attrs string attributes of the header
 * (less `type`, the storage kind that OpenEXR itself adds to every file).
 * Every string and array is malloc'd; release with exr_image_free. */
typedef struct ExrImage {
    int width, height, num_channels;
    char **names;
    float *data;
    int num_attrs;
    char **attr_names;
    char **attr_values;
} ExrImage;

/* Read every channel of a float/half scanline EXR (the first part of a
 * multi-part file) as float; other attribute types than string are skipped.
 * Images over 2^30 samples (width * height * channels) are refused.
 * On failure img is left empty and err names the path and OpenEXR's error. */
bool exr_read(const char *path, ExrImage *img, Error *err);
/* Free everything exr_read allocated and zero img (safe on a zeroed img). */
void exr_image_free(ExrImage *img);
/* Index of a channel by name, or -1. */
int exr_image_channel(const ExrImage *img, const char *name);

#endif
