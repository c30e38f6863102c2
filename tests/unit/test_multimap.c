/* test_multimap.c -- the multiple-shadow-map techniques of course §5.2.4
 * beyond `light_sampling` (whose 1/sqrt(N) convergence test_backprojection
 * measures): `layered_attenuation` (Agrawala et al. 2000) on sphere-on-plane
 * at 160 x 120, 16 light samples, against `light_sampling` with the same
 * samples and maps and against a 64-sample Embree reference; epsilon's
 * stiffness (course §5.2.4 [OWN]); the layer cap's overflow; N = 1; the
 * LDI's size refused before any map is drawn. One thread, about 10 s. */
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "soft_helpers.h"
#include "test.h"

#define MM_REF_SAMPLES 64

/* Over the lit candidates off the terminator (where layered_attenuation
 * counts every sample and light_sampling only those above the tangent
 * plane): mean |a - b|, the share differing by more than one sample's
 * weight 1/n, and the largest difference. */
typedef struct Diff { long count, beyond_one; double mean_abs, max_abs; } Diff;

static Diff diff_off_terminator(Lab *lab, const Image *a, const Image *b, int n)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const uint8_t *term = cls ? res_terminator(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    Diff d = {0, 0, 0.0, 0.0};
    for (long s = 0; term && s < (long)a->width * a->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || term[s]) continue;
        double e = fabs((double)a->data[s] - b->data[s]);
        d.count++;
        d.beyond_one += e > 1.0 / n + 1e-6;
        d.mean_abs += e;
        d.max_abs = e > d.max_abs ? e : d.max_abs;
    }
    if (d.count) d.mean_abs /= d.count;
    return d;
}

/* Samples of the image outside [0, 1] or NaN, over the lit candidates. */
static long outside_unit(Lab *lab, const Image *v)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    long bad = 0;
    for (long s = 0; cls && s < (long)v->width * v->height; s++)
        bad += cls[s] == SAMPLE_LIT_CANDIDATE && !(v->data[s] >= 0.0f && v->data[s] <= 1.0f);
    return bad;
}

/* layered_attenuation converges to light_sampling with the same 16 samples
 * as the maps grow: the forward warp counts a sample for an LDI texel when
 * any of its warped points lands there, so each sample's shadow edge moves
 * out by up to a texel (a leak), which halves with the texel. Against the
 * reference its penumbra RMSE is within 1.3x light_sampling's at 512^2. */
TEST(test_layered_attenuation_converges_to_light_sampling)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    static const char *const sizes[] = {"map_size=256", "map_size=512"};
    double mean[2];
    Metrics mls, mla;
    for (int k = 0; k < 2; k++) {
        const char *pl[] = {sizes[k], "samples=16", NULL};
        const char *pa[] = {sizes[k], "samples=16", "epsilon=0.2", NULL};
        RenderResult ls, la;
        CHECK(soft_render(lab, "light_sampling", pl, &ls));
        CHECK(soft_render(lab, "layered_attenuation", pa, &la));
        Diff d = diff_off_terminator(lab, &la.visibility, &ls.visibility, 16);
        mean[k] = d.mean_abs;
        printf("    %s: vs light_sampling over %ld samples: mean |d| %.5f, max %.4f, %ld (%.2f%%) beyond 1/N\n",
               sizes[k], d.count, d.mean_abs, d.max_abs, d.beyond_one, 100.0 * d.beyond_one / d.count);
        CHECK_MSG(d.beyond_one < 0.01 * d.count, "%s: %ld of %ld samples differ by more than 1/N", sizes[k],
                  d.beyond_one, d.count);
        if (k == 1) {
            CHECK(soft_metrics(lab, &ls.visibility, MM_REF_SAMPLES, &mls));
            CHECK(soft_metrics(lab, &la.visibility, MM_REF_SAMPLES, &mla));
        }
        render_result_free(&ls);
        render_result_free(&la);
    }
    CHECK_MSG(mean[1] < 0.7 * mean[0], "mean difference %.5f at 512^2 not below 0.7x 256^2's %.5f", mean[1], mean[0]);
    double rl = mls.region[REGION_PENUMBRA].rmse, ra = mla.region[REGION_PENUMBRA].rmse;
    printf("    512^2 vs the %d-sample reference: penumbra RMSE light_sampling %.4f, layered_attenuation %.4f; "
           "all %.4f, %.4f\n",
           MM_REF_SAMPLES, rl, ra, mls.region[REGION_ALL].rmse, mla.region[REGION_ALL].rmse);
    CHECK_MSG(ra < 1.3 * rl, "penumbra RMSE %.4f above 1.3x light_sampling's %.4f", ra, rl);
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* Epsilon is stiff (course §5.2.4 [OWN]): 0 splits every surface into
 * layers no receiver matches (umbra everywhere), 1000 (beyond the scene)
 * merges ball and ground into one entry every sample counts (the umbra
 * lit); both are far worse than 0.2, and every output stays in [0, 1]. */
TEST(test_layered_attenuation_epsilon_is_stiff)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    static const char *const eps[] = {"epsilon=0", "epsilon=0.2", "epsilon=1000"};
    double all[3], umbra_signed[3];
    for (int k = 0; k < 3; k++) {
        const char *p[] = {"map_size=256", "samples=8", eps[k], NULL};
        RenderResult r;
        Metrics m;
        CHECK(soft_render(lab, "layered_attenuation", p, &r));
        CHECK_MSG(outside_unit(lab, &r.visibility) == 0, "%s: output outside [0, 1]", eps[k]);
        CHECK(soft_metrics(lab, &r.visibility, MM_REF_SAMPLES, &m));
        all[k] = m.region[REGION_ALL].rmse;
        umbra_signed[k] = m.region[REGION_UMBRA].mean_signed;
        printf("    %-12s RMSE all %.4f, lit region signed %+.4f, umbra signed %+.4f\n", eps[k], all[k],
               m.region[REGION_LIT].mean_signed, umbra_signed[k]);
        render_result_free(&r);
    }
    CHECK_MSG(all[0] > 4 * all[1] && all[2] > 4 * all[1], "RMSE %.4f (0), %.4f (1000) not both 4x the default's %.4f",
              all[0], all[2], all[1]);
    CHECK_MSG(umbra_signed[2] > 0.5, "epsilon beyond the scene: umbra leak %+.4f, not merged", umbra_signed[2]);
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* A layer cap of 1 drops warped depths (counted, aux overflow), one light
 * sample gives a hard shadow in {0, 1}, and an LDI above 2 GiB is refused
 * naming layers and map_size before any map is drawn. */
TEST(test_layered_attenuation_caps_and_refusals)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    const char *capped[] = {"map_size=128", "samples=4", "layers=1", NULL};
    RenderResult r;
    CHECK(soft_render(lab, "layered_attenuation", capped, &r));
    long overflowed = 0, n = (long)r.aux.width * r.aux.height;
    for (long s = 0; s < n; s++) overflowed += r.aux.data[s * r.aux.channels + 1] > 0.0f;
    printf("    layers=1: %ld of %ld samples' texels dropped warped depths\n", overflowed, n);
    CHECK(overflowed > 0);
    CHECK(outside_unit(lab, &r.visibility) == 0);
    render_result_free(&r);
    const char *one[] = {"map_size=128", "samples=1", NULL};
    CHECK(soft_render(lab, "layered_attenuation", one, &r));
    long fractional = 0;
    for (long s = 0; s < (long)r.visibility.width * r.visibility.height; s++)
        fractional += r.visibility.data[s] != 0.0f && r.visibility.data[s] != 1.0f;
    CHECK_MSG(fractional == 0 && outside_unit(lab, &r.visibility) == 0, "N = 1: %ld values neither 0 nor 1",
              fractional);
    render_result_free(&r);
    Error err;
    const Technique *t = tech_find("layered_attenuation", &err);
    CHECK(t);
    double v[TECH_MAX_PARAMS];
    tech_params_default(t, v);
    CHECK(tech_param_parse(t, "map_size=8192", v, &err) && tech_param_parse(t, "layers=64", v, &err) &&
          tech_param_parse(t, "samples=1", v, &err));
    RenderRequest rq = {.tech = t, .params = v, .light_index = 0, .repeat = 1};
    CHECK(!lab_render(lab, &rq, &r, &err));
    printf("    refused: %s\n", err.msg);
    CHECK(strstr(err.msg, "layers = 64") && strstr(err.msg, "map_size = 8192"));
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* The LDI is a keyed resource: the same parameters again reuse it (every
 * parameter of the technique is one the LDI is built from), a new epsilon
 * rebuilds it, and the log counts its bytes: at least a depth, a count and a
 * last sample per layer of every texel of one 64^2 face. */
TEST(test_layered_attenuation_ldi_is_a_keyed_resource)
{
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    const char *const base[] = {"map_size=64", "samples=4", "layers=4", NULL};
    const char *const other[] = {"map_size=64", "samples=4", "layers=4", "epsilon=0.2", NULL};
    const char *const *runs[] = {base, base, other};
    bool built[3] = {false, true, false};
    size_t bytes[3] = {0, 0, 0};
    for (int k = 0; lab && k < 3; k++)
        CHECK(soft_render_event(lab, "layered_attenuation", runs[k], "layered_attenuation_ldi", &built[k], &bytes[k]));
    printf("    layered_attenuation_ldi: built %d, again %d, at epsilon 0.2 %d; %zu bytes\n", built[0], built[1],
           built[2], bytes[0]);
    CHECK_MSG(built[0] && !built[1] && built[2], "built %d %d %d", built[0], built[1], built[2]);
    CHECK(bytes[0] >= (size_t)4 * (sizeof(float) + 2 * sizeof(uint16_t)) * 64 * 64 && bytes[2] == bytes[0]);
    lab_close(lab);
}
