/* image_io.c -- format dispatch for image reading (see image_io.h). */
#include "io/image_io.h"
#include <string.h>
#include <strings.h>
#include "io/exr.h"
#include "io/image_file.h"

bool path_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), k = strlen(ext);
    return n >= k && strcasecmp(path + n - k, ext) == 0;
}

static bool exr_to_image(const ExrImage *e, Image *img, const char *path, Error *err)
{
    int idx[3] = {exr_image_channel(e, "R"), exr_image_channel(e, "G"), exr_image_channel(e, "B")};
    int nc = 3;
    if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) {
        nc = 1;
        idx[0] = exr_image_channel(e, "Y") >= 0 ? exr_image_channel(e, "Y") : 0;
    }
    if (e->num_channels < 1) return error_set(err, "%s: EXR has no channels", path);
    if (!image_init(img, e->width, e->height, nc, err)) return error_prefix(err, "%s: ", path);
    size_t plane = (size_t)e->width * (size_t)e->height;
    for (size_t i = 0; i < plane; i++)
        for (int c = 0; c < nc; c++) img->data[i * (size_t)nc + (size_t)c] = e->data[(size_t)idx[c] * plane + i];
    return true;
}

bool image_load_any(const char *path, Image *img, Error *err)
{
    if (!path_has_ext(path, ".exr")) return image_read(path, img, err);
    ExrImage e;
    if (!exr_read(path, &e, err)) return false;
    bool ok = exr_to_image(&e, img, path, err);
    exr_image_free(&e);
    return ok;
}
