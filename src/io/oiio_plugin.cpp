/* oiio_plugin.cpp -- OpenImageIO 2.4 behind the C ABI of io/oiio_plugin.h,
 * built as build/libshadowlab_oiio.so. No exception leaves this file: every
 * failure, OIIO's own messages included, becomes a nonzero return and one
 * line of text in the caller's err buffer. Pixel values pass through as
 * stored: alpha stays straight (OIIO's automatic (un)premultiplication is
 * turned off). A file is decoded only by the reader its extension names. */
#include "io/oiio_plugin.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
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

/* OIIO stacks messages one per line ("Read error: hit end of file\nPNG read
 * error: ..."): joined with "; ", trailing breaks dropped. */
std::string one_line(std::string msg)
{
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    for (size_t at = msg.find('\n'); at != std::string::npos; at = msg.find('\n', at))
        msg.replace(at, 1, "; ");
    return msg;
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
    if (err && err_len > 0) std::snprintf(err, static_cast<size_t>(err_len), "%s", one_line(msg).c_str());
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

/* Reject header shapes no caller can take (depth, empty) before alloc sees them. */
void check_shape(const OIIO::ImageSpec &spec)
{
    if (spec.width < 1 || spec.height < 1 || spec.depth != 1 || spec.nchannels < 1)
        throw Failure{"unsupported image size " + std::to_string(spec.width) + "x" +
                      std::to_string(spec.height) + "x" + std::to_string(spec.depth) + ", " +
                      std::to_string(spec.nchannels) + " channels"};
}

void read_float_body(const char *path, OiioPixelAlloc alloc, void *ctx)
{
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1); /* no premultiplication */
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw Failure{or_unknown(OIIO::geterror())};
    const OIIO::ImageSpec &spec = in->spec();
    check_shape(spec);
    char msg[512] = "";
    float *buf = alloc(ctx, spec.width, spec.height, spec.nchannels, msg, static_cast<int>(sizeof msg));
    if (!buf) throw Failure{msg[0] ? msg : "no memory for the pixels"};
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, buf))
        throw Failure{or_unknown(in->geterror())};
    /* A decoder that "succeeds" with a message has made pixels up: libjpeg
     * fills a truncated file's missing rows with grey ("Premature end of
     * JPEG file"), and OIIO keeps the message without reporting an error. */
    std::string warning = in->geterror();
    if (!warning.empty()) throw Failure{warning};
}

int write_u8(const char *path, int w, int h, int channels, const unsigned char *pixels, char *err,
             int err_len)
{
    return guarded(err, err_len, [&] { write_u8_body(path, w, h, channels, pixels); });
}

int read_float(const char *path, OiioPixelAlloc alloc, void *ctx, char *err, int err_len)
{
    return guarded(err, err_len, [&] { read_float_body(path, alloc, ctx); });
}

const OiioPluginApi api = {OIIO_PLUGIN_ABI, write_u8, read_float};

} // namespace

extern "C" __attribute__((visibility("default"))) const OiioPluginApi *shadowlab_oiio_plugin(void)
{
    /* Off: with it, a ".png" that fails as PNG goes to every other reader
     * (WebP decoded a 31-byte fuzz input as a 16383^2 image, 8 s). */
    OIIO::attribute("try_all_readers", 0);
    return &api;
}
