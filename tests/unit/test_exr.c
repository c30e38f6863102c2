/* test_exr.c -- io/exr: bit-exact float round trips (NaN, Inf, denormals,
 * interleaved input, odd and extreme sizes), string attributes, half input
 * with an offset data window, and clean failures on missing, corrupt and
 * unwritable files that leave no partial output behind. */
#include <dirent.h>
#include <openexr.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "io/exr.h"
#include "test.h"

static float from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static uint32_t to_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* Special values first (NaNs with payloads, a signalling NaN, infinities,
 * denormals, -0, extremes), then arbitrary bit patterns. */
static float sample(size_t i, int channel)
{
    static const uint32_t special[] = {0x7fc00000u, 0xffc00000u, 0x7fc12345u, 0x7f800001u, 0x7f800000u,
                                       0xff800000u, 0x00000001u, 0x807fffffu, 0x80000000u, 0x7f7fffffu,
                                       0x00800000u, 0x3f800000u};
    size_t n = sizeof special / sizeof special[0];
    if (i < n) return from_bits(special[(i + (size_t)channel) % n]);
    uint32_t x = (uint32_t)i * 2654435761u ^ (uint32_t)channel * 0x9e3779b9u;
    x ^= x >> 15;
    x *= 0x2c1b3c6du;
    return from_bits(x ^ (x >> 12));
}

static char *tmp_path(const char *name)
{
    static char buf[512];
    snprintf(buf, sizeof buf, "%s/%s", test_tmpdir(), name);
    return buf;
}

static bool write_bytes(const char *path, const void *data, size_t n)
{
    FILE *fp = fopen(path, "wb");
    if (!fp) return false;
    bool ok = fwrite(data, 1, n, fp) == n;
    return (fclose(fp) == 0) && ok;
}

static int dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));) n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d) closedir(d);
    return n;
}

static bool channel_matches(const ExrImage *img, const char *name, const float *src, int stride)
{
    int c = exr_image_channel(img, name);
    if (c < 0) return false;
    const float *plane = img->data + (size_t)c * (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++)
        if (to_bits(plane[i]) != to_bits(src[i * (size_t)stride])) return false;
    return true;
}

/* Write V and error planar and P.X, N.Z interleaved (stride 3, a junk slot
 * between them), read back, compare bits; NULL on success, else what failed. */
static const char *roundtrip(int w, int h, Error *err)
{
    size_t n = (size_t)w * (size_t)h;
    float *v = malloc(n * sizeof *v), *e = malloc(n * sizeof *e), *pn = malloc(3 * n * sizeof *pn);
    const char *why = v && e && pn ? NULL : "out of memory";
    for (size_t i = 0; !why && i < n; i++) {
        v[i] = sample(i, 0);
        e[i] = sample(i, 1);
        pn[3 * i] = sample(i, 2);
        pn[3 * i + 1] = 12345.0f;
        pn[3 * i + 2] = sample(i, 3);
    }
    ExrChannel ch[] = {{"V", v, 1}, {"error", e, 1}, {"P.X", pn, 3}, {"N.Z", pn + 2, 3}};
    const char *path = tmp_path("rt.exr");
    ExrImage img;
    if (!why && !exr_write(path, w, h, ch, 4, NULL, 0, err)) why = "write failed";
    if (!why && !exr_read(path, &img, err)) why = "read failed";
    if (!why) {
        static const char *sorted[] = {"N.Z", "P.X", "V", "error"};
        if (img.width != w || img.height != h || img.num_channels != 4) why = "wrong size";
        for (int c = 0; !why && c < 4; c++)
            if (strcmp(img.names[c], sorted[c]) != 0) why = "channels not sorted by name";
        if (!why && !(channel_matches(&img, "V", v, 1) && channel_matches(&img, "error", e, 1) &&
                      channel_matches(&img, "P.X", pn, 3) && channel_matches(&img, "N.Z", pn + 2, 3)))
            why = "pixel bits differ";
        if (!why && exr_image_channel(&img, "Z") != -1) why = "found a channel that is not there";
        exr_image_free(&img);
    }
    free(v);
    free(e);
    free(pn);
    return why;
}

TEST(exr_roundtrip_bit_exact)
{
    static const int sizes[][2] = {{7, 5}, {1, 1}, {4096, 16}, {33, 17}, {1, 40}, {3, 1}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        Error err = {{0}};
        const char *why = roundtrip(sizes[s][0], sizes[s][1], &err);
        CHECK_MSG(!why, "%dx%d: %s %s", sizes[s][0], sizes[s][1], why, err.msg);
    }
}

TEST(exr_attributes_roundtrip)
{
    float px[6] = {1, 2, 3, 4, 5, 6};
    ExrChannel ch = {"Y", px, 1};
    ExrAttr attrs[] = {{"shadowlab.technique", "pcf"},
                       {"shadowlab.scene", "scenes/a b/c.lua"},
                       {"comments", "utf-8: \xc3\xbc\xe2\x82\xac"},
                       {"shadowlab.empty", ""}};
    const char *path = tmp_path("attrs.exr");
    Error err = {{0}};
    CHECK_MSG(exr_write(path, 3, 2, &ch, 1, attrs, 4, &err), "%s", err.msg);
    ExrImage img;
    CHECK_MSG(exr_read(path, &img, &err), "%s", err.msg);
    int found = 0;
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < img.num_attrs; a++)
            found += !strcmp(img.attr_names[a], attrs[i].name) && !strcmp(img.attr_values[a], attrs[i].value);
    int num_attrs = img.num_attrs;
    bool pixels_ok = channel_matches(&img, "Y", px, 1);
    exr_image_free(&img);
    CHECK_MSG(found == 4 && num_attrs == 4, "found %d of 4, %d string attributes", found, num_attrs);
    CHECK(pixels_ok);
    CHECK(img.data == NULL && img.num_channels == 0 && img.num_attrs == 0);
}

/* A 2x3 one-channel ("Y") file of the given type, uncompressed, with its data
 * window at (3, 5), written through OpenEXRCore directly. */
static bool write_core_file(const char *path, exr_pixel_type_t type, const void *data)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_attr_box2i_t dw = {.min = {.x = 3, .y = 5}, .max = {.x = 4, .y = 7}};
    int part = -1;
    int32_t bpe = type == EXR_PIXEL_HALF ? 2 : 4;
    exr_chunk_info_t ci;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool ok = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init) == EXR_ERR_SUCCESS &&
              exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part) == EXR_ERR_SUCCESS &&
              exr_initialize_required_attr_simple(ctxt, part, 2, 3, EXR_COMPRESSION_NONE) == EXR_ERR_SUCCESS &&
              exr_set_data_window(ctxt, part, &dw) == EXR_ERR_SUCCESS &&
              exr_add_channel(ctxt, part, "Y", type, EXR_PERCEPTUALLY_LINEAR, 1, 1) == EXR_ERR_SUCCESS &&
              exr_write_header(ctxt) == EXR_ERR_SUCCESS;
    for (int y = 5; ok && y <= 7; y++) { /* uncompressed: one line per chunk */
        bool first = y == 5;
        ok = exr_write_scanline_chunk_info(ctxt, part, y, &ci) == EXR_ERR_SUCCESS &&
             (first ? exr_encoding_initialize(ctxt, part, &ci, &enc) : exr_encoding_update(ctxt, part, &ci, &enc)) ==
                 EXR_ERR_SUCCESS;
        if (!ok) break;
        enc.channels[0].user_bytes_per_element = (int16_t)bpe;
        enc.channels[0].user_data_type = (uint16_t)type;
        enc.channels[0].user_pixel_stride = bpe;
        enc.channels[0].user_line_stride = 2 * bpe;
        enc.channels[0].encode_from_ptr = (const uint8_t *)data + (y - 5) * 2 * bpe;
        ok = (!first || exr_encoding_choose_default_routines(ctxt, part, &enc) == EXR_ERR_SUCCESS) &&
             exr_encoding_run(ctxt, part, &enc) == EXR_ERR_SUCCESS;
    }
    ok = exr_encoding_destroy(ctxt, &enc) == EXR_ERR_SUCCESS && ok;
    return exr_finish(&ctxt) == EXR_ERR_SUCCESS && ok;
}

TEST(exr_reads_half_as_float_with_offset_window)
{
    /* 1, 0.5, -2, 65504, smallest half denormal (2^-24), +Inf */
    const uint16_t half[6] = {0x3c00, 0x3800, 0xc000, 0x7bff, 0x0001, 0x7c00};
    const float want[6] = {1.0f, 0.5f, -2.0f, 65504.0f, 5.9604644775390625e-8f, INFINITY};
    const char *path = tmp_path("half.exr");
    CHECK(write_core_file(path, EXR_PIXEL_HALF, half));
    ExrImage img;
    Error err = {{0}};
    CHECK_MSG(exr_read(path, &img, &err), "%s", err.msg);
    bool ok = img.width == 2 && img.height == 3 && img.num_channels == 1 && channel_matches(&img, "Y", want, 1);
    exr_image_free(&img);
    CHECK(ok);
}

TEST(exr_rejects_uint_channels)
{
    const uint32_t ids[6] = {1, 2, 3, 4, 5, 6};
    const char *path = tmp_path("uint.exr");
    CHECK(write_core_file(path, EXR_PIXEL_UINT, ids));
    ExrImage img;
    Error err = {{0}};
    CHECK(!exr_read(path, &img, &err));
    CHECK_MSG(strstr(err.msg, path) && strstr(err.msg, "channel Y"), "%s", err.msg);
    CHECK(img.data == NULL && img.names == NULL);
}

TEST(exr_read_missing_file_fails)
{
    const char *path = tmp_path("missing.exr");
    ExrImage img;
    Error err = {{0}};
    CHECK(!exr_read(path, &img, &err));
    CHECK_MSG(strstr(err.msg, path) != NULL, "%s", err.msg);
    CHECK(img.data == NULL && img.names == NULL && img.num_channels == 0);
}

/* Write `n` bytes as `name` and try to read it: NULL if that fails cleanly
 * (message with the path, img left empty), else what went wrong. */
static const char *read_fails(const char *name, const void *data, size_t n, Error *err)
{
    const char *path = tmp_path(name);
    ExrImage img;
    if (!write_bytes(path, data, n)) return "cannot write the test file";
    if (exr_read(path, &img, err)) {
        exr_image_free(&img);
        return "read succeeded";
    }
    if (!strstr(err->msg, path)) return "message lacks the path";
    return img.data == NULL && img.names == NULL ? NULL : "image not emptied";
}

TEST(exr_read_corrupt_file_fails)
{
    float px[33 * 17];
    for (int i = 0; i < 33 * 17; i++) px[i] = sample((size_t)i, 0);
    ExrChannel ch = {"V", px, 1};
    Error err = {{0}};
    CHECK_MSG(exr_write(tmp_path("good.exr"), 33, 17, &ch, 1, NULL, 0, &err), "%s", err.msg);
    size_t size = 0;
    char *bytes = file_read_all(tmp_path("good.exr"), &size, &err);
    CHECK_MSG(bytes && size > 64, "%s", err.msg);
    char noise[300];
    for (size_t i = 0; i < sizeof noise; i++) noise[i] = (char)(i * 7 + 3);
    memcpy(noise, bytes, 8); /* the magic number and version, then noise */
    struct { const char *name; const void *data; size_t n; } cases[] = {
        {"empty.exr", "", 0},
        {"text.exr", "this is not an EXR file\n", 24},
        {"noise.exr", noise, sizeof noise},
        {"magic.exr", bytes, 8},
        {"quarter.exr", bytes, size / 4},
        {"cut.exr", bytes, size - 9},
    };
    const char *why = NULL;
    size_t c = 0;
    for (; !why && c < sizeof cases / sizeof cases[0]; c++)
        why = read_fails(cases[c].name, cases[c].data, cases[c].n, &err);
    free(bytes);
    CHECK_MSG(!why, "%s: %s (%s)", cases[c - 1].name, why, err.msg);
}

TEST(exr_write_into_missing_dir_fails)
{
    float px = 1.0f;
    ExrChannel ch = {"V", &px, 1};
    char path[600], tmp[700];
    snprintf(path, sizeof path, "%s/no/such/dir/out.exr", test_tmpdir());
    atomic_tmp_name(path, tmp, sizeof tmp);
    Error err = {{0}};
    CHECK(!exr_write(path, 1, 1, &ch, 1, NULL, 0, &err));
    CHECK_MSG(strstr(err.msg, path) != NULL, "%s", err.msg);
    CHECK(!file_exists(path) && !file_exists(tmp));
    CHECK(dir_entries(test_tmpdir()) == 0);
}

TEST(exr_failed_write_keeps_old_file_and_no_temp)
{
    float px[4] = {1, 2, 3, 4};
    ExrChannel ch = {"V", px, 1};
    ExrChannel dup[2] = {{"V", px, 1}, {"V", px, 1}};
    ExrAttr clash = {"compression", "zip"}; /* a required attribute of another type */
    const char *path = tmp_path("out.exr");
    Error err = {{0}};
    CHECK_MSG(exr_write(path, 2, 2, &ch, 1, NULL, 0, &err), "%s", err.msg);
    CHECK(!exr_write(path, 2, 2, &ch, 1, &clash, 1, &err));
    CHECK_MSG(strstr(err.msg, path) && strstr(err.msg, "attribute compression:"), "%s", err.msg);
    CHECK(!exr_write(path, 2, 2, dup, 2, NULL, 0, &err));
    CHECK_MSG(strstr(err.msg, path) && strstr(err.msg, "channel V:"), "%s", err.msg);
    CHECK(dir_entries(test_tmpdir()) == 1);
    ExrImage img;
    CHECK_MSG(exr_read(path, &img, &err), "%s", err.msg);
    bool same = img.width == 2 && channel_matches(&img, "V", px, 1);
    exr_image_free(&img);
    CHECK(same);
}

TEST(exr_write_rejects_bad_arguments)
{
    float px[4] = {0};
    ExrChannel ok = {"V", px, 1}, no_data = {"V", NULL, 1}, no_stride = {"V", px, 0}, no_name = {"", px, 1};
    ExrAttr no_value = {"a", NULL};
    const char *path = tmp_path("bad.exr");
    Error err = {{0}};
    CHECK(!exr_write(path, 0, 2, &ok, 1, NULL, 0, &err));
    CHECK(!exr_write(path, 2, 2, &ok, 0, NULL, 0, &err));
    CHECK(!exr_write(path, 2, 2, &no_data, 1, NULL, 0, &err));
    CHECK(!exr_write(path, 2, 2, &no_stride, 1, NULL, 0, &err));
    CHECK(!exr_write(path, 2, 2, &no_name, 1, NULL, 0, &err));
    CHECK(!exr_write(path, 2, 2, &ok, 1, &no_value, 1, &err));
    CHECK_MSG(strstr(err.msg, path) != NULL, "%s", err.msg);
    CHECK(dir_entries(test_tmpdir()) == 0);
}
