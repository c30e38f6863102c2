/* image.c -- allocation of float images. */
#include "core/image.h"
#include <stdint.h>
#include <stdlib.h>

/* Largest image accepted: 16384 x 16384 pixels x 4 channels (4 GiB). */
#define IMAGE_MAX_SIDE 16384
#define IMAGE_MAX_CHANNELS 16

bool image_init(Image *img, int width, int height, int channels, Error *err)
{
    img->width = img->height = img->channels = 0;
    img->data = NULL;
    if (width < 1 || height < 1 || width > IMAGE_MAX_SIDE || height > IMAGE_MAX_SIDE)
        return error_set(err, "image size %dx%d outside [1, %d] per side", width, height, IMAGE_MAX_SIDE);
    if (channels < 1 || channels > IMAGE_MAX_CHANNELS)
        return error_set(err, "image channel count %d outside [1, %d]", channels, IMAGE_MAX_CHANNELS);
    size_t n = (size_t)width * (size_t)height * (size_t)channels;
    img->data = calloc(n, sizeof(float));
    if (!img->data) return error_set(err, "out of memory for a %dx%dx%d image", width, height, channels);
    img->width = width;
    img->height = height;
    img->channels = channels;
    return true;
}

void image_free(Image *img)
{
    if (!img) return;
    free(img->data);
    img->data = NULL;
    img->width = img->height = img->channels = 0;
}

size_t image_count(const Image *img)
{
    return (size_t)img->width * (size_t)img->height * (size_t)img->channels;
}
