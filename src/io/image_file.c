/* image_file.c -- image files through the OpenImageIO plugin: locating and
 * dlopening it once, 8-bit (s)RGB encoding for output, linearisation of
 * display formats on input (after image_check.c's structural checks, into
 * an Image the plugin decodes straight into), and atomic writes via
 * same-extension temporaries (OIIO picks the format from the extension). */
#define _POSIX_C_SOURCE 200809L
#include "io/image_file.h"
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>
#include "core/fsutil.h"
#include "io/image_check.h"
#include "io/oiio_plugin.h"

#define PLUGIN_FILE "libshadowlab_oiio.so"
#define PATH_BUF 4096

typedef const OiioPluginApi *(*PluginEntry)(void);

static pthread_once_t plugin_once = PTHREAD_ONCE_INIT;
static const OiioPluginApi *plugin_api; /* written only inside plugin_once */
static char plugin_error[768];           /* why loading failed */
static atomic_bool plugin_ready;

/* Full path of the plugin: $SHADOWLAB_PLUGIN_DIR, else the executable's directory. */
static bool plugin_path(char *out, size_t n)
{
    const char *dir = getenv("SHADOWLAB_PLUGIN_DIR");
    char exe[PATH_BUF];
    if (!dir || !*dir) {
        ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (len <= 0) {
            snprintf(plugin_error, sizeof plugin_error, "readlink /proc/self/exe: %s", strerror(errno));
            return false;
        }
        exe[len] = '\0';
        *strrchr(exe, '/') = '\0'; /* the link target is an absolute path */
        dir = exe;
    }
    int len = snprintf(out, n, "%s/%s", dir, PLUGIN_FILE);
    if (len < 0 || (size_t)len >= n) {
        snprintf(plugin_error, sizeof plugin_error, "plugin directory path too long");
        return false;
    }
    return true;
}

/* dlopen the plugin and fetch its API; NULL (reason in plugin_error) on failure. */
static const OiioPluginApi *plugin_open(const char *so)
{
    void *handle = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        snprintf(plugin_error, sizeof plugin_error, "%s", dlerror());
        return NULL;
    }
    PluginEntry entry = (PluginEntry)dlsym(handle, OIIO_PLUGIN_ENTRY);
    const OiioPluginApi *api = entry ? entry() : NULL;
    if (api && api->abi == OIIO_PLUGIN_ABI) return api;
    if (!entry)
        snprintf(plugin_error, sizeof plugin_error, "%s", dlerror());
    else
        snprintf(plugin_error, sizeof plugin_error, "%.600s: plugin ABI %d, this build expects %d", so,
                 api ? api->abi : -1, OIIO_PLUGIN_ABI);
    dlclose(handle);
    return NULL;
}

static void plugin_load(void)
{
    char so[PATH_BUF];
    if (!plugin_path(so, sizeof so)) return;
    plugin_api = plugin_open(so);
    atomic_store(&plugin_ready, plugin_api != NULL);
}

/* The plugin's API, loaded on first call; NULL with a message naming `path`. */
static const OiioPluginApi *plugin_get(const char *path, const char *what, Error *err)
{
    pthread_once(&plugin_once, plugin_load);
    if (!plugin_api)
        error_set(err, "%s: %s needs build/" PLUGIN_FILE " (OpenImageIO plugin): %s; run make", path,
                  what, plugin_error);
    return plugin_api;
}

bool image_plugin_loaded(void)
{
    return atomic_load(&plugin_ready);
}

/* The '.' that starts the extension of path's last component, or its end. */
static const char *extension_dot(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : path + strlen(path);
}

/* "dir/out.png" -> "dir/out.tmp<pid>-<n>.png": unique, same extension. */
static bool tmp_sibling(const char *path, char *out, size_t n)
{
    static atomic_uint counter;
    const char *dot = extension_dot(path);
    int len = snprintf(out, n, "%.*s.tmp%ld-%u%s", (int)(dot - path), path, (long)getpid(),
                       atomic_fetch_add(&counter, 1u), dot);
    return len >= 0 && (size_t)len < n;
}

/* Display formats whose pixel values are taken as sRGB-encoded. */
static bool is_srgb_format(const char *path)
{
    static const char *const exts[] = {"png", "jpg", "jpeg", "bmp", "gif",
                                       "tga", "ppm", "pgm", "pnm", "webp"};
    const char *dot = extension_dot(path);
    if (!*dot) return false;
    for (size_t i = 0; i < sizeof exts / sizeof exts[0]; i++)
        if (strcasecmp(dot + 1, exts[i]) == 0) return true;
    return false;
}

/* Index of the alpha channel (last of 2 or 4), or -1. */
static int alpha_channel(int channels)
{
    return channels == 2 || channels == 4 ? channels - 1 : -1;
}

static float srgb_encode(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

static float srgb_decode(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* Clamp to [0,1] (NaN -> 0), optionally sRGB-encode, round to 8 bits. */
static unsigned char to_u8(float v, bool srgb)
{
    v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
    if (srgb) v = srgb_encode(v);
    return (unsigned char)(v * 255.0f + 0.5f);
}

/* The image as malloc'd 8-bit values, or NULL when out of memory. */
static unsigned char *image_to_u8(const Image *img, bool srgb)
{
    size_t n = image_count(img), c = (size_t)img->channels;
    unsigned char *px = malloc(n);
    if (!px) return NULL;
    int alpha = alpha_channel(img->channels);
    for (size_t i = 0; i < n; i++) px[i] = to_u8(img->data[i], srgb && (int)(i % c) != alpha);
    return px;
}

static void linearise(Image *img)
{
    size_t n = image_count(img), c = (size_t)img->channels;
    int alpha = alpha_channel(img->channels);
    for (size_t i = 0; i < n; i++)
        if ((int)(i % c) != alpha) img->data[i] = srgb_decode(img->data[i]);
}

/* Flush a file the plugin wrote to disk, so the rename publishes whole data. */
static bool fsync_path(const char *path, char *msg, size_t n)
{
    int fd = open(path, O_RDONLY);
    bool ok = fd >= 0 && fsync(fd) == 0;
    if (!ok) snprintf(msg, n, "fsync of the temporary file failed: %s", strerror(errno));
    if (fd >= 0) close(fd);
    return ok;
}

/* Encode img and have the plugin write it to tmp; message in msg on failure. */
static bool write_tmp(const OiioPluginApi *api, const char *tmp, const Image *img, bool srgb,
                      char *msg, size_t n)
{
    unsigned char *px = image_to_u8(img, srgb);
    if (!px) {
        snprintf(msg, n, "out of memory");
        return false;
    }
    int rc = api->write_u8(tmp, img->width, img->height, img->channels, px, msg, (int)n);
    free(px);
    return rc == 0 && fsync_path(tmp, msg, n);
}

bool image_write_ldr(const char *path, const Image *img, bool srgb, Error *err)
{
    int c = img->channels;
    if (!img->data || (c != 1 && c != 3 && c != 4))
        return error_set(err, "%s: cannot write a %d-channel image as 8-bit (1, 3 or 4 channels)", path, c);
    const OiioPluginApi *api = plugin_get(path, "PNG/JPEG output", err);
    if (!api) return false;
    char tmp[PATH_BUF], msg[ERROR_MSG_MAX];
    if (!tmp_sibling(path, tmp, sizeof tmp)) return error_set(err, "%s: path too long", path);
    if (!write_tmp(api, tmp, img, srgb, msg, sizeof msg)) {
        remove(tmp);
        return error_set(err, "%s: %s", path, msg);
    }
    return rename_into_place(tmp, path, err);
}

/* OiioPixelAlloc: the Image (ctx) sized by image_init, whose limits apply. */
static float *alloc_image(void *ctx, int w, int h, int channels, char *msg, int n)
{
    Image *img = ctx;
    Error err;
    if (image_init(img, w, h, channels, &err)) return img->data;
    snprintf(msg, (size_t)n, "%s", err.msg);
    return NULL;
}

bool image_read(const char *path, Image *img, Error *err)
{
    *img = (Image){0};
    if (!image_file_check(path, err)) return false;
    const OiioPluginApi *api = plugin_get(path, "PNG/JPEG input", err);
    if (!api) return false;
    char msg[ERROR_MSG_MAX];
    if (api->read_float(path, alloc_image, img, msg, (int)sizeof msg) != 0) {
        image_free(img);
        return error_set(err, "%s: %s", path, msg);
    }
    if (is_srgb_format(path)) linearise(img);
    return true;
}
