/* oiio_plugin.cpp -- OpenImageIO 2.4 behind the C ABI of io/oiio_plugin.h,
 * built as build/libshadowlab_oiio.so. No exception leaves this file: every
 * failure, OIIO's own messages included, becomes a nonzero return and text
 * in the caller's err buffer. Pixel values pass through as stored: alpha
 * stays straight (OIIO's automatic (un)premultiplication is turned off). */
#include "io/oiio_plugin.h"

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace {

/* A failure on its way to the caller's err buffer. */
struct Failure {
    std::string msg;
};

std::string or_unknown(const std::string &msg)
{
    return msg.empty() ? std::string("unknown OpenImageIO error") : msg;
}

/* Run body(); turn a Failure or any exception into (1, message in err). */
template <typename Body> int guarded(char *err, int err_len, Body body)
{
    std::string msg;
    try {
        body();
        return 0;
    } catch (const Failure &f) {
        msg = f.msg;
    } catch (const std::exception &e) {
        msg = e.what();
    } catch (...) {
        msg = "unknown exception in the OpenImageIO plugin";
    }
    if (err && err_len > 0) std::snprintf(err, static_cast<size_t>(err_len), "%s", msg.c_str());
    return 1;
}

void write_u8_body(const char *path, int w, int h, int channels, const unsigned char *pixels)
{
    if (w < 1 || h < 1 || (channels != 1 && channels != 3 && channels != 4))
        throw Failure{"cannot write a " + std::to_string(w) + "x" + std::to_string(h) + "x" +
                      std::to_string(channels) + " image (1, 3 or 4 channels)"};
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Failure{or_unknown(OIIO::geterror())};
    OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1); /* store the bytes as given */
    if (!out->open(path, spec)) throw Failure{or_unknown(out->geterror())};
    bool ok = out->write_image(OIIO::TypeDesc::UINT8, pixels);
    ok = out->close() && ok;
    if (!ok) throw Failure{or_unknown(out->geterror())};
}

/* Number of floats in the image, or a Failure for empty/absurd sizes. */
size_t value_count(const OIIO::ImageSpec &spec)
{
    if (spec.width < 1 || spec.height < 1 || spec.depth != 1 || spec.nchannels < 1)
        throw Failure{"unsupported image size " + std::to_string(spec.width) + "x" +
                      std::to_string(spec.height) + "x" + std::to_string(spec.depth) + ", " +
                      std::to_string(spec.nchannels) + " channels"};
    uint64_t n = static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height) *
                 static_cast<uint64_t>(spec.nchannels);
    if (n > SIZE_MAX / sizeof(float)) throw Failure{"image too large"};
    return static_cast<size_t>(n);
}

void read_float_body(const char *path, int *w, int *h, int *channels, float **pixels)
{
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1); /* no premultiplication */
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw Failure{or_unknown(OIIO::geterror())};
    const OIIO::ImageSpec &spec = in->spec();
    size_t n = value_count(spec);
    float *buf = static_cast<float *>(std::malloc(n * sizeof(float)));
    if (!buf) throw Failure{"out of memory for " + std::to_string(n) + " floats"};
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, buf)) {
        std::free(buf);
        throw Failure{or_unknown(in->geterror())};
    }
    *w = spec.width;
    *h = spec.height;
    *channels = spec.nchannels;
    *pixels = buf;
}

int write_u8(const char *path, int w, int h, int channels, const unsigned char *pixels, char *err,
             int err_len)
{
    return guarded(err, err_len, [&] { write_u8_body(path, w, h, channels, pixels); });
}

int read_float(const char *path, int *w, int *h, int *channels, float **pixels, char *err,
               int err_len)
{
    *pixels = nullptr;
    return guarded(err, err_len, [&] { read_float_body(path, w, h, channels, pixels); });
}

void free_pixels(float *pixels)
{
    std::free(pixels);
}

const OiioPluginApi api = {OIIO_PLUGIN_ABI, write_u8, read_float, free_pixels};

} // namespace

extern "C" __attribute__((visibility("default"))) const OiioPluginApi *shadowlab_oiio_plugin(void)
{
    return &api;
}
