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

#define OIIO_PLUGIN_ABI 2
#define OIIO_PLUGIN_ENTRY "shadowlab_oiio_plugin"

/* Destination for a decoded image of w x h x channels floats, or NULL with
 * a message in err (size err_len). */
typedef float *(*OiioPixelAlloc)(void *ctx, int w, int h, int channels, char *err, int err_len);

typedef struct OiioPluginApi {
    int abi;
    /* Write an 8-bit image (1, 3 or 4 channels, interleaved, rows top to
     * bottom, alpha straight, bytes stored as given) in the format given by
     * the file extension. Returns 0 on success, else writes a message into
     * err (size err_len). */
    int (*write_u8)(const char *path, int w, int h, int channels, const unsigned char *pixels,
                    char *err, int err_len);
    /* Read an image with the reader its extension names (OIIO's fallback of
     * trying every other reader is off: a ".png" is decoded as PNG or
     * refused), converted to float, channels and values as stored (alpha not
     * premultiplied into colour). Once the header is read, alloc(ctx, w, h,
     * channels, err, err_len) supplies the destination (interleaved, rows
     * top to bottom): it enforces the caller's size limits and returns NULL
     * with a message to refuse. A decode that completes with a warning (a
     * truncated JPEG, its missing rows filled with grey) fails too. Returns
     * 0 on success, else a one-line message in err. */
    int (*read_float)(const char *path, OiioPixelAlloc alloc, void *ctx, char *err, int err_len);
} OiioPluginApi;

/* The exported symbol (named by OIIO_PLUGIN_ENTRY). */
const OiioPluginApi *shadowlab_oiio_plugin(void);

#ifdef __cplusplus
}
#endif

#endif
