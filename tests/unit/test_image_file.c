/* test_image_file.c -- io/image_file: the OpenImageIO plugin is loaded only on
 * first use, PNG round trips (sRGB RGB, linear gray, RGBA with linear alpha),
 * atomic writes, the error messages of failed reads and writes, and empty or
 * truncated light images refused (by the reader and the scene loader). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "fixtures.h"
#include "io/image_file.h"
#include "scene/scene.h"
#include "test.h"

static bool plugin_loaded_at_start, oiio_mapped_at_start;

/* Does /proc/self/maps list a file whose path contains `needle`? */
static bool mapped(const char *needle)
{
    char *maps = file_read_all("/proc/self/maps", NULL, NULL);
    bool found = maps && strstr(maps, needle);
    free(maps);
    return found;
}

/* Snapshot before main(), independent of which tests run first. */
__attribute__((constructor)) static void snapshot_at_start(void)
{
    plugin_loaded_at_start = image_plugin_loaded();
    oiio_mapped_at_start = mapped("libOpenImageIO");
}

static void tmp_path(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", test_tmpdir(), name);
}

/* Number of entries in the test's scratch directory (no stray temporaries). */
static int tmpdir_entries(void)
{
    DIR *d = opendir(test_tmpdir());
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));) n += e->d_name[0] != '.';
    if (d) closedir(d);
    return n;
}

static float srgb_encode(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

static float clamp01(float v)
{
    return v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
}

/* A w x h gradient per channel, running a little outside [0,1] to test clamping. */
static bool make_gradient(Image *img, int w, int h, int channels)
{
    Error err;
    if (!image_init(img, w, h, channels, &err)) return false;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < channels; c++)
                image_px(img, x, y)[c] = -0.1f + 1.2f * (float)(x + y * (c + 1)) / (float)((w - 1) + (h - 1) * (c + 1));
    return true;
}

/* Write img, read it back; values must agree within 1/255 after sRGB encoding
 * (the reader linearises PNGs) -- i.e. the stored bytes were `expected`. */
static void roundtrip(const char *name, int channels, bool srgb)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    Image img, back = {0};
    Error err;
    CHECK(make_gradient(&img, 37, 19, channels));
    bool ok = image_write_ldr(path, &img, srgb, &err) && image_read(path, &back, &err);
    CHECK_MSG(ok, "%s", err.msg);
    CHECK(back.width == 37 && back.height == 19 && back.channels == channels);
    CHECK(tmpdir_entries() == 1);
    for (size_t i = 0; i < image_count(&img); i++) {
        bool alpha = channels == 4 && i % 4 == 3;
        float want = clamp01(img.data[i]), got = back.data[i];
        if (srgb && !alpha) want = srgb_encode(want);
        if (!alpha) got = srgb_encode(got);
        CHECK_NEAR(got, want, 1.0 / 255.0 + 1e-6);
    }
    image_free(&img);
    image_free(&back);
}

TEST(image_file_plugin_loaded_lazily)
{
    CHECK(!plugin_loaded_at_start);
    CHECK(!oiio_mapped_at_start);
    char path[512];
    tmp_path(path, sizeof path, "tiny.png");
    Image img;
    Error err;
    CHECK(image_init(&img, 2, 2, 1, &err));
    bool ok = image_write_ldr(path, &img, true, &err);
    image_free(&img);
    CHECK_MSG(ok, "%s", err.msg);
    CHECK(image_plugin_loaded());
    CHECK(mapped("libOpenImageIO"));
}

TEST(image_file_png_rgb_srgb_roundtrip)
{
    roundtrip("rgb.png", 3, true);
}

TEST(image_file_png_gray_linear_roundtrip)
{
    roundtrip("gray.png", 1, false);
}

TEST(image_file_png_rgba_alpha_linear)
{
    roundtrip("rgba.png", 4, true);
}

TEST(image_file_write_failures_leave_no_file)
{
    char path[512];
    tmp_path(path, sizeof path, "missing-dir/out.png");
    Image img;
    Error err;
    CHECK(image_init(&img, 4, 4, 3, &err));
    bool ok = image_write_ldr(path, &img, true, &err);
    image_free(&img);
    CHECK(!ok);
    CHECK_MSG(strstr(err.msg, path), "%s", err.msg);
    CHECK(!file_exists(path));
    CHECK(image_init(&img, 4, 4, 2, &err));
    tmp_path(path, sizeof path, "two.png");
    ok = image_write_ldr(path, &img, true, &err);
    image_free(&img);
    CHECK(!ok && strstr(err.msg, "2-channel"));
    CHECK(tmpdir_entries() == 0);
}

TEST(image_file_read_missing_or_garbage_fails)
{
    char path[512];
    Image img;
    Error err;
    tmp_path(path, sizeof path, "missing.png");
    CHECK(!image_read(path, &img, &err));
    CHECK_MSG(strstr(err.msg, path), "%s", err.msg);
    CHECK(img.data == NULL);
    tmp_path(path, sizeof path, "garbage.png");
    FILE *fp = fopen(path, "wb");
    CHECK(fp);
    fputs("this is not a PNG file\n", fp);
    fclose(fp);
    CHECK(!image_read(path, &img, &err));
    CHECK_MSG(strstr(err.msg, path), "%s", err.msg);
    CHECK(img.data == NULL);
}

/* An sRGB gradient of w x h RGB pixels written to path (its extension's format). */
static bool write_gradient(const char *path, int w, int h, Error *err)
{
    Image img;
    if (!make_gradient(&img, w, h, 3)) return error_set(err, "out of memory");
    bool ok = image_write_ldr(path, &img, true, err);
    image_free(&img);
    return ok;
}

/* Write the first `keep` bytes of file `from` to `to` (0: an empty file). */
static bool copy_prefix(const char *from, const char *to, size_t keep)
{
    size_t size = 0;
    char *bytes = file_read_all(from, &size, NULL);
    FILE *fp = bytes ? fopen(to, "wb") : NULL;
    bool ok = fp && size > keep && fwrite(bytes, 1, keep, fp) == keep;
    if (fp) ok = fclose(fp) == 0 && ok;
    free(bytes);
    return ok;
}

/* A scene lighting a plane with the textured rectangle `image` (beside it). */
static const char *light_image_scene(const char *image)
{
    static char text[1024];
    snprintf(text, sizeof text,
             "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 8, height = 6 },\n"
             "  lights = { { type = 'textured_rect', position = {0, 4, 0}, direction = {0, -1, 0},\n"
             "               width = 1, height = 1, image = '%s' } },\n"
             "  objects = { { shape = 'plane' } } }\n",
             image);
    return text;
}

/* Empty and truncated light images (the fuzzer's first finding was the empty
 * PNG): each is refused by the reader and by the scene loader, naming the
 * file (and the scene field) and why, in one line, with the image left
 * empty. Truncations cut the header (8 bytes: the PNG signature, 2: the JPEG
 * SOI marker) or the pixel data (half the file: libjpeg would fill the
 * missing rows with grey and call it a success). */
TEST(image_file_empty_or_truncated_light_images_refused)
{
    static const char *const exts[] = {"png", "jpg"};
    for (int e = 0; e < 2; e++) {
        char whole[512], cut[512], name[64];
        snprintf(name, sizeof name, "whole.%s", exts[e]);
        tmp_path(whole, sizeof whole, name);
        Image back;
        Error err;
        bool ok = write_gradient(whole, 64, 48, &err);
        CHECK_MSG(ok, "%s", err.msg);
        size_t size = 0;
        free(file_read_all(whole, &size, NULL));
        const size_t keeps[] = {0, e == 0 ? 8 : 2, size / 2};
        for (int k = 0; k < 3; k++) {
            snprintf(name, sizeof name, "cut-%zu.%s", keeps[k], exts[e]);
            tmp_path(cut, sizeof cut, name);
            CHECK(copy_prefix(whole, cut, keeps[k]));
            ok = image_read(cut, &back, &err);
            if (ok) image_free(&back);
            CHECK_MSG(!ok, "%s (%zu of %zu bytes) was read", name, keeps[k], size);
            const char *why = keeps[k] == 0 ? "empty file" : e == 0 ? "truncated PNG" : k == 2 ? "Premature end" : "";
            CHECK_MSG(strstr(err.msg, cut) && strstr(err.msg, why) && !strchr(err.msg, '\n'), "%s", err.msg);
            CHECK(back.data == NULL);
            Scene sc;
            ok = scene_load(fixture_file("s.lua", light_image_scene(name)), NULL, 0, &sc, &err);
            if (ok) scene_free(&sc);
            CHECK_MSG(!ok, "a scene with light image %s loaded", name);
            CHECK_MSG(strstr(err.msg, name) && strstr(err.msg, "lights[1].image"), "%s", err.msg);
        }
    }
}

/* OIIO's fallback is off: a file is decoded by the reader its extension
 * names or refused, never handed to another reader (the fuzzer's slow unit:
 * 31 bytes named .png that the WebP reader took for a 16383^2 image, 8 s).
 * A real PNG named .jpg, and those 31 bytes under either name. */
TEST(image_file_reader_chosen_by_extension_only)
{
    char png[512], jpg[512];
    tmp_path(png, sizeof png, "picture.png");
    tmp_path(jpg, sizeof jpg, "picture.jpg");
    Image back;
    Error err;
    bool ok = write_gradient(png, 16, 8, &err);
    CHECK_MSG(ok, "%s", err.msg);
    CHECK(rename(png, jpg) == 0);
    ok = image_read(jpg, &back, &err);
    if (ok) image_free(&back);
    CHECK_MSG(!ok, "a PNG named .jpg was read");
    CHECK_MSG(strstr(err.msg, jpg), "%s", err.msg);
    static const unsigned char webp_bomb[31] = {0x2f, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c,
                                                0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0xda, 0xe3, 0xe3, 0xe3, 0x1c,
                                                0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c, 0x1c};
    const char *paths[] = {png, jpg};
    for (int i = 0; i < 2; i++) {
        FILE *fp = fopen(paths[i], "wb");
        CHECK(fp && fwrite(webp_bomb, 1, sizeof webp_bomb, fp) == sizeof webp_bomb && fclose(fp) == 0);
        ok = image_read(paths[i], &back, &err);
        if (ok) image_free(&back);
        CHECK_MSG(!ok, "the fuzzer's 31 bytes named %s were read", paths[i]);
        CHECK_MSG(strstr(err.msg, paths[i]) && !strchr(err.msg, '\n'), "%s", err.msg);
        printf("    %s\n", err.msg);
    }
}
