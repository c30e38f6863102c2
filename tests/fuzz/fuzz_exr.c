/* fuzz_exr.c -- libFuzzer harness for light images in EXR (OpenEXR's C API
 * through io/exr.c and the channel selection of io/image_io.c). */
#include "fuzz_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_image(data, size, "exr"); }
