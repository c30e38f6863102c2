/* fuzz_png.c -- libFuzzer harness for light images in PNG, read through the
 * OpenImageIO plugin (io/image_file.c; the plugin itself is not
 * instrumented, so coverage guides only our side). Needs
 * SHADOWLAB_PLUGIN_DIR pointing at build/libshadowlab_oiio.so. */
#include "fuzz_image.h"
#include "io/image_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_image(data, size, "png"); }

/* Load the plugin (OpenImageIO: ~260 libraries) before the first timed
 * input: a signature and an IEND chunk pass image_read's structural check
 * (io/image_check.c), so OIIO itself is called (and refuses the file). */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    static const uint8_t iend_only[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 0,
                                        'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    const char *path = fuzz_file(iend_only, sizeof iend_only, "png");
    Image img = {0};
    Error err;
    if (path && image_read(path, &img, &err)) image_free(&img);
    return 0;
}
