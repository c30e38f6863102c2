/* fuzz_image.h -- the body of the light-image harnesses: an image that loads
 * has a sane shape and as many values as it says; a refusal has a message. */
#ifndef SL_FUZZ_IMAGE_H
#define SL_FUZZ_IMAGE_H
#include "fuzz_util.h"
#include "io/image_io.h"

static int fuzz_image(const uint8_t *data, size_t size, const char *ext)
{
    const char *path = fuzz_file(data, size, ext);
    if (!path) return 0;
    Image img = {0};
    Error err = {{0}};
    if (!image_load_any(path, &img, &err)) {
        if (!err.msg[0] || img.data) abort();
        return 0;
    }
    if (img.width < 1 || img.height < 1 || img.channels < 1 || !img.data) abort();
    float sum = 0;
    for (size_t i = 0; i < image_count(&img); i++) sum += img.data[i]; /* every value readable */
    if (sum != sum && sum == sum) abort(); /* keeps the reads */
    image_free(&img);
    return 0;
}

#endif
