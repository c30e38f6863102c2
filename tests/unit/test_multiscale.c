/* test_multiscale.c -- the multiscale backprojection variants `hsm`, `mssm`
 * and `ysm` (course §5.2.3.4-5): the MSSM's levels give exact bounds over
 * any window and their minimum's texel; each variant against the Embree
 * reference on sphere-on-plane; the early outs against full backprojection
 * (early_out=none), counted; the share of receivers needing backprojection
 * (course Fig. 5.10: MSSM classifies at least as many by early out as HSM)
 * on spheres.lua and, where the model is found, the bunny; the bad input of
 * issue 15 (lowest budget, a light wider than the map's view, receivers at
 * the light's depth, a 1^2 map, MSSM maps above 1024^2). 160 x 120 or
 * smaller, 64 reference samples. */
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "resources/maps/prefilter.h"
#include "resources/standard.h"
#include "soft_helpers.h"
#include "techniques/smap.h"
#include "test.h"

static const char *const variants[] = {"hsm", "mssm", "ysm"};
#define NUM_VARIANTS 3
enum { CLASS_LIT, CLASS_UMBRA, CLASS_BACKPROJECTED }; /* aux `class` (backprojection.c) */

/* minmax_levels_query against the brute-force bounds of the texels under
 * the base-level nodes of a window, and minmax_levels_min's node against
 * the window's minimum, on spheres.lua's 64^2 map (its ground slopes in
 * the light's depth; base 0 and 2). */
TEST(test_multiscale_levels_are_exact_bounds)
{
    Lab *lab = soft_open("spheres.lua", NULL);
    CHECK(lab);
    Error err;
    const Technique *t = tech_find("mssm", &err);
    CHECK(t);
    double p[TECH_MAX_PARAMS];
    tech_params_default(t, p);
    p[SMAP_P_MAP_SIZE] = 64;
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *map = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    const MinMaxPyramid *pyr = map ? res_minmax_pyramid(lab_resources(lab), map, &err) : NULL;
    CHECK(pyr);
    int face = 0, best = -1; /* the face with the most casters (a sphere light's cube map: the one below) */
    for (int f = 0; f < map->num_faces; f++) {
        int drawn = 0;
        for (int q = 0; q < map->res * map->res; q++) drawn += isfinite(shadowmap_texel(map, f, q % map->res, q / map->res));
        if (drawn > best) best = drawn, face = f;
    }
    uint32_t seed = 12345u;
    for (int base = 0; base <= 2; base += 2) {
        const MinMaxLevels *m = res_minmax_levels(lab_resources(lab), pyr, base, &err);
        CHECK_MSG(m, "%s", err.msg);
        CHECK(m->res == 64 >> base && (1 << (m->levels - 1)) >= m->res);
        int windows = 0, nodes_ok = 0, tighter = 0;
        for (int trial = 0; trial < 400; trial++) {
            /* small windows (1 to 12 nodes a side) keep the bounds local: a wide one holds the map's
             * extremes (the ball's top, the empty texels) whatever the query reads */
            uint32_t r[4];
            for (int k = 0; k < 4; k++) r[k] = (seed = seed * 1664525u + 1013904223u) >> 8;
            int x0 = (int)(r[0] % (uint32_t)m->res), y0 = (int)(r[1] % (uint32_t)m->res);
            int x1 = x0 + (int)(r[2] % 12u), y1 = y0 + (int)(r[3] % 12u);
            x1 = x1 < m->res ? x1 : m->res - 1;
            y1 = y1 < m->res ? y1 : m->res - 1;
            float lo = INFINITY, hi = -INFINITY;
            for (int j = y0 << base; j < (y1 + 1) << base; j++)
                for (int i = x0 << base; i < (x1 + 1) << base; i++) {
                    float z = shadowmap_texel(map, face, i, j);
                    lo = z < lo ? z : lo;
                    hi = z > hi ? z : hi;
                }
            float qlo, qhi;
            minmax_levels_query(m, face, x0, y0, x1, y1, &qlo, &qhi);
            CHECK_MSG(qlo == lo && qhi == hi, "base %d, nodes [%d, %d] x [%d, %d]: bounds (%g, %g), brute force (%g, %g)",
                      base, x0, x1, y0, y1, qlo, qhi, lo, hi);
            windows++;
            float plo, phi; /* the pyramid's 2 x 2 nodes over the same texels, for scale */
            minmax_query(pyr, face, x0 << base, y0 << base, ((x1 + 1) << base) - 1, ((y1 + 1) << base) - 1, &plo, &phi);
            tighter += plo < lo || phi > hi;
            /* a window of level k at (x0, y0), inside the face: its minimum and the node holding it */
            int k = 0;
            while (k + 1 < m->levels && (x0 + (2 << k) <= m->res) && (y0 + (2 << k) <= m->res)) k++;
            int ni = x0, nj = y0;
            float wmin = minmax_levels_min(m, face, k, &ni, &nj), blo, bhi;
            minmax_levels_query(m, face, x0, y0, x0 + (1 << k) - 1, y0 + (1 << k) - 1, &blo, &bhi);
            int ti = ni, tj = nj;
            float node = minmax_node_min(pyr, face, base, &ti, &tj);
            CHECK_MSG(wmin == blo && node == wmin && ni >= x0 && ni < x0 + (1 << k) && nj >= y0 && nj < y0 + (1 << k),
                      "base %d level %d at (%d, %d): min %g at node (%d, %d) holding %g, window min %g", base, k, x0,
                      y0, wmin, ni, nj, node, blo);
            nodes_ok++;
        }
        printf("    face %d, base %d: %d levels of %d^2 nodes, %d random windows exact (the pyramid's bounds looser in %d), %d "
               "minima found at their node\n",
               face, base, m->levels, m->res, windows, tighter, nodes_ok);
            CHECK(tighter > windows / 10); /* the windows test something the pyramid does not give */
    }
    lab_close(lab);
}

/* Lit candidates per class of aux `class` (channel 0 of 2). */
static void class_counts(Lab *lab, const RenderResult *r, long counts[3])
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    counts[0] = counts[1] = counts[2] = 0;
    for (long s = 0; cls && s < (long)r->visibility.width * r->visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        int c = (int)r->aux.data[(size_t)s * r->aux.channels];
        if (c >= 0 && c < 3) counts[c]++;
    }
}

/* Each variant at its defaults (1024^2 cube map, budget 32, microquads,
 * 256-sample bitmask; mssm's levels take 528 MiB) against a 64-sample stratified reference on sphere-on-plane,
 * 160 x 120. Measured: penumbra RMSE 0.0581 (hsm), 0.0571 (mssm), 0.0573
 * (ysm), against the reference's own noise 0.042; umbra leak <= 0.0020;
 * all-sample RMSE 0.0130. The bounds leave ~20% (penumbra 0.07, all 0.016)
 * for other machines' rounding; every value is finite. */
TEST(test_multiscale_against_the_reference_on_sphere_on_plane)
{
    Lab *lab = soft_open("sphere-on-plane.lua", NULL);
    CHECK(lab);
    for (int v = 0; v < NUM_VARIANTS; v++) {
        RenderResult r;
        Metrics m;
        const char *none[] = {NULL};
        CHECK(soft_render(lab, variants[v], none, &r));
        CHECK(soft_metrics(lab, &r.visibility, 64, &m));
        long counts[3];
        class_counts(lab, &r, counts);
        const ErrorStats *pe = &m.region[REGION_PENUMBRA], *um = &m.region[REGION_UMBRA], *all = &m.region[REGION_ALL];
        printf("    %-4s all RMSE %.4f, penumbra RMSE %.4f (signed %+.4f, noise %.4f), umbra leak %.4f; classes lit "
               "%ld, umbra %ld, backprojected %ld\n",
               variants[v], all->rmse, pe->rmse, pe->mean_signed, pe->noise_rms, um->leak_mean, counts[0], counts[1],
               counts[2]);
        CHECK(all->nonfinite == 0);
        CHECK_MSG(pe->count > 150 && pe->rmse <= 0.07, "%s: penumbra RMSE %.4f above 0.07", variants[v], pe->rmse);
        CHECK_MSG(um->leak_mean <= 0.005, "%s: umbra leak %.4f above 0.005", variants[v], um->leak_mean);
        CHECK_MSG(all->rmse <= 0.016, "%s: RMSE %.4f above 0.016", variants[v], all->rmse);
        CHECK(counts[0] > 0 && counts[1] > 0 && counts[2] > 0);
        render_result_free(&r);
    }
    lab_close(lab);
}

/* The early outs against full backprojection (early_out=none), sample by
 * sample: a lit early out never changes the result (exact: z_p <= z_min
 * leaves no occluder, V = 1 either way); an umbra early out (V = 0) may
 * differ where the backprojected occluders leave light samples uncovered
 * at the search area's rim. Tolerance: the umbra early outs' results
 * differ from full backprojection in at most 2% of those receivers, by at
 * most 8 of the 256 light samples. Measured on sphere-on-plane and
 * spheres.lua (160 x 120, map 512): 0 of 43 to 213 umbra early outs
 * differ, for every variant (the microquads over an all-occluding area
 * cover every light sample). */
TEST(test_multiscale_early_outs_match_full_backprojection)
{
    static const char *const scenes[] = {"sphere-on-plane.lua", "spheres.lua"};
    for (int sc = 0; sc < 2; sc++) {
        Lab *lab = soft_open(scenes[sc], NULL);
        CHECK(lab);
        Error err;
        const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
        CHECK(cls);
        for (int v = 0; v < NUM_VARIANTS; v++) {
            const char *fast[] = {"map_size=512", NULL}, *full[] = {"map_size=512", "early_out=none", NULL};
            RenderResult a, b;
            CHECK(soft_render(lab, variants[v], fast, &a));
            CHECK(soft_render(lab, variants[v], full, &b));
            long n[3] = {0}, differ[3] = {0}, backprojected = 0;
            double worst[3] = {0};
            for (long s = 0; s < (long)a.visibility.width * a.visibility.height; s++) {
                if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
                int c = (int)a.aux.data[(size_t)s * 2];
                backprojected += (int)b.aux.data[(size_t)s * 2] == CLASS_BACKPROJECTED;
                double d = fabs((double)a.visibility.data[s] - b.visibility.data[s]);
                n[c]++;
                differ[c] += d > 0.0;
                worst[c] = fmax(worst[c], d);
            }
            printf("    %s %-4s early outs: lit %ld (%ld differ, max %.4f), umbra %ld (%ld differ, max %.4f); "
                   "early_out=none backprojects %ld\n",
                   scenes[sc], variants[v], n[CLASS_LIT], differ[CLASS_LIT], worst[CLASS_LIT], n[CLASS_UMBRA],
                   differ[CLASS_UMBRA], worst[CLASS_UMBRA], backprojected);
            CHECK_MSG(differ[CLASS_LIT] == 0, "%s: %ld lit early outs differ from full backprojection", variants[v],
                      differ[CLASS_LIT]);
            CHECK(differ[CLASS_BACKPROJECTED] == 0); /* the same loop, the same window */
            CHECK_MSG(differ[CLASS_UMBRA] <= n[CLASS_UMBRA] / 50 && worst[CLASS_UMBRA] <= 8.0 / 256.0 + 1e-6,
                      "%s: %ld of %ld umbra early outs differ, by up to %.4f", variants[v], differ[CLASS_UMBRA],
                      n[CLASS_UMBRA], worst[CLASS_UMBRA]);
            CHECK(backprojected == n[0] + n[1] + n[2]); /* none: every receiver backprojected */
            render_result_free(&a);
            render_result_free(&b);
        }
        lab_close(lab);
    }
}

/* Course Fig. 5.10: the share of receivers needing backprojection. MSSM's
 * exact window bounds (and YSM's, above its HSM levels) are never looser
 * than HSM's 2 x 2 nodes, so they classify at least as many receivers by
 * early out; measured on spheres.lua (procedural, the default) and the
 * bunny when SHADOWLAB_MODEL_PATH holds it (160 x 120, map 512). */
static void classification_shares(Lab *lab, const char *name)
{
    long early[NUM_VARIANTS], total = 0;
    for (int v = 0; v < NUM_VARIANTS; v++) {
        const char *p[] = {"map_size=512", NULL};
        RenderResult r;
        CHECK(soft_render(lab, variants[v], p, &r));
        long c[3];
        class_counts(lab, &r, c);
        total = c[0] + c[1] + c[2];
        early[v] = c[0] + c[1];
        printf("    %s %-4s: %ld receivers, lit early out %ld, umbra early out %ld, backprojected %ld (%.1f%%)\n", name,
               variants[v], total, c[0], c[1], c[2], 100.0 * c[2] / total);
        render_result_free(&r);
    }
    CHECK(total > 1000);
    CHECK_MSG(early[1] >= early[0] && early[2] >= early[0], "%s: early outs mssm %ld, ysm %ld below hsm's %ld", name,
              early[1], early[2], early[0]);
    CHECK_MSG(early[1] >= early[2], "%s: mssm's early outs %ld below ysm's %ld", name, early[1], early[2]);
}

TEST(test_multiscale_mssm_classifies_at_least_as_many_as_hsm)
{
    Lab *lab = soft_open("spheres.lua", NULL);
    CHECK(lab);
    classification_shares(lab, "spheres.lua");
    lab_close(lab);
    const char *dir = getenv("SHADOWLAB_MODEL_PATH");
    char path[1024];
    snprintf(path, sizeof path, "%s/stanford-bunny.obj", dir ? dir : "");
    FILE *f = dir ? fopen(path, "rb") : NULL;
    if (!f) {
        printf("    note: SHADOWLAB_MODEL_PATH unset or no stanford-bunny.obj there; the bunny skipped\n");
        return;
    }
    fclose(f);
    lab = soft_open("bunny.lua", NULL);
    CHECK(lab);
    classification_shares(lab, "bunny.lua");
    lab_close(lab);
}

/* Every lit candidate's value finite and in [0, 1]. */
static long out_of_range(Lab *lab, const RenderResult *r)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    long bad = 0;
    for (long s = 0; s < (long)r->visibility.width * r->visibility.height; s++)
        bad += (!cls || cls[s] == SAMPLE_LIT_CANDIDATE) && !(r->visibility.data[s] >= 0.0f && r->visibility.data[s] <= 1.0f);
    return bad;
}

/* Issue 15's bad input: the lowest budget (2), a light wider than the
 * map's field of view (a sphere of radius 3 at height 4 over
 * sphere-on-plane's ball), receivers at the light's depth (a wall through
 * the light's plane): finite and in [0, 1], with and without blending;
 * a 1^2 map at every variant's defaults renders. MSSM maps above 1024^2
 * and YSM levels that leave one are refused, naming the parameter and its
 * range. */
TEST(test_multiscale_bad_input_stays_finite_or_is_refused)
{
    static const char *const wall_scene =
        "return {\n"
        "  camera = { position = {3, 3, 5}, target = {0, 1.5, 0}, fov = 60, width = 64, height = 48 },\n"
        "  lights = { { type = 'sphere', position = {0, 2, 0}, radius = 0.3 } },\n"
        "  objects = {\n"
        "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
        "    { name = 'wall', shape = 'box', size = {0.2, 4, 3}, translate = {1, 2, 0} },\n"
        "    { name = 'block', shape = 'box', size = {0.5, 0.5, 0.5}, translate = {0, 0.8, 0.6} },\n"
        "  },\n"
        "}\n";
    const char *huge[] = {"lights[1].radius=3", "camera.width=80", "camera.height=60", NULL};
    Lab *labs[3] = {soft_open("sphere-on-plane.lua", huge), fixture_lab("wall.lua", wall_scene),
                    soft_open("sphere-on-plane.lua", NULL)};
    static const char *const names[] = {"light radius 3", "receivers at the light's depth", "budget 2"};
    for (int k = 0; k < 3; k++) {
        CHECK(labs[k]);
        for (int v = 0; v < NUM_VARIANTS; v++)
            for (int blend = 0; blend < 2; blend++) {
                const char *p[] = {"map_size=256", k == 2 ? "budget=2" : "budget=32", blend ? "blend=true" : "blend=false",
                                   NULL};
                RenderResult r;
                CHECK(soft_render(labs[k], variants[v], p, &r));
                long bad = out_of_range(labs[k], &r);
                CHECK_MSG(bad == 0, "%s, %s, blend %d: %ld samples non-finite or outside [0, 1]", names[k],
                          variants[v], blend, bad);
                render_result_free(&r);
            }
        printf("    %s: hsm, mssm, ysm (blend off and on) finite, in [0, 1]\n", names[k]);
    }
    /* the smallest map, every variant at its defaults (ysm's hsm_levels 3 beyond a 1^2 map's one level) */
    for (int v = 0; v < NUM_VARIANTS; v++) {
        const char *p[] = {"map_size=1", NULL};
        RenderResult r;
        CHECK(soft_render(labs[2], variants[v], p, &r));
        CHECK_MSG(out_of_range(labs[2], &r) == 0, "%s, map_size 1: values outside [0, 1]", variants[v]);
        render_result_free(&r);
    }
    /* refusals: mssm above 1024^2, ysm's MSSM level above it */
    static const struct { const char *tech, *p[3], *want; } refuse[] = {
        {"mssm", {"map_size=2048", NULL}, "map_size range [1, 1024]"},
        {"ysm", {"map_size=2048", "hsm_levels=1", NULL}, "range [2, 12]"},
    };
    for (int k = 0; k < 2; k++) {
        Error err;
        const Technique *t = tech_find(refuse[k].tech, &err);
        double values[TECH_MAX_PARAMS];
        CHECK(t);
        tech_params_default(t, values);
        for (int i = 0; refuse[k].p[i]; i++) CHECK(tech_param_parse(t, refuse[k].p[i], values, &err));
        RenderRequest rq = {.tech = t, .params = values, .light_index = 0, .repeat = 1};
        RenderResult r;
        bool ok = lab_render(labs[2], &rq, &r, &err);
        if (ok) render_result_free(&r);
        printf("    %s %s %s: %s\n", refuse[k].tech, refuse[k].p[0], refuse[k].p[1] ? refuse[k].p[1] : "",
               ok ? "accepted" : err.msg);
        CHECK_MSG(!ok && strstr(err.msg, refuse[k].tech) && strstr(err.msg, refuse[k].want), "%s: '%s' lacks '%s'",
                  refuse[k].tech, ok ? "(accepted)" : err.msg, refuse[k].want);
    }
    for (int k = 0; k < 3; k++) lab_close(labs[k]);
}
