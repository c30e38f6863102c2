/* fuzz_png.c -- libFuzzer harness for light images in PNG, read through the
 * OpenImageIO plugin (io/image_file.c; the plugin itself is not
 * instrumented, so coverage guides only our side). Needs
 * SHADOWLAB_PLUGIN_DIR pointing at build/libshadowlab_oiio.so. */
#include "fuzz_image.h"
#include "io/image_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_image(data, size, "png"); }

/* Load the plugin (OpenImageIO: ~260 libraries) before the first timed input. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    Image img = {0};
    Error err;
    if (image_read("/nonexistent/shadowlab-fuzz-warmup.png", &img, &err)) image_free(&img);
    return 0;
}
