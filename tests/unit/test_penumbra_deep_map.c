/* test_penumbra_deep_map.c -- `penumbra_deep_map` (St-Amour et al. 2005,
 * course §5.2.4) on sphere-on-plane at 160 x 120 with perspective maps (one
 * face: cheap), against `light_sampling` with the same light samples and
 * maps and against a 64-sample Embree reference; the compression bound over
 * every texel of the built resource (read through rm_on_build); the vertex
 * cap, N = 1 and the memory refusal; the build's cost linear in N, read from
 * machine-independent work counters; each sample map biasing its own depth
 * tests. One thread, about 3 s. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "soft_helpers.h"
#include "techniques/multimap.h"
#include "test.h"

#define PDM_REF_SAMPLES 64

/* Mean and largest |a - b| over the lit candidates off the terminator (where
 * the deep map counts every sample, light_sampling those above the tangent
 * plane). */
typedef struct Diff { long count; double mean_abs, max_abs; } Diff;

static Diff diff_off_terminator(Lab *lab, const Image *a, const Image *b)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const uint8_t *term = cls ? res_terminator(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
    Diff d = {0, 0.0, 0.0};
    for (long s = 0; term && s < (long)a->width * a->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || term[s]) continue;
        double e = fabs((double)a->data[s] - b->data[s]);
        d.count++;
        d.mean_abs += e;
        d.max_abs = e > d.max_abs ? e : d.max_abs;
    }
    if (d.count) d.mean_abs /= d.count;
    return d;
}

/* Lit candidates whose value is outside [0, 1] or NaN. */
static long outside_unit(Lab *lab, const Image *v)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    long bad = 0;
    for (long s = 0; cls && s < (long)v->width * v->height; s++)
        bad += cls[s] == SAMPLE_LIT_CANDIDATE && !(v->data[s] >= 0.0f && v->data[s] <= 1.0f);
    return bad;
}

/* The deep maps built while capturing: deep copies (the cache may drop them). */
#define MAX_CAPTURED 4
typedef struct Captured { DeepMap map[MAX_CAPTURED]; int count; } Captured;

static void capture(const char *kind, void *res, void *user)
{
    Captured *c = user;
    if (strcmp(kind, "penumbra_deep_map") || c->count == MAX_CAPTURED) return;
    const DeepMap *d = res;
    DeepMap *o = &c->map[c->count++];
    *o = *d;
    size_t nv = d->first[d->texels];
    o->first = malloc((d->texels + 1) * sizeof *o->first);
    o->vertex = malloc((nv ? nv : 1) * sizeof *o->vertex);
    o->unknown = malloc(d->texels);
    memcpy(o->first, d->first, (d->texels + 1) * sizeof *o->first);
    memcpy(o->vertex, d->vertex, nv * sizeof *o->vertex);
    memcpy(o->unknown, d->unknown, d->texels);
}

static void captured_free(Captured *c)
{
    for (int k = 0; k < c->count; k++) free(c->map[k].first), free(c->map[k].vertex), free(c->map[k].unknown);
    c->count = 0;
}

/* A texel's function at z from the left (left = true) or the right, written
 * apart from the technique's reader: the limits of the piecewise-linear
 * function at a depth where it may jump. */
static double limit_at(const DeepVertex *v, int n, double z, bool left)
{
    int k = 0; /* the first vertex at or beyond z (left), beyond z (right) */
    while (k < n && (left ? v[k].z < z : v[k].z <= z)) k++;
    if (k == 0) return v[0].v;
    if (k == n) return v[n - 1].v;
    if (v[k].z == v[k - 1].z) return left ? v[k - 1].v : v[k].v;
    double w = (z - v[k - 1].z) / ((double)v[k].z - v[k - 1].z);
    return v[k - 1].v + w * ((double)v[k].v - v[k - 1].v);
}

/* The largest deviation of `approx` from `exact` (error = 0: the step
 * function itself) at every depth where exact has a vertex, both sides:
 * between two of them exact is constant and approx linear, so these bound
 * the deviation at every depth. */
static double max_deviation(const DeepMap *exact, const DeepMap *approx)
{
    double worst = 0.0;
    for (size_t t = 0; t < exact->texels; t++) {
        if (exact->unknown[t] || approx->unknown[t]) continue;
        const DeepVertex *e = exact->vertex + exact->first[t], *a = approx->vertex + approx->first[t];
        int ne = (int)(exact->first[t + 1] - exact->first[t]), na = (int)(approx->first[t + 1] - approx->first[t]);
        for (int k = 0; k < ne; k++)
            for (int side = 0; side < 2; side++) {
                double d = fabs(limit_at(e, ne, e[k].z, side) - limit_at(a, na, e[k].z, side));
                worst = d > worst ? d : worst;
            }
    }
    return worst;
}

/* With error = 0 and filter = nearest the deep map is light_sampling's N
 * depth tests sampled on the centre's texel rays: the two differ where a
 * receiver's texel ray meets another sample verdict than the receiver,
 * within a texel of a sample's shadow edge, so the mean difference shrinks
 * with the centre's texels. Against the reference, the default bilinear
 * lookup's penumbra RMSE is within 1.2x light_sampling's at 256^2. */
TEST(test_penumbra_deep_map_converges_to_light_sampling)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    static const char *const sizes[] = {"map_size=128", "map_size=256"};
    double mean[2];
    Metrics mls, mpd;
    for (int k = 0; k < 2; k++) {
        const char *pl[] = {sizes[k], "projection=perspective", "samples=16", NULL};
        const char *pd[] = {sizes[k], "projection=perspective", "samples=16", "error=0", "max_vertices=512",
                            "filter=nearest", NULL};
        const char *pb[] = {sizes[k], "projection=perspective", "samples=16", "error=0", "max_vertices=512", NULL};
        RenderResult ls, pdm, bil;
        CHECK(soft_render(lab, "light_sampling", pl, &ls));
        CHECK(soft_render(lab, "penumbra_deep_map", pd, &pdm));
        CHECK(soft_render(lab, "penumbra_deep_map", pb, &bil));
        Diff d = diff_off_terminator(lab, &pdm.visibility, &ls.visibility);
        mean[k] = d.mean_abs;
        printf("    %s: vs light_sampling over %ld samples: mean |d| %.5f, max %.4f\n", sizes[k], d.count, d.mean_abs,
               d.max_abs);
        CHECK(outside_unit(lab, &pdm.visibility) == 0 && outside_unit(lab, &bil.visibility) == 0);
        if (k == 1) {
            CHECK(soft_metrics(lab, &ls.visibility, PDM_REF_SAMPLES, &mls));
            CHECK(soft_metrics(lab, &bil.visibility, PDM_REF_SAMPLES, &mpd));
        }
        render_result_free(&ls);
        render_result_free(&pdm);
        render_result_free(&bil);
    }
    CHECK_MSG(mean[1] < 0.75 * mean[0], "mean difference %.5f at 256^2 not below 0.75x 128^2's %.5f", mean[1], mean[0]);
    double rl = mls.region[REGION_PENUMBRA].rmse, rp = mpd.region[REGION_PENUMBRA].rmse;
    printf("    256^2 vs the %d-sample reference: penumbra RMSE light_sampling %.4f, penumbra_deep_map (bilinear) %.4f; "
           "lit %.4f, %.4f\n",
           PDM_REF_SAMPLES, rl, rp, mls.region[REGION_LIT].rmse, mpd.region[REGION_LIT].rmse);
    CHECK_MSG(rp < 1.2 * rl, "penumbra RMSE %.4f above 1.2x light_sampling's %.4f", rp, rl);
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* Every texel's compressed function is within `error` of its step function
 * (the error = 0 build of the same samples and maps, cube maps of 128^2:
 * the ground's drop stays inside the scene's bounds) at every event depth,
 * on both sides of each step; the vertices fall as error grows; nothing
 * reaches the cap of 512. */
TEST(test_penumbra_deep_map_compression_bound)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    Captured cap = {.count = 0};
    rm_on_build(lab_resources(lab), capture, &cap);
    static const double errors[] = {0, 0.05, 0.1, 0.2};
    for (int k = 0; k < 4; k++) {
        char e[32];
        snprintf(e, sizeof e, "error=%g", errors[k]);
        const char *p[] = {"map_size=128", "projection=cube", "samples=16", e, "max_vertices=512", NULL};
        RenderResult r;
        CHECK(soft_render(lab, "penumbra_deep_map", p, &r));
        render_result_free(&r);
    }
    rm_on_build(lab_resources(lab), NULL, NULL);
    CHECK(cap.count == 4);
    for (int k = 0; k < 4; k++) {
        const DeepMap *d = &cap.map[k];
        double dev = max_deviation(&cap.map[0], d);
        printf("    error %-4g: %u vertices (%.2f per texel), %ld capped, largest deviation %.5f\n", d->error,
               d->first[d->texels], (double)d->first[d->texels] / d->texels, d->capped, dev);
        CHECK(d->capped == 0 && d->texels == cap.map[0].texels);
        CHECK_MSG(dev <= d->error + 1e-6, "error %g: deviation %.6f", d->error, dev);
        if (k > 0) CHECK(d->first[d->texels] < cap.map[k - 1].first[cap.map[k - 1].texels]);
    }
    captured_free(&cap);
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* A cap of 2 vertices compresses every texel with more looser (counted,
 * output still in [0, 1]); one light sample, nearest, is a hard shadow in
 * {0, 1}; a deep map above 2 GiB at its cap is refused naming max_vertices
 * and map_size before any map is drawn. */
TEST(test_penumbra_deep_map_cap_and_refusals)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    Captured cap = {.count = 0};
    rm_on_build(lab_resources(lab), capture, &cap);
    const char *capped[] = {"map_size=64", "projection=perspective", "samples=4", "max_vertices=2", NULL};
    RenderResult r;
    CHECK(soft_render(lab, "penumbra_deep_map", capped, &r));
    rm_on_build(lab_resources(lab), NULL, NULL);
    CHECK(cap.count == 1);
    printf("    max_vertices=2: %ld of %zu texels capped\n", cap.map[0].capped, cap.map[0].texels);
    CHECK(cap.map[0].capped > 0);
    CHECK(outside_unit(lab, &r.visibility) == 0);
    captured_free(&cap);
    render_result_free(&r);
    const char *one[] = {"map_size=64", "projection=perspective", "samples=1", "filter=nearest", NULL};
    CHECK(soft_render(lab, "penumbra_deep_map", one, &r));
    long fractional = 0;
    for (long s = 0; s < (long)r.visibility.width * r.visibility.height; s++)
        fractional += r.visibility.data[s] != 0.0f && r.visibility.data[s] != 1.0f;
    CHECK_MSG(fractional == 0 && outside_unit(lab, &r.visibility) == 0, "N = 1: %ld values neither 0 nor 1",
              fractional);
    render_result_free(&r);
    Error err;
    const Technique *t = tech_find("penumbra_deep_map", &err);
    CHECK(t);
    double v[TECH_MAX_PARAMS];
    tech_params_default(t, v);
    CHECK(tech_param_parse(t, "map_size=8192", v, &err) && tech_param_parse(t, "max_vertices=1024", v, &err) &&
          tech_param_parse(t, "samples=1", v, &err) && tech_param_parse(t, "projection=perspective", v, &err));
    RenderRequest rq = {.tech = t, .params = v, .light_index = 0, .repeat = 1};
    CHECK(!lab_render(lab, &rq, &r, &err));
    printf("    refused: %s\n", err.msg);
    CHECK(strstr(err.msg, "max_vertices = 1024") && strstr(err.msg, "map_size = 8192"));
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* The build's cost (the course: "interactive rates, at best") is linear in
 * N: every centre texel marches every sample's map. Read from the deep
 * map's own work counters (texels read while building it, net of the maps'
 * renders), machine-independent: 16 samples read 3.5-4.5x what 4 do. */
TEST(test_penumbra_deep_map_build_linear_in_samples)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    static const char *const ns[] = {"samples=4", "samples=16"};
    double fetches[2], build_s[2];
    for (int k = 0; k < 2; k++) {
        const char *p[] = {"map_size=64", "projection=perspective", ns[k], NULL};
        RenderResult r;
        CHECK(soft_render(lab, "penumbra_deep_map", p, &r));
        fetches[k] = 0.0, build_s[k] = 0.0;
        for (int e = 0; e < rm_log_count(lab_resources(lab)); e++) {
            const ResourceEvent *ev = rm_log_event(lab_resources(lab), e);
            if (!strcmp(ev->kind, "penumbra_deep_map") && ev->built)
                fetches[k] = (double)ev->work.texel_fetches, build_s[k] = ev->own_s;
        }
        render_result_free(&r);
    }
    double ratio = fetches[1] / fetches[0];
    printf("    build: %.0f texels read at N = 4, %.0f at N = 16 (x%.2f); %.3f s, %.3f s (x%.2f, not asserted)\n",
           fetches[0], fetches[1], ratio, build_s[0], build_s[1], build_s[1] / build_s[0]);
    CHECK_MSG(fetches[0] > 0.0 && ratio >= 3.5 && ratio <= 4.5, "texels read x%.2f from N = 4 to 16", ratio);
    lab_close(lab);
    omp_set_num_threads(threads);
}

/* Each sample's depth test takes the slope-scaled bias of its own map: on
 * sphere-on-plane's cube maps the centre's -y face sees the ground at a
 * constant depth (slope 0: no bias at lookup) where the samples' -z faces
 * see it grazing, so without it the lit ground along the faces' seam read
 * 3 of 16 samples shadowed. The lit region's RMSE against the reference
 * stays within 2x light_sampling's (cube maps of 128^2). */
TEST(test_penumbra_deep_map_sample_maps_bias_their_own_tests)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    const char *pl[] = {"map_size=128", "projection=cube", "samples=16", NULL};
    const char *pd[] = {"map_size=128", "projection=cube", "samples=16", "error=0", "max_vertices=512", NULL};
    RenderResult ls, pdm;
    Metrics mls, mpd;
    CHECK(soft_render(lab, "light_sampling", pl, &ls));
    CHECK(soft_render(lab, "penumbra_deep_map", pd, &pdm));
    CHECK(soft_metrics(lab, &ls.visibility, PDM_REF_SAMPLES, &mls));
    CHECK(soft_metrics(lab, &pdm.visibility, PDM_REF_SAMPLES, &mpd));
    double rl = mls.region[REGION_LIT].rmse, rp = mpd.region[REGION_LIT].rmse;
    printf("    cube 128^2: lit RMSE light_sampling %.4f, penumbra_deep_map %.4f (signed %+.4f)\n", rl, rp,
           mpd.region[REGION_LIT].mean_signed);
    CHECK_MSG(rp < 2.0 * rl, "lit RMSE %.4f above 2x light_sampling's %.4f", rp, rl);
    render_result_free(&ls);
    render_result_free(&pdm);
    lab_close(lab);
    omp_set_num_threads(threads);
}
