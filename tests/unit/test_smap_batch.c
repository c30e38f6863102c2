/* test_smap_batch.c -- smap_receivers, the batched float32 receiver set-up
 * every map technique shares (smap.h): on perspective and ortho maps, with
 * and without the normal offset, it locates each lit candidate where the
 * double-precision lookup (lightview_locate, lightview_texel_world) does, to
 * float32 rounding; a sample gets the same receiver whatever its place in a
 * batch (smap_receiver is a batch of one); other classes are left out.
 * smap_refs gives pcf the same references to the bit, and pcf's vector box
 * counts as its taps one by one, past the map's edges too. */
#include <float.h>
#include <stdlib.h>
#include <string.h>
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
        ref = k % 2 ? -ref : ref;                                                        /* and (-1, 0] */
        float z0 = (float)ref, zs[3] = {nextafterf(z0, -INFINITY), z0, nextafterf(z0, INFINITY)};
        float up = (double)z0 < ref ? nextafterf(z0, INFINITY) : z0;
        differing += memcmp(&up, &(float){smap_ref_up(ref)}, sizeof up) != 0;
        for (int i = 0; i < 3; i++, tried++)
            differing += (ref <= zs[i]) != (smap_ref_up(ref) <= zs[i]) || (ref > zs[i]) != (smap_ref_up(ref) > zs[i]);
    }
    CHECK_MSG(differing == 0, "%ld of %ld float compares differ from the double compare", differing, tried);
    CHECK_MSG(isnan(smap_ref_up(NAN)), "NaN reference became a value");
    CHECK_MSG(smap_ref_up(-INFINITY) == -INFINITY && smap_ref_up(-1e300) == -FLT_MAX && smap_ref_up(1e-300) > 0.0f,
              "smap_ref_up at the ends of float's range: %g %g %g", smap_ref_up(-INFINITY), smap_ref_up(-1e300),
              smap_ref_up(1e-300));
}

/* smap_refs against smap_receivers on every lit candidate: the same
 * inside answer, texel coordinates and reference (rounded up), to the bit. */
static long refs_differing(Lab *lab, const char *params, long *inside_count)
{
    Error err;
    const Technique *t = tech_find("pcf", &err);
    double values[TECH_MAX_PARAMS];
    if (!t || !filtered_params(t, params, values)) return -1;
    ShadowMapSpec spec = smap_spec(values);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    if (!m || !vs || !cls) return -1;
    SmapBias b = smap_bias(values, lab_scene(lab));
    long differing = 0;
    *inside_count = 0;
    for (int first = 0; first < vs->count; first += SMAP_BATCH) {
        int n = vs->count - first < SMAP_BATCH ? vs->count - first : SMAP_BATCH;
        SmapReceiver r[SMAP_BATCH];
        bool inside[SMAP_BATCH];
        SmapRefs refs;
        smap_receivers(m, &b, vs->p_world + first, vs->n_geom_world + first, cls + first, n, r, inside);
        smap_refs(m, &b, vs->p_world + first, vs->n_geom_world + first, cls + first, n, &refs);
        int candidates = 0;
        for (int k = 0; k < n; k++) candidates += cls[first + k] == SAMPLE_LIT_CANDIDATE;
        differing += refs.count != candidates;
        for (int k = 0; k < refs.count; k++) {
            const SmapReceiver *o = &r[refs.sample[k]];
            bool in = inside[refs.sample[k]];
            *inside_count += in;
            differing += cls[first + refs.sample[k]] != SAMPLE_LIT_CANDIDATE || refs.inside[k] != in ||
                         (in && (refs.face[k] != o->mc.face || refs.s[k] != o->mc.s || refs.t[k] != o->mc.t ||
                                 memcmp(&refs.ref_up[k], &(float){smap_ref_up(o->ref)}, sizeof(float)) != 0));
        }
    }
    return differing;
}

TEST(test_smap_refs_are_the_receivers_references_to_the_bit)
{
    static const char *const sphere[] = {
        "projection=perspective depth=ndc slope_bias=0 bias_steps=2000",
        "projection=perspective depth=linear slope_bias=0 bias=0.01 bias_steps=30",
        "depth=ndc depth_bits=u16 slope_bias=0 bias_steps=3 normal_offset=1",
        "depth=linear depth_bits=u24 slope_bias=0 bias_steps=3",
        "depth=ndc slope_bias=1 bias_steps=50",                /* a plane per receiver: through the records */
        "projection=cube depth=ndc slope_bias=0 bias_steps=9", /* a map the batch path does not serve */
        NULL};
    static const char *const overhead[] = {"projection=ortho depth=ndc slope_bias=0 bias_steps=50 normal_offset=2",
                                           "projection=ortho depth=linear slope_bias=0 bias=0.001", NULL};
    static const struct { const char *scene; const char *const *cases; } scenes[] = {
        {"scenes/sphere-on-plane.lua", sphere}, {"scenes/overhead-plane.lua", overhead}};
    for (int s = 0; s < 2; s++) {
        Lab *lab = filtered_open(scenes[s].scene, 160, 120);
        CHECK(lab);
        for (const char *const *c = scenes[s].cases; *c; c++) {
            char params[256];
            snprintf(params, sizeof params, "map_size=256 %s", *c);
            long inside = 0, differing = refs_differing(lab, params, &inside);
            printf("    %s %s: %ld inside, %ld differ\n", scenes[s].scene, params, inside, differing);
            CHECK_MSG(inside > 5000, "%s: only %ld receivers inside", params, inside);
            CHECK_MSG(differing == 0, "%s: %ld receivers differ from smap_receivers'", params, differing);
        }
        lab_close(lab);
    }
}

/* pcf's box without the receiver plane (smap_refs, taps 4 to a vector)
 * against the box counted tap by tap with smap_lit on the sample's
 * SmapReceiver: lit candidates whose visibility differs at all. */
static long box_differing(Lab *lab, const char *params, long *candidates)
{
    Error err;
    const Technique *t = tech_find("pcf", &err);
    double values[TECH_MAX_PARAMS];
    RenderResult rr = {0};
    if (!t || !filtered_params(t, params, values) || !filtered_render(lab, "pcf", params, &rr)) return -1;
    ShadowMapSpec spec = smap_spec(values);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    if (!m || !vs || !cls) return -1;
    SmapBias b = smap_bias(values, lab_scene(lab));
    int K = (int)values[SMAP_NUM_PARAMS];
    b.filter_radius = 0.5 * (K - 1);
    long differing = 0;
    *candidates = 0;
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float expect = 1.0f;
        if (smap_receiver(m, &b, vs->p_world[s], vs->n_geom_world[s], &r)) {
            int i0 = (int)floor(r.mc.s - 0.5 * K + 0.5), j0 = (int)floor(r.mc.t - 0.5 * K + 0.5), lit = 0;
            for (int j = j0; j < j0 + K; j++)
                for (int i = i0; i < i0 + K; i++) lit += smap_lit(m, &r, i, j) == 1.0f;
            expect = (float)lit / (float)(K * K);
        }
        (*candidates)++;
        differing += rr.visibility.data[s] != expect;
    }
    render_result_free(&rr);
    return differing;
}

TEST(test_pcf_box_counts_as_its_taps_one_by_one_at_every_width_and_edge)
{
    /* K = 1, 4 (whole vectors), 5 and 7 (a masked last vector), 15; on a 16^2
     * map most boxes reach past an edge, on 64^2 few */
    static const char *const cases[] = {"K=1 map_size=16", "K=4 map_size=16", "K=5 map_size=16", "K=7 map_size=64",
                                        "K=15 map_size=16", "K=15 map_size=64 depth=ndc slope_bias=0", NULL};
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", 160, 120);
    CHECK(lab);
    for (const char *const *c = cases; *c; c++) {
        char params[128];
        snprintf(params, sizeof params, "kernel=box receiver_plane=0 %s", *c);
        long candidates = 0, differing = box_differing(lab, params, &candidates);
        printf("    %s: %ld of %ld lit candidates differ\n", params, differing, candidates);
        CHECK_MSG(candidates > 5000 && differing == 0, "%s: %ld of %ld lit candidates differ from the taps one by one",
                  params, differing, candidates);
    }
    lab_close(lab);
}
