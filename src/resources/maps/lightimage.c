/* lightimage.c -- summed-area tables of an emission image (lightimage.h). */
#include "resources/maps/lightimage.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/hash.h"

static void sat_destroy(void *r)
{
    LightImageSat *t = r;
    free(t->sum);
    free(t->sum2);
    free(t);
}

static size_t sat_bytes(const void *r)
{
    const LightImageSat *t = r;
    return sizeof *t + 2 * sizeof(double) * 3 * (size_t)(t->width + 1) * (size_t)(t->height + 1);
}

static const ResourceKind kind_light_image_sat = {"light_image_sat", sat_bytes, sat_destroy, RES_FRAME};

static size_t at(const LightImageSat *t, int x, int y, int c)
{
    return ((size_t)y * (size_t)(t->width + 1) + (size_t)x) * 3 + (size_t)c;
}

static void *build_sat(const void *args, Error *err)
{
    const Image *im = args;
    LightImageSat *t = calloc(1, sizeof *t);
    size_t n = 3 * (size_t)(im->width + 1) * (size_t)(im->height + 1);
    if (t) {
        t->sum = calloc(n, sizeof *t->sum);
        t->sum2 = calloc(n, sizeof *t->sum2);
    }
    if (!t || !t->sum || !t->sum2) {
        if (t) sat_destroy(t);
        error_set(err, "out of memory for the light image's tables");
        return NULL;
    }
    t->width = im->width;
    t->height = im->height;
    for (int y = 0; y < im->height; y++)
        for (int x = 0; x < im->width; x++)
            for (int c = 0; c < 3; c++) {
                double v = image_px(im, x, y)[im->channels >= 3 ? c : 0];
                t->peak = fmax(t->peak, v);
                t->sum[at(t, x + 1, y + 1, c)] = v + t->sum[at(t, x, y + 1, c)] + t->sum[at(t, x + 1, y, c)] -
                                                 t->sum[at(t, x, y, c)];
                t->sum2[at(t, x + 1, y + 1, c)] = v * v + t->sum2[at(t, x, y + 1, c)] +
                                                  t->sum2[at(t, x + 1, y, c)] - t->sum2[at(t, x, y, c)];
            }
    return t;
}

const LightImageSat *res_light_image_sat(ResourceManager *rm, const Scene *scene, int light_index, Error *err)
{
    const Light *l = &scene->lights[light_index];
    if (l->kind != LIGHT_TEXTURED_RECT || !l->emission.data) {
        error_set(err, "light %d has no emission image (it is a %s light)", light_index + 1, light_kind_name(l->kind));
        return NULL;
    }
    Hasher h;
    hash_init(&h);
    hash_str(&h, "light image sat 1");
    hash_u64(&h, scene->hash_lights[light_index]);
    char desc[160];
    snprintf(desc, sizeof desc, "light %d image %dx%d", light_index + 1, l->emission.width, l->emission.height);
    return rm_acquire(rm, &kind_light_image_sat, hash_final(&h), desc, build_sat, &l->emission, err);
}

/* Integral of a table from the image's top-left corner to the real pixel
 * position (x, y): the integral of a piecewise-constant image is bilinear
 * inside each pixel, so fractional positions interpolate exactly. */
static double integral(const LightImageSat *t, const double *table, double x, double y, int c)
{
    x = fmin(fmax(x, 0.0), t->width);
    y = fmin(fmax(y, 0.0), t->height);
    int x0 = (int)x < t->width ? (int)x : t->width - 1, y0 = (int)y < t->height ? (int)y : t->height - 1;
    double fx = x - x0, fy = y - y0;
    double a = table[at(t, x0, y0, c)], b = table[at(t, x0 + 1, y0, c)];
    double d = table[at(t, x0, y0 + 1, c)], e = table[at(t, x0 + 1, y0 + 1, c)];
    return a + fx * (b - a) + fy * (d - a) + fx * fy * (a - b - d + e);
}

static double box_sum(const LightImageSat *t, const double *table, double x0, double x1, double y0, double y1, int c)
{
    return integral(t, table, x1, y1, c) - integral(t, table, x0, y1, c) - integral(t, table, x1, y0, c) +
           integral(t, table, x0, y0, c);
}

void light_image_box(const LightImageSat *t, double u0, double u1, double v0, double v1, double mean[3],
                     double *variance)
{
    double x0 = u0 * t->width, x1 = u1 * t->width, y0 = (1.0 - v1) * t->height, y1 = (1.0 - v0) * t->height;
    double area = (x1 - x0) * (y1 - y0), var = 0.0;
    for (int c = 0; c < 3; c++) {
        double m = area > 0.0 ? box_sum(t, t->sum, x0, x1, y0, y1, c) / area : 0.0;
        double m2 = area > 0.0 ? box_sum(t, t->sum2, x0, x1, y0, y1, c) / area : 0.0;
        mean[c] = fmax(m, 0.0);
        var += fmax(m2 - m * m, 0.0);
    }
    *variance = t->peak > 0.0 ? var / (3.0 * t->peak * t->peak) : 0.0;
}
