/* test_nan_inject.c -- a NaN depth reaches the output as NaN (issue 13 §1):
 * for every shadow-map technique, every shadow map the lab builds gets a
 * NaN checkerboard (every other texel) as soon as it is built, through the
 * resource manager's build hook, before anything reads it: the maps a
 * technique keys its own way (light_sampling's, one per light sample, keyed
 * by the sample point) are poisoned like the light's own, and every
 * resource built from a map (moments, box blurs, SATs, min-max pyramids,
 * shadow-width maps, slice tables) inherits the NaN, so every filter window
 * mixes NaN with depths (where fmin/fmax would keep the depths). Then the
 * technique renders, and samples that read a NaN texel must be NaN in the
 * visibility (the test asks for some: nearest lookups read half), and
 * the metrics must count them as non-finite, not score them as lit or
 * shadowed. fmin/fmax, `!(x > 0)` guards and comparisons that read NaN as
 * "not a blocker" turned such samples into values. 48 x 36 samples, 64^2
 * maps, a 4-sample reference, one thread (idle OpenMP workers would only
 * spin): a second or two for the registry. */
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "filtered_fixtures.h"
#include "soft_helpers.h"
#include "techniques/smap.h"
#include "test.h"

#define NAN_W 48
#define NAN_H 36
#define NAN_MAP_SIZE 64

/* rm_on_build hook: a NaN checkerboard over every face of a shadow map. */
static void poison_map(const char *kind, void *res, void *user)
{
    (void)user;
    if (strcmp(kind, "shadow_map") != 0) return;
    ShadowMap *m = res;
    for (size_t i = 0; i < (size_t)m->num_faces * m->res * m->res; i++)
        if ((i % (size_t)m->res + i / (size_t)m->res) % 2 == 0) m->depth[i] = NAN;
}

/* Render t on a lab whose every depth map is a NaN checkerboard; the lit
 * candidates and the NaN among them; metrics' non-finite count. false if it
 * cannot run. */
static bool render_poisoned(const Technique *t, const char *scene, long *candidates, long *nans, long *nonfinite)
{
    Error err;
    Lab *lab = filtered_open(scene, NAN_W, NAN_H);
    if (!lab) return false;
    double p[TECH_MAX_PARAMS];
    tech_params_default(t, p);
    p[SMAP_P_MAP_SIZE] = NAN_MAP_SIZE;
    rm_on_build(lab_resources(lab), poison_map, NULL);
    RenderRequest rq = {.tech = t, .params = p, .light_index = 0, .repeat = 1};
    RenderResult r;
    bool ok = lab_render(lab, &rq, &r, &err);
    if (!ok) printf("    %s: %s\n", t->name, err.msg);
    const uint8_t *cls = ok ? res_classes(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    *candidates = *nans = 0;
    for (long s = 0; cls && s < (long)r.visibility.width * r.visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        (*candidates)++;
        *nans += isnan(r.visibility.data[s * r.visibility.channels]);
    }
    Metrics mt;
    ok = cls && soft_metrics(lab, &r.visibility, 4, &mt);
    *nonfinite = ok ? mt.nonfinite : -1;
    if (cls) render_result_free(&r);
    lab_close(lab);
    return ok;
}

TEST(test_nan_inject_depth_map_nan_reaches_output_and_metrics)
{
    int failed = 0, threads = omp_get_max_threads();
    omp_set_num_threads(1);
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        if (!smap_has_map_params(t)) continue; /* ray traced: no depth map */
        const char *scene = t->lights & LIGHT_BIT(LIGHT_SPHERE) ? "scenes/sphere-on-plane.lua" : "scenes/contact.lua";
        long candidates, nans, nonfinite;
        bool ran = render_poisoned(t, scene, &candidates, &nans, &nonfinite);
        if (!ran) omp_set_num_threads(threads);
        CHECK_MSG(ran, "%s did not run", t->name);
        bool good = nans > 0 && nonfinite >= nans;
        printf("    %-14s NaN in %ld of %ld lit candidates, metrics non-finite %ld%s\n", t->name, nans, candidates,
               nonfinite, good ? "" : "  <- NaN lost");
        failed += !good;
    }
    omp_set_num_threads(threads);
    CHECK_MSG(failed == 0, "%d techniques turned a NaN depth into a value", failed);
}
