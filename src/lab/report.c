/* report.c -- EXR bundles, PNG previews and the printed metrics table of a
 * run (see report.h); the JSON record is in record.c. */
#include "lab/report.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "core/hash.h"
#include "core/timer.h"
#include "io/exr.h"
#include "io/image_file.h"

const char *report_stem(const RunReport *r) { return r->tech ? r->tech->name : "reference"; }

double report_error_scale(double max_abs)
{
    static const double steps[] = {1, 2, 5};
    if (isnan(max_abs)) return 1.0; /* no finite error (an empty region): the full range */
    for (double decade = 0.01; decade < 1e6; decade *= 10)
        for (int i = 0; i < 3; i++)
            if (steps[i] * decade >= max_abs) return steps[i] * decade;
    return 1e6;
}

/* ---- EXR ---------------------------------------------------------------- */

#define MAX_EXR_CHANNELS 24

typedef struct ChannelList {
    ExrChannel ch[MAX_EXR_CHANNELS];
    char names[MAX_EXR_CHANNELS][32];
    int n;
} ChannelList;

static void add_channel(ChannelList *cl, const char *name, const float *data, int stride)
{
    snprintf(cl->names[cl->n], sizeof cl->names[0], "%s", name);
    cl->ch[cl->n] = (ExrChannel){cl->names[cl->n], data, stride};
    cl->n++;
}

/* An image's channels as PREFIX.V or PREFIX.R/G/B ("V", "R"... without prefix). */
static void add_image(ChannelList *cl, const char *prefix, const Image *img)
{
    static const char *const rgb[] = {"R", "G", "B"};
    for (int c = 0; c < img->channels; c++) {
        char name[32];
        const char *suffix = img->channels == 1 ? "V" : rgb[c];
        if (prefix) snprintf(name, sizeof name, "%s.%s", prefix, suffix);
        else snprintf(name, sizeof name, "%s", suffix);
        add_channel(cl, name, img->data + c, img->channels);
    }
}

static void add_vec3(ChannelList *cl, const char *prefix, const vec3 *v)
{
    static const char *const axes[] = {"X", "Y", "Z"};
    for (int a = 0; a < 3; a++) {
        char name[32];
        snprintf(name, sizeof name, "%s.%s", prefix, axes[a]);
        add_channel(cl, name, &v->x + a, 3);
    }
}

static void format_params(const RunReport *r, char *out, size_t n)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; r->tech && i < r->tech->num_params && used < n; i++) {
        char v[64];
        tech_param_format(&r->tech->params[i], r->params[i], v, sizeof v);
        used += (size_t)snprintf(out + used, n - used, "%s%s=%s", i ? " " : "", r->tech->params[i].name, v);
    }
}

/* The scene overrides the run was opened with, "key=value; ..." ("" when none). */
static void format_overrides(const Lab *lab, char *out, size_t n)
{
    const char *const *ov;
    int count = lab_overrides(lab, &ov);
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < count && used < n; i++)
        used += (size_t)snprintf(out + used, n - used, "%s%s", i ? "; " : "", ov[i]);
}

static void format_reference(const RunReport *r, char *out, size_t n)
{
    const ReferenceParams *p = &r->ref->params;
    snprintf(out, n, "%s, %d %s light samples, seed %u", measure_name(p->measure), p->samples,
             sampling_pattern_name(p->pattern), p->seed);
}

bool report_write_exr(const RunReport *r, const char *path, Error *err)
{
    const Scene *sc = lab_scene(r->lab);
    Error e2;
    const ViewSamples *vs = res_view_samples(lab_resources(r->lab), sc, &e2); /* reused, never rebuilt here */
    const uint8_t *cls = res_classes(lab_resources(r->lab), sc, r->light_index, &e2);
    if (!vs || !cls) return error_set(err, "%s", e2.msg);
    ChannelList cl = {.n = 0};
    Image class_img = {0}, object_img = {0};
    if (!image_init(&class_img, vs->width, vs->height, 1, err) || !image_init(&object_img, vs->width, vs->height, 1, err)) {
        image_free(&class_img);
        return false;
    }
    for (int s = 0; s < vs->count; s++) {
        class_img.data[s] = (float)cls[s];
        object_img.data[s] = (float)vs->object[s];
    }
    add_image(&cl, NULL, r->render ? &r->render->visibility : &r->ref->value);
    if (r->render && r->ref) add_image(&cl, "ref", &r->ref->value);
    if (r->ref) add_image(&cl, "stderr", &r->ref->std_error);
    if (r->signed_error) add_image(&cl, "error", r->signed_error);
    add_vec3(&cl, "P", vs->p_world);
    add_vec3(&cl, "N", vs->n_geom_world);
    add_channel(&cl, "depth", vs->depth_view, 1);
    add_channel(&cl, "class", class_img.data, 1);
    add_channel(&cl, "object", object_img.data, 1);
    const Image *aux = r->render ? &r->render->aux : NULL;
    for (int k = 0; aux && k < aux->channels && cl.n < MAX_EXR_CHANNELS; k++) {
        char name[32];
        snprintf(name, sizeof name, "aux.%s", r->tech->aux[k]);
        add_channel(&cl, name, aux->data + k, aux->channels);
    }

    char hash[17], params[1024] = "", refdesc[256] = "", light[64], scale[32];
    hash_hex(sc->hash, hash);
    format_params(r, params, sizeof params);
    if (r->ref) format_reference(r, refdesc, sizeof refdesc);
    snprintf(light, sizeof light, "%d (%s)", r->light_index + 1, light_kind_name(sc->lights[r->light_index].kind));
    snprintf(scale, sizeof scale, "%g", r->error_scale);
    char overrides[1024];
    format_overrides(r->lab, overrides, sizeof overrides);
    ExrAttr attrs[] = {
        {"shadowlab.overrides", overrides},
        {"shadowlab.command", r->command},
        {"shadowlab.scene", sc->path},
        {"shadowlab.scene_hash", hash},
        {"shadowlab.technique", r->tech ? r->tech->name : "reference"},
        {"shadowlab.params", params},
        {"shadowlab.light", light},
        {"shadowlab.reference", refdesc},
        {"shadowlab.error_scale", scale},
        {"shadowlab.channels",
         "V or R,G,B: visibility in [0,1] (irradiance: radiance); ref.*: reference; stderr.*: its standard error; "
         "error.*: estimate - reference; P, N: world position and geometric normal; depth: view-axis distance; "
         "class: 0 background, 1 lit candidate, 2 back-facing, 3 outside light, 4 not a receiver; object: index; "
         "aux.*: the technique's auxiliary channels (0 outside the lit candidates)"},
    };
    bool ok = exr_write(path, vs->width, vs->height, cl.ch, cl.n, attrs, (int)(sizeof attrs / sizeof attrs[0]), err);
    image_free(&class_img);
    image_free(&object_img);
    return ok;
}

/* ---- PNG previews ------------------------------------------------------ */

/* Box filter by the supersampling factor, down to the camera's pixels. */
static bool downsample(const Image *src, int f, Image *dst, Error *err)
{
    if (!image_init(dst, src->width / f, src->height / f, src->channels, err)) return false;
    float inv = 1.0f / (float)(f * f);
    for (int y = 0; y < dst->height; y++)
        for (int x = 0; x < dst->width; x++)
            for (int c = 0; c < src->channels; c++) {
                float sum = 0;
                for (int j = 0; j < f; j++)
                    for (int i = 0; i < f; i++) sum += image_px(src, x * f + i, y * f + j)[c];
                image_px(dst, x, y)[c] = sum * inv;
            }
    return true;
}

static bool write_png(const char *dir, const char *stem, const char *suffix, const Image *img, int ss, bool srgb,
                      Error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s%s.png", dir, stem, suffix);
    Image small;
    if (!downsample(img, ss, &small, err)) return false;
    bool ok = image_write_ldr(path, &small, srgb, err);
    image_free(&small);
    return ok;
}

/* albedo x cosine x visibility (course Eq. 1.3 split into shading x shadow),
 * with the light's colour; the irradiance reference is shown as it is,
 * normalised by its maximum. */
static void shade(const RunReport *r, const ViewSamples *vs, const Image *vis, Image *out)
{
    const Scene *sc = lab_scene(r->lab);
    const Light *l = &sc->lights[r->light_index];
    bool radiance = !r->render && r->ref->params.measure == MEASURE_IRRADIANCE;
    float max_v = 1e-30f;
    for (size_t i = 0; radiance && i < image_count(vis); i++) max_v = fmaxf(max_v, vis->data[i]);
    for (int s = 0; s < vs->count; s++) {
        float *o = out->data + 3 * (size_t)s;
        if (vs->object[s] < 0) { o[0] = o[1] = o[2] = 0.05f; continue; }
        const float *v = vis->data + (size_t)s * vis->channels;
        vec3 a = sc->objects[vs->object[s]].albedo;
        float cosl = fmaxf(0.0f, v3_dot(vs->n_shading_world[s], light_sample_center(l, vs->p_world[s]).dir_world));
        for (int c = 0; c < 3; c++) {
            float vc = v[vis->channels == 3 ? c : 0];
            o[c] = radiance ? vc / max_v : (&a.x)[c] * cosl * vc;
        }
    }
}

/* Diverging map: blue (-scale, over-darkening), white (0), red (+scale, light
 * leaking); samples outside the evaluated class are grey, non-finite
 * estimates black. */
static void error_colors(const Image *err_img, const uint8_t *cls, double scale, Image *out)
{
    for (int s = 0; s < out->width * out->height; s++) {
        float *o = out->data + 3 * (size_t)s;
        if (cls[s] != SAMPLE_LIT_CANDIDATE) { o[0] = o[1] = o[2] = 0.5f; continue; }
        double e = 0;
        for (int c = 0; c < err_img->channels; c++) e += err_img->data[(size_t)s * err_img->channels + c];
        if (!isfinite(e)) { o[0] = o[1] = o[2] = 0.0f; continue; }
        float t = (float)fmax(-1.0, fmin(1.0, e / err_img->channels / scale));
        o[0] = t < 0 ? 1.0f + t : 1.0f;
        o[1] = 1.0f - fabsf(t);
        o[2] = t > 0 ? 1.0f - t : 1.0f;
    }
}

/* An auxiliary channel's integer values as colours (0 grey, 1 red, 2 green,
 * 3 blue, 4 and above yellow, as seed 001's Fig. 2 colours its subdivision
 * levels); samples outside the evaluated class are black. */
static void aux_colors(const Image *aux, int k, const uint8_t *cls, Image *out)
{
    static const float palette[5][3] = {{0.35f, 0.35f, 0.35f}, {0.9f, 0.1f, 0.1f}, {0.1f, 0.8f, 0.1f},
                                        {0.15f, 0.3f, 1.0f}, {1.0f, 0.9f, 0.1f}};
    for (int s = 0; s < out->width * out->height; s++) {
        float *o = out->data + 3 * (size_t)s;
        float v = aux->data[(size_t)s * aux->channels + k];
        int level = v >= 4.0f ? 4 : v >= 0.0f ? (int)v : 0;
        for (int c = 0; c < 3; c++) o[c] = cls[s] == SAMPLE_LIT_CANDIDATE ? palette[level][c] : 0.0f;
    }
}

bool report_write_previews(const RunReport *r, const char *dir, Error *err)
{
    const Scene *sc = lab_scene(r->lab);
    const ViewSamples *vs = res_view_samples(lab_resources(r->lab), sc, err);
    const uint8_t *cls = vs ? res_classes(lab_resources(r->lab), sc, r->light_index, err) : NULL;
    if (!cls) return false;
    const Image *vis = r->render ? &r->render->visibility : &r->ref->value;
    int ss = sc->camera.supersample;
    const char *stem = report_stem(r);
    Image rgb;
    if (!image_init(&rgb, vs->width, vs->height, 3, err)) return false;
    bool radiance = !r->render && r->ref->params.measure == MEASURE_IRRADIANCE;
    shade(r, vs, vis, &rgb);
    bool ok = write_png(dir, stem, "-shaded", &rgb, ss, true, err) &&
              (radiance || write_png(dir, stem, "", vis, ss, false, err));
    if (ok && r->signed_error) {
        error_colors(r->signed_error, cls, r->error_scale, &rgb);
        ok = write_png(dir, stem, "-error", &rgb, ss, false, err);
    }
    const Image *aux = r->render ? &r->render->aux : NULL;
    for (int k = 0; ok && aux && k < aux->channels; k++) {
        char suffix[48];
        snprintf(suffix, sizeof suffix, "-aux-%s", r->tech->aux[k]);
        aux_colors(aux, k, cls, &rgb);
        ok = write_png(dir, stem, suffix, &rgb, ss, false, err);
    }
    image_free(&rgb);
    return ok;
}

/* ---- all outputs, atomically per run ------------------------------------ */

static void remove_outputs(const RunReport *r, const char *dir, const char *stem)
{
    static const char *const suffixes[] = {".exr", ".json", ".png", "-shaded.png", "-error.png"};
    char path[4096];
    for (size_t i = 0; i < sizeof suffixes / sizeof suffixes[0]; i++) {
        snprintf(path, sizeof path, "%s/%s%s", dir, stem, suffixes[i]);
        remove(path);
    }
    for (int k = 0; r->tech && k < tech_aux_count(r->tech); k++) {
        snprintf(path, sizeof path, "%s/%s-aux-%s.png", dir, stem, r->tech->aux[k]);
        remove(path);
    }
}

bool report_write_all(RunReport *r, const char *dir, bool png, Error *err)
{
    if (!mkdir_p(dir, err)) return false;
    const char *stem = report_stem(r);
    char path[4096];
    double t0 = timer_now_s();
    snprintf(path, sizeof path, "%s/%s.exr", dir, stem);
    bool ok = report_write_exr(r, path, err) && (!png || report_write_previews(r, dir, err));
    r->output_s = timer_now_s() - t0;
    snprintf(path, sizeof path, "%s/%s.json", dir, stem);
    ok = ok && report_write_record(r, path, err);
    if (!ok) remove_outputs(r, dir, stem);
    return ok;
}
