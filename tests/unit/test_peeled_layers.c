/* test_peeled_layers.c -- depth-peeled layers (resources/maps/peeled.h) and
 * the backprojection family's `layers` (course §5.2.3.3, Fig. 1.8): each
 * layer is the next surface behind the one before by more than the peel
 * epsilon, empty past a texel's last; layers that hold only receivers
 * change nothing (bit for bit) and are not built at layers=1; on the
 * course's Fig. 1.8 scene (scenes/one-layer.lua: a box hidden from the
 * light's centre under a slab) and on overlap.lua the umbra's leak and the
 * penumbra's RMSE against the Embree reference fall with layers. Views of
 * 96 x 72 (128 x 96 strip; 160 x 120 for the layers' count), maps of 256^2 (128^2 on the strip), 64 light
 * samples (tiles=4), 64 reference samples. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "metrics/metrics.h"
#include "resources/maps/peeled.h"
#include "resources/standard.h"
#include "soft_helpers.h"
#include "techniques/smap.h"
#include "test.h"

/* The most surfaces any texel of the map's peeled layers holds, and how
 * many texels break the order (a surface after an empty layer, a layer not
 * behind the one before by more than the epsilon, NaN for empty). */
static int deepest_texel(Lab *lab, const ShadowMap **layer, long *misordered)
{
    ShadowMapSpec spec = shadowmap_spec_default();
    spec.res = 256;
    Error err;
    ResourceManager *rm = lab_resources(lab);
    layer[0] = res_shadow_map(rm, lab_scene(lab), 0, &spec, &err);
    for (int k = 1; layer[0] && k < PEELED_MAX_LAYERS; k++)
        if (!(layer[k] = res_peeled_layer(rm, lab_scene(lab), layer[0], k, &err))) break;
    if (!layer[0] || !layer[PEELED_MAX_LAYERS - 1]) {
        printf("    %s\n", err.msg);
        return -1;
    }
    long texels = (long)layer[0]->num_faces * layer[0]->res * layer[0]->res, bad = 0;
    int deepest = 0;
    for (long t = 0; t < texels; t++) {
        int finite = 0;
        for (int k = 0; k < PEELED_MAX_LAYERS; k++) {
            float d = layer[k]->depth[t];
            if (!isfinite(d)) {
                bad += d != INFINITY; /* empty is +INFINITY, never NaN */
                continue;
            }
            int face = (int)(t / ((long)layer[0]->res * layer[0]->res));
            bad += finite != k; /* a surface after an empty layer */
            bad += k > 0 && !(d > layer[k - 1]->depth[t] + shadowmap_peel_epsilon(layer[k - 1], face));
            finite++;
        }
        if (finite > deepest) deepest = finite;
    }
    *misordered = bad;
    return deepest;
}

/* Layers 0 .. PEELED_MAX_LAYERS - 1 of one-layer.lua's backprojection map
 * (256^2): per texel the finite layers come first, each behind the one
 * before by more than the epsilon; the deepest texel (a ray through the
 * slab's two faces, the box's two and the ground) holds exactly five. A
 * second plane 1e-5 world units behind another (within the epsilon, 1e-5
 * of the ~4-unit depth range) is peeled with it: two surfaces, not three. */
TEST(test_peeled_layers_are_each_texels_next_surfaces)
{
    Lab *lab = soft_open("one-layer.lua", NULL);
    CHECK(lab);
    const ShadowMap *layer[PEELED_MAX_LAYERS] = {NULL};
    long misordered;
    int deepest = deepest_texel(lab, layer, &misordered);
    printf("    one-layer: deepest texel %d surfaces, %ld out of order\n", deepest, misordered);
    CHECK(misordered == 0);
    CHECK_MSG(deepest == 5, "the deepest texel holds %d surfaces, not slab, slab, box, box, ground", deepest);
    Lab *twin = fixture_lab("twin.lua", "return {\n"
                                        "  camera = { position = {0, 6, 3}, target = {0, 0, 0}, width = 32, height = 24 },\n"
                                        "  lights = { { type = 'sphere', position = {0, 4, 0}, radius = 0.2 } },\n"
                                        "  objects = {\n"
                                        "    { name = 'ground', shape = 'plane', size = {8, 8} },\n"
                                        "    { name = 'a', shape = 'plane', size = {1, 1}, translate = {0, 2, 0} },\n"
                                        "    { name = 'b', shape = 'plane', size = {1, 1}, translate = {0, 1.99999, 0} },\n"
                                        "  },\n"
                                        "}\n");
    CHECK(twin);
    const ShadowMap *twins[PEELED_MAX_LAYERS] = {NULL};
    deepest = deepest_texel(twin, twins, &misordered);
    printf("    twin planes 1e-5 apart: deepest texel %d surfaces, %ld out of order\n", deepest, misordered);
    CHECK(misordered == 0);
    CHECK_MSG(deepest == 2, "planes within the peel epsilon count as %d surfaces with the ground", deepest);
    lab_close(twin);
    /* the peel test refuses a negative epsilon (raster.h) */
    RasterOptions bad = {.peel = layer[0]->depth, .peel_epsilon = -1.0f};
    Error err;
    DepthBuffer db;
    CHECK(depth_buffer_init(&db, 4, 4, false, &err));
    CHECK(!raster_depth(NULL, 0, &layer[0]->view.face[0].raster, &bad, &db, NULL, &err));
    CHECK(strstr(err.msg, "peel_epsilon") != NULL);
    depth_buffer_free(&db);
    lab_close(lab);
}

/* Does the render's resource scope hold a resource of this kind? */
static bool acquired(const RenderResult *r, const char *kind)
{
    for (int i = 0; i < r->num_tech_resources; i++)
        if (strcmp(r->tech_resources[i].kind, kind) == 0) return true;
    return false;
}

/* The strip scene: per texel the strip, then the ground under it, a
 * receiver that never blocks itself; layers 2 and 3 add only the ground and
 * empty texels, so each technique of the family, occluder and accumulation
 * gives the same image bit for bit, and layers=1 builds no peeled layer. */
TEST(test_peeled_layers_of_receivers_change_nothing)
{
    Lab *lab = soft_strip("{ type = 'sphere', position = {0, 4, 0}, radius = 0.5 }", 2.0);
    CHECK(lab);
    static const char *const runs[][3] = {
        {"backprojection", "occluder=microquad", "accumulate=bitmask"},
        {"backprojection", "occluder=micropatch", "accumulate=area"},
        {"backprojection", "occluder=contour", "accumulate=area"},
        {"backprojection", "occluder=contour", "accumulate=bitmask"},
        {"hsm", "occluder=microquad", "accumulate=area"},
        {"mssm", "occluder=micropatch", "accumulate=bitmask"},
        {"ysm", "occluder=contour", "accumulate=area"},
    };
    for (int k = 0; k < 7; k++) {
        const char *tech = runs[k][0];
        const char *one[] = {"map_size=128", runs[k][1], runs[k][2], "layers=1", NULL};
        const char *three[] = {"map_size=128", runs[k][1], runs[k][2], "layers=3", NULL};
        RenderResult a, b;
        CHECK(soft_render(lab, tech, one, &a) && soft_render(lab, tech, three, &b));
        CHECK(!acquired(&a, "peeled_layer") && acquired(&b, "peeled_layer"));
        size_t n = (size_t)a.visibility.width * a.visibility.height;
        long differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += memcmp(&a.visibility.data[i], &b.visibility.data[i], sizeof(float)) != 0;
        CHECK_MSG(differ == 0, "%s %s %s: layers 3 differs from 1 at %ld samples", tech, runs[k][1], runs[k][2],
                  differ);
        render_result_free(&a);
        render_result_free(&b);
    }
    lab_close(lab);
}

typedef struct LayerErrors { double penumbra_rmse, umbra_leak, penumbra_signed; } LayerErrors;

static LayerErrors layer_errors(Lab *lab, const char *tech, const char *const *params)
{
    RenderResult r;
    Metrics m;
    LayerErrors e = {NAN, NAN, NAN};
    if (!soft_render(lab, tech, params, &r)) return e;
    if (soft_metrics(lab, &r.visibility, 64, &m))
        e = (LayerErrors){m.region[REGION_PENUMBRA].rmse, m.region[REGION_UMBRA].leak_mean,
                          m.region[REGION_PENUMBRA].mean_signed};
    render_result_free(&r);
    return e;
}

/* Course Fig. 1.8: backprojection's bitmask with 1, 3, 4 and 8 layers
 * against the reference. On one-layer.lua the hidden box is the third
 * layer (slab top, slab bottom, box top): its umbra leak falls at 3, and
 * 4 (the course's count) is within 1% of 8; on overlap.lua the low
 * slab's penumbra under the high one falls with layers too. Summed areas
 * over-occlude more with layers (the penumbra's signed error falls). */
TEST(test_peeled_layers_recover_occluders_hidden_from_the_centre)
{
    static const char *const scenes[] = {"one-layer.lua", "overlap.lua"};
    static const int counts[] = {1, 3, 4, 8};
    for (int s = 0; s < 2; s++) {
        static const char *const view[] = {"camera.width=96", "camera.height=72", NULL};
        Lab *lab = soft_open(scenes[s], view);
        CHECK(lab);
        LayerErrors e[4];
        for (int k = 0; k < 4; k++) {
            char layers[16];
            snprintf(layers, sizeof layers, "layers=%d", counts[k]);
            const char *p[] = {"map_size=256", "tiles=4", layers, NULL};
            e[k] = layer_errors(lab, "backprojection", p);
            printf("    %-14s layers %d: penumbra RMSE %.4f signed %+.4f, umbra leak %.5f\n", scenes[s], counts[k],
                   e[k].penumbra_rmse, e[k].penumbra_signed, e[k].umbra_leak);
        }
        CHECK_MSG(e[2].umbra_leak < 0.5 * e[0].umbra_leak, "%s: umbra leak %.5f at 4 layers against %.5f at 1",
                  scenes[s], e[2].umbra_leak, e[0].umbra_leak);
        CHECK_MSG(e[2].penumbra_rmse < e[0].penumbra_rmse, "%s: penumbra RMSE %.4f at 4 layers against %.4f at 1",
                  scenes[s], e[2].penumbra_rmse, e[0].penumbra_rmse);
        CHECK(fabs(e[2].penumbra_rmse - e[3].penumbra_rmse) < 0.01 * e[3].penumbra_rmse);
        if (s == 0) {
            const char *area1[] = {"map_size=256", "tiles=4", "occluder=micropatch", "accumulate=area", "layers=1", NULL};
            const char *area4[] = {"map_size=256", "tiles=4", "occluder=micropatch", "accumulate=area", "layers=4", NULL};
            LayerErrors a1 = layer_errors(lab, "backprojection", area1), a4 = layer_errors(lab, "backprojection", area4);
            printf("    %-14s micropatch areas: penumbra signed %+.4f at 1 layer, %+.4f at 4\n", scenes[s],
                   a1.penumbra_signed, a4.penumbra_signed);
            CHECK(a4.penumbra_signed < a1.penumbra_signed);
        }
        lab_close(lab);
    }
}

/* ---- contour popping (course §5.2.3.3: "2D extraction misses occluders,
 * which causes popping") ---------------------------------------------------
 * A one-sided bar (a plane 0.2 x 0.4 at height 2) above a 1 x 1 slab (at 1,
 * its top at 1.02) under a sphere light at 4: seen from the light's centre
 * the bar lies inside the slab's outline until its +x edge reaches the
 * slab's. The contour of the blocking lexels is the union's outline, at the
 * depths of its boundary lexels only: the bar, nearer the light, is in it
 * only where it is on the boundary, so as the bar's edge crosses the
 * outline the image jumps. The bar moves in steps of a quarter texel (at
 * its depth) from 1 texel inside to 1 outside; per step the mean |dV| over
 * the samples lit-candidate in both frames, for the technique and for the
 * reference (144 stratified samples, the same light points every frame).
 * Every representation jumps where a lexel enters the mask (the lexel grid
 * is fixed); at the outline's change contour's jump is the largest, twice
 * microquad's at the same step and several times the reference's. 64 x 48
 * view, map 256^2, 4 layers so the slab under the bar is in the map. */
#define POP_STEPS 9

typedef struct PopFrame { Image v[2], ref; uint8_t *cls; } PopFrame;

static Lab *pop_scene(double bar_right)
{
    char text[1024];
    snprintf(text, sizeof text,
             "return {\n"
             "  camera = { position = {0.6, 0.9, 0}, target = {0.6, 0, 0}, up = {0, 0, -1}, fov = 60, width = 64, "
             "height = 48 },\n"
             "  lights = { { type = 'sphere', position = {0, 4, 0}, radius = 0.3 } },\n"
             "  objects = {\n"
             "    { name = 'ground', shape = 'plane', size = {8, 8} },\n"
             "    { name = 'slab', shape = 'box', size = {1, 0.04, 1}, translate = {0, 1, 0}, receiver = false },\n"
             "    { name = 'bar', shape = 'plane', size = {0.2, 0.4}, translate = {%.9g, 2, 0}, receiver = false },\n"
             "  },\n"
             "}\n",
             bar_right - 0.1);
    return fixture_lab("pop.lua", text);
}

static double mean_step(const Image *a, const Image *b, const uint8_t *ca, const uint8_t *cb)
{
    double sum = 0.0;
    long n = 0;
    for (long i = 0; i < (long)a->width * a->height; i++) {
        if (ca[i] != SAMPLE_LIT_CANDIDATE || cb[i] != SAMPLE_LIT_CANDIDATE) continue;
        sum += fabs(a->data[i] - b->data[i]);
        n++;
    }
    return n ? sum / n : NAN;
}

TEST(test_peeled_layers_contour_pops_where_the_outline_changes)
{
    static const char *const runs[2][5] = {
        {"map_size=256", "tiles=4", "occluder=contour", "accumulate=area", "layers=4"},
        {"map_size=256", "tiles=4", "occluder=microquad", "accumulate=bitmask", "layers=4"},
    };
    Lab *probe = pop_scene(0.0);
    CHECK(probe);
    double texel = soft_map_dx(probe, "backprojection", 256) * 2.0; /* world units at the bar's depth 2 */
    lab_close(probe);
    double edge = 0.5 * 2.0 / 3.0; /* the slab's +x edge (depth 3 from the light) seen at depth 2 */
    static PopFrame f[POP_STEPS];
    for (int s = 0; s < POP_STEPS; s++) {
        Lab *lab = pop_scene(edge + (s - (POP_STEPS - 1) / 2) * 0.25 * texel);
        CHECK(lab);
        Error err;
        for (int k = 0; k < 2; k++) {
            const char *p[6] = {runs[k][0], runs[k][1], runs[k][2], runs[k][3], runs[k][4], NULL};
            RenderResult r;
            CHECK(soft_render(lab, "backprojection", p, &r));
            f[s].v[k] = r.visibility;
            r.visibility = (Image){0};
            render_result_free(&r);
        }
        RefInfo info;
        RefRequest rq = {0, {MEASURE_VISIBILITY, 144, SAMPLING_STRATIFIED, 1, false}, NULL};
        const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
        const uint8_t *cls = ref ? res_classes(lab_resources(lab), lab_scene(lab), 0, &err) : NULL;
        CHECK_MSG(cls, "%s", err.msg);
        size_t n = (size_t)ref->value.width * ref->value.height;
        CHECK(image_init(&f[s].ref, ref->value.width, ref->value.height, 1, &err));
        memcpy(f[s].ref.data, ref->value.data, n * sizeof(float));
        f[s].cls = malloc(n);
        memcpy(f[s].cls, cls, n);
        lab_close(lab);
    }
    double max_step[3] = {0}, sum_step[3] = {0}, d[POP_STEPS][3];
    int pop = 0; /* the step of contour's largest change */
    for (int s = 0; s + 1 < POP_STEPS; s++) {
        for (int k = 0; k < 2; k++) d[s][k] = mean_step(&f[s].v[k], &f[s + 1].v[k], f[s].cls, f[s + 1].cls);
        d[s][2] = mean_step(&f[s].ref, &f[s + 1].ref, f[s].cls, f[s + 1].cls);
        printf("    step %d (%+.3f texels): contour %.5f, microquad %.5f, reference %.5f\n", s,
               (s - (POP_STEPS - 1) / 2 + 0.5) * 0.25, d[s][0], d[s][1], d[s][2]);
        for (int k = 0; k < 3; k++) {
            if (d[s][k] > max_step[k]) max_step[k] = d[s][k];
            sum_step[k] += d[s][k];
        }
        if (d[s][0] > d[pop][0]) pop = s;
    }
    static const char *const names[] = {"contour (4 layers)", "microquad (4 layers)", "reference"};
    for (int k = 0; k < 3; k++)
        printf("    %-22s largest step %.5f, mean step %.5f, largest / mean %.2f\n", names[k], max_step[k],
               sum_step[k] / (POP_STEPS - 1), max_step[k] / (sum_step[k] / (POP_STEPS - 1)));
    printf("    at step %d contour's change is %.2f x microquad's and %.2f x the reference's\n", pop,
           d[pop][0] / d[pop][1], d[pop][0] / d[pop][2]);
    CHECK_MSG(d[pop][0] > 1.5 * d[pop][1] && d[pop][0] > 4.0 * d[pop][2],
              "no contour pop: %.5f against microquad's %.5f and the reference's %.5f", d[pop][0], d[pop][1],
              d[pop][2]);
    for (int s = 0; s < POP_STEPS; s++) {
        for (int k = 0; k < 2; k++) image_free(&f[s].v[k]);
        image_free(&f[s].ref);
        free(f[s].cls);
    }
}
