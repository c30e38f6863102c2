/* exr.c -- float32 EXR read/write on OpenEXRCore's C API (never the C++ one).
 * Writing encodes one scanline chunk at a time straight from the caller's
 * (possibly interleaved) buffers into a temporary sibling file, which is
 * synced and renamed into place. Reading decodes each chunk straight into
 * the planes of one float buffer, converting half to float on the way.
 * OpenEXR's error callback stores its detailed message in a thread-local
 * buffer (instead of printing to stderr) so that it can go into Error. */
#include "io/exr.h"
#include <errno.h>
#include <fcntl.h>
#include <openexr.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/fsutil.h"

#define PART 0 /* the one part written; the part read */
/* Largest image read, in samples (4 GiB of floats): a corrupt data window
 * fails with a message instead of a giant allocation. */
#define MAX_SAMPLES ((int64_t)1 << 30)
#define TMP_PATH_MAX 4096 /* room for `path` plus atomic_tmp_name's suffix */

static _Thread_local char last_detail[512];

/* The state shared by the helpers of one exr_write or exr_read call. */
typedef struct Job {
    exr_context_t ctxt;
    const char *path;
    Error *err;
} Job;

static void capture_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    snprintf(last_detail, sizeof last_detail, "%s", msg ? msg : "");
}

static exr_context_initializer_t job_initializer(void)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = capture_error;
    last_detail[0] = '\0';
    return init;
}

/* True if rv is success; otherwise fill the error with the path, what failed
 * (printf-style), OpenEXR's message and code name and, when it says more,
 * the detail its error callback reported. */
__attribute__((format(printf, 3, 4))) static bool check(const Job *job, exr_result_t rv, const char *what, ...)
{
    if (rv == EXR_ERR_SUCCESS) return true;
    char what_buf[256];
    va_list ap;
    va_start(ap, what);
    vsnprintf(what_buf, sizeof what_buf, what, ap);
    va_end(ap);
    const char *msg = exr_get_default_error_message(rv);
    bool more = last_detail[0] && strcmp(last_detail, msg) != 0;
    return error_set(job->err, "%s: %s: %s (%s)%s%s", job->path, what_buf, msg, exr_get_error_code_as_string(rv),
                     more ? ": " : "", more ? last_detail : "");
}

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

/* ---- writing ---- */

static bool check_write_args(const char *path, int width, int height, const ExrChannel *channels,
                             int num_channels, const ExrAttr *attrs, int num_attrs, Error *err)
{
    if (strlen(path) + 32 >= TMP_PATH_MAX) return error_set(err, "%s: path too long", path);
    if (width < 1 || height < 1)
        return error_set(err, "%s: image size %dx%d must be at least 1x1", path, width, height);
    if (num_channels < 1 || !channels) return error_set(err, "%s: no channels to write", path);
    if (num_attrs < 0 || (num_attrs > 0 && !attrs)) return error_set(err, "%s: bad attribute list", path);
    for (int c = 0; c < num_channels; c++) {
        const ExrChannel *ch = &channels[c];
        if (!ch->name || !ch->name[0] || !ch->data)
            return error_set(err, "%s: channel %d has no name or no data", path, c);
        if (ch->stride < 1 || (int64_t)width * ch->stride > INT32_MAX / 4)
            return error_set(err, "%s: channel %s: stride %d out of range [1, %d]", path, ch->name, ch->stride,
                             (int)(INT32_MAX / 4 / width));
    }
    for (int a = 0; a < num_attrs; a++)
        if (!attrs[a].name || !attrs[a].name[0] || !attrs[a].value)
            return error_set(err, "%s: attribute %d has no name or no value", path, a);
    return true;
}

static bool write_header(const Job *job, int width, int height, const ExrChannel *channels, int num_channels,
                         const ExrAttr *attrs, int num_attrs)
{
    int part = -1;
    if (!check(job, exr_add_part(job->ctxt, NULL, EXR_STORAGE_SCANLINE, &part), "cannot add part") ||
        !check(job, exr_initialize_required_attr_simple(job->ctxt, part, width, height, EXR_COMPRESSION_ZIP),
               "cannot set the header"))
        return false;
    for (int c = 0; c < num_channels; c++)
        if (!check(job, exr_add_channel(job->ctxt, part, channels[c].name, EXR_PIXEL_FLOAT,
                                        EXR_PERCEPTUALLY_LINEAR, 1, 1),
                   "cannot add channel %s", channels[c].name))
            return false;
    for (int a = 0; a < num_attrs; a++)
        if (!check(job, exr_attr_set_string(job->ctxt, part, attrs[a].name, attrs[a].value),
                   "cannot set attribute %s", attrs[a].name))
            return false;
    return check(job, exr_write_header(job->ctxt), "cannot write the header");
}

static const ExrChannel *find_channel(const ExrChannel *channels, int num_channels, const char *name)
{
    for (int c = 0; c < num_channels; c++)
        if (strcmp(channels[c].name, name) == 0) return &channels[c];
    return NULL;
}

/* Point every channel of the chunk starting at row y at the caller's data
 * (a channel not found keeps a NULL pointer, which exr_encoding_run rejects). */
static void bind_inputs(exr_encode_pipeline_t *enc, const ExrChannel *channels, int num_channels, int width,
                        int y)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *info = &enc->channels[c];
        const ExrChannel *ch = find_channel(channels, num_channels, info->channel_name);
        if (!ch) continue;
        info->user_bytes_per_element = 4;
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_pixel_stride = ch->stride * 4;
        info->user_line_stride = width * ch->stride * 4;
        info->encode_from_ptr = (const uint8_t *)(ch->data + (size_t)y * (size_t)width * (size_t)ch->stride);
    }
}

static bool encode_chunk(const Job *job, exr_encode_pipeline_t *enc, int y, int width, const ExrChannel *channels,
                         int num_channels)
{
    exr_chunk_info_t ci;
    if (!check(job, exr_write_scanline_chunk_info(job->ctxt, PART, y, &ci), "cannot start a chunk")) return false;
    bool first = y == 0;
    exr_result_t rv = first ? exr_encoding_initialize(job->ctxt, PART, &ci, enc)
                            : exr_encoding_update(job->ctxt, PART, &ci, enc);
    if (!check(job, rv, "cannot set up encoding")) return false;
    bind_inputs(enc, channels, num_channels, width, ci.start_y);
    if (first && !check(job, exr_encoding_choose_default_routines(job->ctxt, PART, enc), "no encoder"))
        return false;
    return check(job, exr_encoding_run(job->ctxt, PART, enc), "cannot encode a chunk");
}

static bool write_pixels(const Job *job, int width, int height, const ExrChannel *channels, int num_channels)
{
    int32_t lines = 0;
    if (!check(job, exr_get_scanlines_per_chunk(job->ctxt, PART, &lines), "cannot get the chunk size"))
        return false;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool ok = true;
    for (int y = 0; ok && y < height; y += lines) ok = encode_chunk(job, &enc, y, width, channels, num_channels);
    exr_result_t rv = exr_encoding_destroy(job->ctxt, &enc);
    return ok && check(job, rv, "cannot free the encoder");
}

/* Flush the finished temporary file to disk before it replaces `path`. */
static bool sync_file(const char *tmp, const char *path, Error *err)
{
    int fd = open(tmp, O_RDONLY);
    bool ok = fd >= 0 && fsync(fd) == 0;
    int e = errno;
    if (fd >= 0) close(fd);
    return ok || error_set(err, "%s: cannot sync %s: %s", path, tmp, strerror(e));
}

bool exr_write(const char *path, int width, int height, const ExrChannel *channels, int num_channels,
               const ExrAttr *attrs, int num_attrs, Error *err)
{
    if (!path) return error_set(err, "exr_write: no path");
    if (!check_write_args(path, width, height, channels, num_channels, attrs, num_attrs, err)) return false;
    char tmp[TMP_PATH_MAX];
    atomic_tmp_name(path, tmp, sizeof tmp);
    Job job = {NULL, path, err};
    exr_context_initializer_t init = job_initializer();
    bool ok = check(&job, exr_start_write(&job.ctxt, tmp, EXR_WRITE_FILE_DIRECTLY, &init), "cannot create EXR") &&
              write_header(&job, width, height, channels, num_channels, attrs, num_attrs) &&
              write_pixels(&job, width, height, channels, num_channels);
    exr_result_t rv = exr_finish(&job.ctxt);
    ok = ok && check(&job, rv, "cannot finish EXR") && sync_file(tmp, path, err);
    if (!ok) {
        remove(tmp);
        return false;
    }
    return rename_into_place(tmp, path, err);
}

/* ---- reading ---- */

static bool check_channels(const Job *job, const exr_attr_chlist_t *chlist)
{
    if (chlist->num_channels < 1) return error_set(job->err, "%s: no channels", job->path);
    for (int c = 0; c < chlist->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chlist->entries[c];
        if ((e->pixel_type != EXR_PIXEL_FLOAT && e->pixel_type != EXR_PIXEL_HALF) || e->x_sampling != 1 ||
            e->y_sampling != 1)
            return error_set(job->err, "%s: channel %s: only full-resolution half/float channels are supported",
                             job->path, e->name.str);
    }
    return true;
}

/* Size the image from the data window and name its planes. */
static bool read_layout(const Job *job, ExrImage *img, exr_attr_box2i_t *dw)
{
    exr_storage_t storage;
    const exr_attr_chlist_t *chlist = NULL;
    if (!check(job, exr_get_storage(job->ctxt, PART, &storage), "cannot get the storage type") ||
        !check(job, exr_get_data_window(job->ctxt, PART, dw), "cannot get the data window") ||
        !check(job, exr_get_channels(job->ctxt, PART, &chlist), "cannot get the channels"))
        return false;
    if (storage != EXR_STORAGE_SCANLINE) return error_set(job->err, "%s: not a flat scanline EXR", job->path);
    if (!check_channels(job, chlist)) return false;
    int64_t w = (int64_t)dw->max.x - dw->min.x + 1, h = (int64_t)dw->max.y - dw->min.y + 1;
    if (w < 1 || h < 1 || w > INT32_MAX / 4 || h > INT32_MAX || w * h > MAX_SAMPLES / chlist->num_channels)
        return error_set(job->err, "%s: data window [%d %d]-[%d %d] with %d channels is empty or over %lld "
                         "samples", job->path, dw->min.x, dw->min.y, dw->max.x, dw->max.y, chlist->num_channels,
                         (long long)MAX_SAMPLES);
    img->width = (int)w;
    img->height = (int)h;
    img->num_channels = chlist->num_channels;
    img->names = calloc((size_t)img->num_channels, sizeof *img->names);
    img->data = malloc((size_t)(w * h) * (size_t)img->num_channels * sizeof(float));
    if (!img->names || !img->data) return error_set(job->err, "%s: out of memory", job->path);
    for (int c = 0; c < img->num_channels; c++) {
        const exr_attr_string_t *name = &chlist->entries[c].name;
        img->names[c] = dup_n(name->str, (size_t)name->length);
        if (!img->names[c]) return error_set(job->err, "%s: out of memory", job->path);
    }
    return true;
}

/* The string attributes, less `type` (the storage kind OpenEXR writes itself). */
static bool read_attrs(const Job *job, ExrImage *img)
{
    int32_t count = 0;
    if (!check(job, exr_get_attribute_count(job->ctxt, PART, &count), "cannot count attributes")) return false;
    img->attr_names = calloc((size_t)count + 1, sizeof *img->attr_names);
    img->attr_values = calloc((size_t)count + 1, sizeof *img->attr_values);
    if (!img->attr_names || !img->attr_values) return error_set(job->err, "%s: out of memory", job->path);
    for (int32_t i = 0; i < count; i++) {
        const exr_attribute_t *a = NULL;
        if (!check(job, exr_get_attribute_by_index(job->ctxt, PART, EXR_ATTR_LIST_FILE_ORDER, i, &a),
                   "cannot get an attribute"))
            return false;
        if (a->type != EXR_ATTR_STRING || strcmp(a->name, "type") == 0) continue;
        int n = img->num_attrs++;
        img->attr_names[n] = dup_n(a->name, strlen(a->name));
        img->attr_values[n] = dup_n(a->string->str ? a->string->str : "", (size_t)a->string->length);
        if (!img->attr_names[n] || !img->attr_values[n])
            return error_set(job->err, "%s: out of memory", job->path);
    }
    return true;
}

/* Point every channel of the chunk at its rows in its plane, as float. */
static void bind_outputs(exr_decode_pipeline_t *dec, const ExrImage *img, int row)
{
    size_t plane = (size_t)img->width * (size_t)img->height;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *info = &dec->channels[c];
        info->user_bytes_per_element = 4;
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_pixel_stride = 4;
        info->user_line_stride = img->width * 4;
        info->decode_to_ptr = (uint8_t *)(img->data + (size_t)c * plane + (size_t)row * (size_t)img->width);
    }
}

static bool decode_chunk(const Job *job, exr_decode_pipeline_t *dec, int y, int y0, ExrImage *img)
{
    exr_chunk_info_t ci;
    if (!check(job, exr_read_scanline_chunk_info(job->ctxt, PART, y, &ci), "cannot read a chunk table entry"))
        return false;
    bool first = y == y0;
    exr_result_t rv = first ? exr_decoding_initialize(job->ctxt, PART, &ci, dec)
                            : exr_decoding_update(job->ctxt, PART, &ci, dec);
    if (!check(job, rv, "cannot set up decoding")) return false;
    if (ci.start_y < y0 || ci.height < 1 || ci.start_y - y0 + ci.height > img->height || ci.width != img->width)
        return error_set(job->err, "%s: chunk at row %d does not fit the data window", job->path, y);
    bind_outputs(dec, img, ci.start_y - y0);
    if (first && !check(job, exr_decoding_choose_default_routines(job->ctxt, PART, dec), "no decoder"))
        return false;
    return check(job, exr_decoding_run(job->ctxt, PART, dec), "cannot decode a chunk");
}

static bool read_pixels(const Job *job, ExrImage *img, int y0)
{
    int32_t lines = 0;
    if (!check(job, exr_get_scanlines_per_chunk(job->ctxt, PART, &lines), "cannot get the chunk size"))
        return false;
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    bool ok = lines > 0 || error_set(job->err, "%s: bad chunk size %d", job->path, (int)lines);
    for (int64_t y = y0; ok && y < (int64_t)y0 + img->height; y += lines)
        ok = decode_chunk(job, &dec, (int)y, y0, img);
    exr_result_t rv = exr_decoding_destroy(job->ctxt, &dec);
    return ok && check(job, rv, "cannot free the decoder");
}

bool exr_read(const char *path, ExrImage *img, Error *err)
{
    memset(img, 0, sizeof *img);
    if (!path) return error_set(err, "exr_read: no path");
    Job job = {NULL, path, err};
    exr_context_initializer_t init = job_initializer();
    exr_attr_box2i_t dw;
    bool ok = check(&job, exr_start_read(&job.ctxt, path, &init), "cannot open EXR") &&
              read_layout(&job, img, &dw) && read_attrs(&job, img) && read_pixels(&job, img, dw.min.y);
    exr_result_t rv = exr_finish(&job.ctxt);
    ok = ok && check(&job, rv, "cannot close EXR");
    if (!ok) exr_image_free(img);
    return ok;
}

void exr_image_free(ExrImage *img)
{
    if (!img) return;
    for (int c = 0; img->names && c < img->num_channels; c++) free(img->names[c]);
    for (int a = 0; a < img->num_attrs; a++) {
        free(img->attr_names[a]);
        free(img->attr_values[a]);
    }
    free(img->names);
    free(img->data);
    free(img->attr_names);
    free(img->attr_values);
    memset(img, 0, sizeof *img);
}

int exr_image_channel(const ExrImage *img, const char *name)
{
    for (int c = 0; img && name && c < img->num_channels; c++)
        if (strcmp(img->names[c], name) == 0) return c;
    return -1;
}
