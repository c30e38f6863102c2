/* test_smap_batch.c -- smap_receivers, the batched float32 receiver set-up
 * every map technique shares (smap.h): on perspective and ortho maps, with
 * and without the normal offset, it locates each lit candidate where the
 * double-precision lookup (lightview_locate, lightview_texel_world) does, to
 * float32 rounding; a sample gets the same receiver whatever its place in a
 * batch (smap_receiver is a batch of one); other classes are left out. */
#include <stdlib.h>
#include "filtered_fixtures.h"
#include "rt/rt.h"
#include "techniques/smap.h"
#include "test.h"

typedef struct BatchAgreement {
    long located, inside_differs, batch_differs, others_inside;
    double max_ds, max_dz, max_dtexel; /* texels; z_ndc; relative */
} BatchAgreement;

/* The double lookup of smap_receiver's lift and normal offset. */
static MapCoord double_locate(const ShadowMap *m, const SmapBias *b, vec3 p_world, vec3 n_world, double *texel)
{
    dvec3 n = d3_from(n_world), p = d3_madd(d3_from(p_world), n, rt_ray_offset(b->scene_extent, p_world));
    MapCoord mc = lightview_locate(&m->view, p);
    *texel = lightview_texel_world(&m->view, &mc);
    if (b->normal_offset_texels > 0.0) {
        mc = lightview_locate(&m->view, d3_madd(p, n, b->normal_offset_texels * *texel));
        *texel = lightview_texel_world(&m->view, &mc);
    }
    return mc;
}

static void compare_one(const ShadowMap *m, const SmapBias *b, const ViewSamples *vs, int s, const SmapReceiver *r,
                        bool inside, BatchAgreement *a)
{
    double texel;
    MapCoord mc = double_locate(m, b, vs->p_world[s], vs->n_geom_world[s], &texel);
    SmapReceiver one;
    bool one_inside = smap_receiver(m, b, vs->p_world[s], vs->n_geom_world[s], &one);
    a->batch_differs += one_inside != inside || (inside && (one.mc.s != r->mc.s || one.mc.t != r->mc.t ||
                                                            one.ref != r->ref || one.texel_world != r->texel_world));
    a->inside_differs += mc.inside != inside;
    if (!inside || !mc.inside) return;
    a->located++;
    double ds = fmax(fabs(mc.s - r->mc.s), fabs(mc.t - r->mc.t)), dz = fabs(mc.z_ndc - r->mc.z_ndc);
    double dt = fabs(texel - r->texel_world) / texel;
    a->max_ds = fmax(a->max_ds, ds);
    a->max_dz = fmax(a->max_dz, dz);
    a->max_dtexel = fmax(a->max_dtexel, dt);
}

static BatchAgreement batch_agreement(Lab *lab, const char *params)
{
    BatchAgreement a = {0};
    Error err;
    const Technique *t = tech_find("pcf", &err);
    double values[TECH_MAX_PARAMS];
    if (!t || !filtered_params(t, params, values)) return a;
    ShadowMapSpec spec = smap_spec(values);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    if (!m || !vs || !cls) return a;
    SmapBias b = smap_bias(values, lab_scene(lab));
    SmapReceiver *r = malloc(sizeof *r * (size_t)vs->count);
    bool *inside = malloc(sizeof *inside * (size_t)vs->count);
    if (!r || !inside) return a;
    /* one odd-sized call over every sample: batches start at 0, 64, ... */
    smap_receivers(m, &b, vs->p_world, vs->n_geom_world, cls, vs->count, r, inside);
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) a.others_inside += inside[s];
        else compare_one(m, &b, vs, s, &r[s], inside[s], &a);
    }
    free(r);
    free(inside);
    return a;
}

static void check_cases(const char *scene, const char *const *cases, int n)
{
    Lab *lab = filtered_open(scene, 160, 120);
    CHECK(lab);
    for (int c = 0; c < n; c++) {
        BatchAgreement a = batch_agreement(lab, cases[c]);
        printf("    %s %s: %ld located; max |ds| %.1e texels, |dz_ndc| %.1e, texel size %.1e relative; "
               "inside differs %ld\n",
               scene, cases[c], a.located, a.max_ds, a.max_dz, a.max_dtexel, a.inside_differs);
        CHECK_MSG(a.located > 5000, "%s: only %ld receivers located", cases[c], a.located);
        /* float32: s, t ~ 1e3 texels carry ~1e-4 of rounding, z_ndc ~1e-7 */
        CHECK_MSG(a.max_ds < 2e-3, "%s: texel coordinates off by %.2g texels", cases[c], a.max_ds);
        CHECK_MSG(a.max_dz < 2e-6, "%s: z_ndc off by %.2g", cases[c], a.max_dz);
        CHECK_MSG(a.max_dtexel < 1e-5, "%s: texel size off by %.2g (relative)", cases[c], a.max_dtexel);
        CHECK_MSG(a.inside_differs <= a.located / 10000, "%s: %ld samples inside on one side only", cases[c],
                  a.inside_differs);
        CHECK_MSG(a.batch_differs == 0, "%s: %ld samples set up unlike a batch of one", cases[c], a.batch_differs);
        CHECK_MSG(a.others_inside == 0, "%s: %ld samples of other classes set up", cases[c], a.others_inside);
    }
    lab_close(lab);
}

TEST(test_smap_receivers_batch_locates_as_the_double_lookup)
{
    const char *perspective[] = {"projection=perspective depth=ndc",
                                 "projection=perspective depth=linear normal_offset=1"};
    const char *ortho[] = {"projection=ortho depth=ndc slope_bias=0", "projection=ortho depth=linear normal_offset=2"};
    check_cases("scenes/sphere-on-plane.lua", perspective, 2);
    check_cases("scenes/overhead-plane.lua", ortho, 2);
}

/* smap_ref_up: a float compare gives the double compare's answer against
 * every float32 near the reference (the float below, at and above it). */
TEST(test_smap_ref_up_compares_as_the_double_reference)
{
    uint32_t state = 12345u;
    long differing = 0, tried = 0;
    for (int k = 0; k < 100000; k++) {
        state = state * 1664525u + 1013904223u;
        double ref = (state >> 8) / 16777216.0 + ldexp((double)(state & 0xff), -40); /* [0, 1), sub-float bits */
        float z0 = (float)ref, zs[3] = {nextafterf(z0, -INFINITY), z0, nextafterf(z0, INFINITY)};
        for (int i = 0; i < 3; i++, tried++)
            differing += (ref <= zs[i]) != (smap_ref_up(ref) <= zs[i]) || (ref > zs[i]) != (smap_ref_up(ref) > zs[i]);
    }
    CHECK_MSG(differing == 0, "%ld of %ld float compares differ from the double compare", differing, tried);
    CHECK_MSG(isnan(smap_ref_up(NAN)), "NaN reference became a value");
}
