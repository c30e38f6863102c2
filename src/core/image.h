/* image.h -- the one image type: a float32 raster with interleaved channels.
 * Row 0 is the top row of the picture (camera convention); pixel (x, y) of
 * channel c is data[(y * width + x) * channels + c]. */
#ifndef SL_IMAGE_H
#define SL_IMAGE_H
#include <stddef.h>
#include "core/error.h"

typedef struct Image {
    int width, height, channels;
    float *data;
} Image;

/* Allocate a zero-filled image; fails (with a message) on absurd sizes. */
bool image_init(Image *img, int width, int height, int channels, Error *err);
void image_free(Image *img);
size_t image_count(const Image *img); /* width * height * channels */

static inline float *image_px(const Image *img, int x, int y)
{
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
}

#endif
