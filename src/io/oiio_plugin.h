/* oiio_plugin.h -- the C ABI of build/libshadowlab_oiio.so, the plugin that
 * wraps OpenImageIO (C++, slow to load) so that the engine never links it:
 * io/image_file.c dlopens the plugin on first use, calls the one exported
 * entry point and checks `abi` against OIIO_PLUGIN_ABI. Bump the number on
 * any change to the struct. */
#ifndef SL_OIIO_PLUGIN_H
#define SL_OIIO_PLUGIN_H

#ifdef __cplusplus
extern "C" {
#endif

#define OIIO_PLUGIN_ABI 1
#define OIIO_PLUGIN_ENTRY "shadowlab_oiio_plugin"

typedef struct OiioPluginApi {
    int abi;
    /* Write an 8-bit image (1, 3 or 4 channels, interleaved, rows top to
     * bottom, alpha straight, bytes stored as given) in the format given by
     * the file extension. Returns 0 on success, else writes a message into
     * err (size err_len). */
    int (*write_u8)(const char *path, int w, int h, int channels, const unsigned char *pixels,
                    char *err, int err_len);
    /* Read any image OIIO can read, converted to float, channels and values
     * as stored (alpha not premultiplied into colour). *pixels is allocated
     * by the plugin; release it with free_pixels. */
    int (*read_float)(const char *path, int *w, int *h, int *channels, float **pixels,
                      char *err, int err_len);
    void (*free_pixels)(float *pixels);
} OiioPluginApi;

/* The exported symbol (named by OIIO_PLUGIN_ENTRY). */
const OiioPluginApi *shadowlab_oiio_plugin(void);

#ifdef __cplusplus
}
#endif

#endif
