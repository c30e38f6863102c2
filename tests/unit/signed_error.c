/* signed_error.c -- per-sample errors against the reference (signed_error.h). */
#include "signed_error.h"
#include <math.h>
#include <stdio.h>

bool signed_error(Lab *lab, const Image *v, int samples, Metrics *m, Image *e)
{
    Error err;
    RefInfo info;
    *e = (Image){0};
    RefRequest rq = {0, {MEASURE_VISIBILITY, samples, SAMPLING_STRATIFIED, 1, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
    const uint8_t *cls = ref ? res_classes(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    const uint8_t *term = cls ? res_terminator(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    if (term && image_init(e, v->width, v->height, v->channels, &err) && metrics_compute(v, ref, cls, term, m, e, &err))
        return true;
    image_free(e);
    printf("    signed error: %s\n", err.msg);
    return false;
}

long signed_error_count(const Image *e, double below, double above)
{
    long n = 0;
    for (long s = 0; s < (long)e->width * e->height; s++) {
        bool hit = false;
        for (int c = 0; c < e->channels; c++) {
            double d = e->data[s * e->channels + c];
            hit = hit || d < below || d > above;
        }
        n += hit;
    }
    return n;
}

long outside_unit_range(const Image *v)
{
    long bad = 0;
    for (size_t i = 0; i < image_count(v); i++) bad += !(v->data[i] >= 0.0f && v->data[i] <= 1.0f);
    return bad;
}
