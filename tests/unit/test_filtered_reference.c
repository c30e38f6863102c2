/* test_filtered_reference.c -- the prefiltered shadow maps of course ch.4
 * against the Embree reference, where their sources say they do well and
 * where they say they fail: with one occluder over a receiver each is as
 * good as PCF of the same width (§4.2: "similar to PCF"); on stacked
 * occluders VSM bleeds light into the umbra (§4.2.1, Fig. 4.5) and layers,
 * exponential warps, four moments or bleeding reduction take it away
 * (§4.2.2, §4.2.4, Peters & Klein 2015), the last at the penumbra's cost;
 * ESM leaks at contacts as e^(-c gap) (§4.2.4); CSM with 4 terms rings light
 * into the umbra where 16 do not (§4.2.3, Fig. 4.7). The bounds sit above
 * the values measured at writing (printed) by the margins stated. */
#include <string.h>
#include "filtered_fixtures.h"
#include "test.h"

#define REF_SAMPLES 64

typedef struct Scored { Metrics m; bool ok; } Scored;

/* A technique with "name=value ..." over its defaults, scored against the
 * scene's reference (REF_SAMPLES R2 light samples). */
static Scored score(Lab *lab, const char *tech, const char *list)
{
    Scored out = {.ok = false};
    Error err;
    RenderResult rr;
    RefInfo info;
    RefRequest ref_rq = {0, {MEASURE_VISIBILITY, REF_SAMPLES, SAMPLING_R2, 1, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &ref_rq, &info, &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const uint8_t *term = res_terminator(lab_resources(lab), lab_scene(lab), 0, &err);
    if (!ref || !cls || !term) { printf("    %s\n", err.msg); return out; }
    if (!filtered_render(lab, tech, list, &rr)) return out;
    out.ok = metrics_compute(&rr.visibility, ref, cls, term, &out.m, NULL, &err);
    render_result_free(&rr);
    printf("    %-5s %-36s rmse %.4f | umbra leak %.4f | penumbra over-dark %.4f\n", tech, list, out.m.region[REGION_ALL].rmse,
           out.m.region[REGION_UMBRA].leak_mean, out.m.region[REGION_PENUMBRA].dark_mean);
    return out;
}

TEST(test_filtered_do_as_well_as_pcf_under_one_occluder)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", 240, 180);
    CHECK(lab);
    const char *p = "map_size=512 K=9";
    Scored pcf = score(lab, "pcf", p);
    CHECK(pcf.ok);
    int n = 0;
    for (int i = 0; i < tech_count(); i++) {
        const Technique *t = tech_at(i);
        if (!filtered_acquires_moments(t)) continue;
        Scored s = score(lab, t->name, p);
        /* Out-of-range values cannot get out: each technique clamps its
         * result to [0, 1] (vsm.c and csm.c with comparisons, which NaN
         * passes; esm.c with fmin, which would turn NaN into 1). */
        CHECK_MSG(s.ok && s.m.nonfinite == 0, "%s: %ld non-finite values", t->name, s.m.nonfinite);
        /* Measured within 0.001 of PCF's RMSE (0.038) and umbra leaks up to
         * 0.004 (CSM's ringing): bounds of 0.005 and 0.01. */
        CHECK_MSG(fabs(s.m.region[REGION_ALL].rmse - pcf.m.region[REGION_ALL].rmse) < 0.005, "%s: rmse %.4f, pcf %.4f",
                  t->name, s.m.region[REGION_ALL].rmse, pcf.m.region[REGION_ALL].rmse);
        CHECK_MSG(s.m.region[REGION_UMBRA].leak_mean < 0.01, "%s leaks %.4f into the umbra", t->name,
                  s.m.region[REGION_UMBRA].leak_mean);
        n++;
    }
    CHECK(n >= 6);
    lab_close(lab);
}

TEST(test_vsm_bleeds_on_stacked_occluders_and_its_remedies_do_not)
{
    Lab *lab = filtered_open("scenes/overlap.lua", 240, 180);
    CHECK(lab);
    const char *p = "map_size=512 K=9";
    char q[256];
    Scored pcf = score(lab, "pcf", p), vsm = score(lab, "vsm", p);
    CHECK(pcf.ok && vsm.ok);
    double leak_pcf = pcf.m.region[REGION_UMBRA].leak_mean, leak_vsm = vsm.m.region[REGION_UMBRA].leak_mean;
    /* Measured 0.0385 against PCF's 0.0016. */
    CHECK_MSG(leak_vsm > 0.02 && leak_vsm > 10 * leak_pcf, "vsm leak %.4f, pcf %.4f", leak_vsm, leak_pcf);
    /* The remedies (measured 0.0023, 0.0019, 0.0022, 0.0011: PCF's own leak
     * and a little) within a tenth of VSM's; where they fail (one layer for
     * both slabs; a nearly linear warp at c = 2; a large moment bias:
     * measured 0.0385, 0.0282, 0.0784) above half of it. */
    static const struct { const char *tech, *params; bool fails; } cases[] = {
        {"lvsm", "layers=8", false}, {"evsm", "", false}, {"msm", "", false}, {"vsm", "bleed_reduction=0.3", false},
        {"lvsm", "layers=2", true},  {"evsm", "exponent_pos=2 exponent_neg=2", true}, {"msm", "moment_bias=0.01", true}};
    double reduced_dark = 0.0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        snprintf(q, sizeof q, "%s %s", p, cases[i].params);
        Scored s = score(lab, cases[i].tech, q);
        CHECK(s.ok);
        double leak = s.m.region[REGION_UMBRA].leak_mean;
        if (cases[i].fails)
            CHECK_MSG(leak > 0.5 * leak_vsm, "%s %s leaks only %.4f", cases[i].tech, cases[i].params, leak);
        else
            CHECK_MSG(leak < 0.1 * leak_vsm, "%s %s still leaks %.4f", cases[i].tech, cases[i].params, leak);
        if (i == 3) reduced_dark = s.m.region[REGION_PENUMBRA].dark_mean;
    }
    /* Bleeding reduction pays in the penumbra (course §4.2.2: "darker"):
     * measured 0.1037 against VSM's 0.0715. */
    CHECK(reduced_dark > vsm.m.region[REGION_PENUMBRA].dark_mean + 0.01);
    lab_close(lab);
}

TEST(test_esm_leaks_at_contacts_as_the_exponent_falls)
{
    Lab *lab = filtered_open("scenes/contact.lua", 240, 180);
    CHECK(lab);
    const char *p = "map_size=1024 K=5";
    char q[256];
    Scored pcf = score(lab, "pcf", p), esm80 = score(lab, "esm", p);
    snprintf(q, sizeof q, "%s exponent=20", p);
    Scored esm20 = score(lab, "esm", q);
    CHECK(pcf.ok && esm80.ok && esm20.ok);
    double l_pcf = pcf.m.region[REGION_UMBRA].leak_mean, l80 = esm80.m.region[REGION_UMBRA].leak_mean,
           l20 = esm20.m.region[REGION_UMBRA].leak_mean;
    /* Measured 0.0023 (pcf), 0.0066 (c = 80), 0.0655 (c = 20): the catalogue's
     * e^(-c gap) puts a gap of 1% of the depth range at 0.45 for c = 80, and
     * c = 20 lets four times larger gaps through. */
    CHECK_MSG(l80 < 0.015, "esm c = 80 leaks %.4f at contacts", l80);
    CHECK_MSG(l20 > 5 * l80 && l20 > 10 * l_pcf, "c = 20 leaks %.4f, c = 80 %.4f, pcf %.4f", l20, l80, l_pcf);
    lab_close(lab);
}

TEST(test_csm_rings_into_the_umbra_with_few_terms)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", 240, 180);
    CHECK(lab);
    Scored m16 = score(lab, "csm", "map_size=512 K=9 terms=16"), m4 = score(lab, "csm", "map_size=512 K=9 terms=4");
    CHECK(m16.ok && m4.ok);
    double l16 = m16.m.region[REGION_UMBRA].leak_mean, l4 = m4.m.region[REGION_UMBRA].leak_mean;
    /* Measured 0.0042 and 0.0539 (Fig. 4.7: "four coefficients show strong ringing"). */
    CHECK_MSG(l4 > 5 * l16 && l4 > 0.02, "terms 4 leaks %.4f, terms 16 %.4f", l4, l16);
    lab_close(lab);
}
