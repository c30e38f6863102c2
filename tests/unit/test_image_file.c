/* test_image_file.c -- io/image_file: the OpenImageIO plugin is loaded only on
 * first use, PNG round trips (sRGB RGB, linear gray, RGBA with linear alpha),
 * atomic writes and the error messages of failed reads and writes. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "io/image_file.h"
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
