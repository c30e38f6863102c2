/* test_exact_soft.c -- the exact soft-shadow methods against the Embree
 * reference with the reference's own light samples (same pattern, seed and
 * count): `depth_complexity` (Laine et al. 2005) and `view_sample_mapping`
 * (Eisemann & Décoret 2007; Sintorn et al. 2008) must match within 1/N
 * (view_sample_mapping: exactly, up to float rounding) per lit candidate
 * except where a light sample lies on a projected edge (aux near_edge > 0,
 * counted), on a sphere, a rect and a disk light, at 64x48 with 64 r2
 * samples. About 0.8 s. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "resources/standard.h"
#include "techniques/exact_soft.h"
#include "test.h"

#define EXACT_SAMPLES 64

/* A box on a plane under a disk light (the scenes hold spheres and rects). */
static const char disk_scene[] =
    "return { name = 'disk-box',\n"
    "  camera = { position = {0.8, 2.6, 4.6}, target = {0.3, 0.3, -0.2}, up = {0, 1, 0}, fov = 40, near = 0.05,\n"
    "             far = 100, width = 64, height = 48 },\n"
    "  lights = { { type = 'disk', position = {-2.0, 3.0, 1.0}, target = {0, 0, 0}, radius = 0.8,\n"
    "               color = {1, 1, 1}, intensity = 10 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {8, 8}, albedo = {0.8, 0.8, 0.8} },\n"
    "    { name = 'box', shape = 'box', size = {1, 1, 1}, rotate = {0, -25, 0}, translate = {0, 0.5, 0},\n"
    "      albedo = {0.7, 0.4, 0.3} } } }\n";

static Lab *open_small(const char *scene)
{
    if (!scene) return fixture_lab("disk-box.lua", disk_scene);
    const char *over[2] = {"camera.width=64", "camera.height=48"};
    char path[256];
    snprintf(path, sizeof path, "scenes/%s", scene);
    Error err;
    Lab *lab = lab_open(path, over, 2, &err);
    if (!lab) printf("    %s\n", err.msg);
    return lab;
}

typedef struct Match {
    long candidates, penumbra, differ, differ_near, near;
    double error; /* sum over lit candidates of |difference| (visibility) */
} Match;

/* `tech` with samples=EXACT_SAMPLES and the extra assignments `more`
 * (comma-separated, or NULL); *params: its parameters. */
static bool render_with(Lab *lab, const char *tech, const char *more, double *params, RenderResult *r)
{
    Error err;
    const Technique *t = tech_find(tech, &err);
    if (!t) return false;
    tech_params_default(t, params);
    char assign[64];
    snprintf(assign, sizeof assign, "samples=%d", EXACT_SAMPLES);
    if (!tech_param_parse(t, assign, params, &err)) { printf("    %s\n", err.msg); return false; }
    char list[128];
    snprintf(list, sizeof list, "%s", more ? more : "");
    for (char *a = strtok(list, ","); a; a = strtok(NULL, ","))
        if (!tech_param_parse(t, a, params, &err)) { printf("    %s\n", err.msg); return false; }
    RenderRequest rq = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    if (lab_render(lab, &rq, r, &err)) return true;
    printf("    %s: %s\n", tech, err.msg);
    return false;
}

/* `tech` at the reference's samples (render_with) against the reference,
 * sample by sample; a sample is near where near_edge (near, or NULL: the
 * render's own aux) is > 0. */
static bool match_reference_near(Lab *lab, const char *tech, const char *more, float tolerance, const Image *near,
                                 Match *m)
{
    Error err;
    double params[TECH_MAX_PARAMS];
    RenderResult r;
    if (!render_with(lab, tech, more, params, &r)) return false;
    RefRequest rr = {0, {MEASURE_VISIBILITY, EXACT_SAMPLES, SAMPLING_R2, 1, false}, NULL};
    rr.params.shared_set = params[EXACT_P_SAMPLE_SET] == EXACT_SET_SHARED; /* the technique's own sample set */
    RefInfo info;
    ResourceManager *rm = lab_resources(lab);
    const Reference *ref = res_reference(rm, lab_scene(lab), &rr, &info, &err);
    const uint8_t *cls = res_classes(rm, lab_scene(lab), 0, &err);
    const float *near_of = near ? near->data : r.aux.data;
    *m = (Match){0};
    for (long s = 0; ref && cls && s < (long)r.visibility.width * r.visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        float e = r.visibility.data[s], v = ref->value.data[s * ref->value.channels];
        bool is_near = near_of[s] > 0.0f, differ = !(fabsf(e - v) <= tolerance);
        m->candidates++;
        m->penumbra += v > 0.0f && v < 1.0f;
        m->near += is_near;
        m->differ += differ;
        m->differ_near += differ && is_near;
        m->error += fabsf(e - v);
    }
    render_result_free(&r);
    return ref && cls;
}

static bool match_reference_with(Lab *lab, const char *tech, const char *more, float tolerance, Match *m)
{
    return match_reference_near(lab, tech, more, tolerance, NULL, m);
}

static bool match_reference(Lab *lab, const char *tech, float tolerance, Match *m)
{
    return match_reference_with(lab, tech, NULL, tolerance, m);
}

/* tolerance: per lit candidate, 1/N for depth_complexity (the paper's
 * bound), float rounding of the same ratio for view_sample_mapping (its
 * bitmask is the reference's rays' answers). */
static void exact_on(const char *scene, const char *tech, float tolerance)
{
    Lab *lab = open_small(scene);
    CHECK(lab);
    Match m;
    CHECK(match_reference(lab, tech, tolerance, &m));
    printf("    %s on %s: %ld lit candidates (%ld in penumbra), %ld differ by more than %g (%ld of them with a light "
           "sample on a projected edge; %ld such samples)\n",
           tech, scene ? scene : "disk-box", m.candidates, m.penumbra, m.differ, (double)tolerance, m.differ_near, m.near);
    CHECK(m.candidates > 1000 && m.penumbra > 20);
    CHECK_MSG(m.differ == m.differ_near, "%ld samples differ with no light sample near a projected edge",
              m.differ - m.differ_near);
    CHECK(m.differ * 100 <= m.candidates);
    lab_close(lab);
}

TEST(test_exact_soft_depth_complexity_matches_the_reference_sphere) { exact_on("sphere-on-plane.lua", "depth_complexity", 1.0f / EXACT_SAMPLES * 1.001f); }
TEST(test_exact_soft_depth_complexity_matches_the_reference_rect) { exact_on("contact.lua", "depth_complexity", 1.0f / EXACT_SAMPLES * 1.001f); }
TEST(test_exact_soft_depth_complexity_matches_the_reference_disk) { exact_on(NULL, "depth_complexity", 1.0f / EXACT_SAMPLES * 1.001f); }
TEST(test_exact_soft_view_sample_mapping_matches_the_reference_sphere) { exact_on("sphere-on-plane.lua", "view_sample_mapping", 1e-6f); }
TEST(test_exact_soft_view_sample_mapping_matches_the_reference_rect) { exact_on("contact.lua", "view_sample_mapping", 1e-6f); }
TEST(test_exact_soft_view_sample_mapping_matches_the_reference_disk) { exact_on(NULL, "view_sample_mapping", 1e-6f); }

/* depth_complexity's silhouette sums (edges=silhouette: the visited
 * triangles' edges summed per caster edge, those that cancel left out)
 * against the brute force (edges=all: every edge stepping the counters):
 * the same visibility bit for bit, on a closed box, the contact scene's
 * clipped triangles and the sphere, at 64x48 with 64 samples. */
static bool render_dc(Lab *lab, const char *edges, RenderResult *r)
{
    Error err;
    const Technique *t = tech_find("depth_complexity", &err);
    double params[TECH_MAX_PARAMS];
    if (!t) return false;
    tech_params_default(t, params);
    char assign[64];
    snprintf(assign, sizeof assign, "edges=%s", edges);
    if (!tech_param_parse(t, assign, params, &err) || !tech_param_parse(t, "samples=64", params, &err)) {
        printf("    %s\n", err.msg);
        return false;
    }
    RenderRequest rq = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
    if (lab_render(lab, &rq, r, &err)) return true;
    printf("    %s\n", err.msg);
    return false;
}

static void silhouette_sums_on(const char *scene)
{
    Lab *lab = open_small(scene);
    CHECK(lab);
    RenderResult all, sil;
    CHECK(render_dc(lab, "all", &all));
    CHECK(render_dc(lab, "silhouette", &sil));
    long n = (long)all.visibility.width * all.visibility.height, differ = 0, shadowed = 0;
    for (long s = 0; s < n; s++) {
        float a = all.visibility.data[s], b = sil.visibility.data[s];
        differ += memcmp(&a, &b, sizeof a) != 0;
        shadowed += a < 1.0f;
    }
    printf("    %s: %ld of %ld samples differ between edges=all and edges=silhouette (%ld shadowed)\n",
           scene ? scene : "disk-box", differ, n, shadowed);
    CHECK(shadowed > 100);
    CHECK(differ == 0);
    render_result_free(&all);
    render_result_free(&sil);
    lab_close(lab);
}

/* Stage two's sphere tree over the light's possible silhouette edges
 * (exact_for_silhouette) against the brute force over every listed edge:
 * per lit candidate, the tree's items whose own sphere reaches the widened
 * samples' cone are, as a set, the listed edges whose sphere does, at 64x48
 * with 64 samples. */
typedef struct EdgeSet {
    const ExactEdges *edges;
    const LightPoints *lp;
    Cone cone;
    uint8_t *mark; /* per listed edge: 1 found by the tree */
    long visited;
} EdgeSet;

static bool mark_item(void *user, int e)
{
    EdgeSet *set = user;
    set->visited++;
    if (exact_ball_in_cone(&set->edges->edge_ball[e], &set->lp->f, &set->cone)) set->mark[e] = 1;
    return false;
}

static void edge_sets_on(const char *scene)
{
    Lab *lab = open_small(scene);
    CHECK(lab);
    Error err;
    const Technique *t = tech_find("depth_complexity", &err);
    double params[TECH_MAX_PARAMS];
    CHECK(t);
    tech_params_default(t, params);
    CHECK(tech_param_parse(t, "samples=64", params, &err));
    const Scene *sc = lab_scene(lab);
    ResourceManager *rm = lab_resources(lab);
    const ViewSamples *vs = res_view_samples(rm, sc, &err);
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, &err) : NULL;
    CHECK(cls);
    TechContext ctx = {sc, 0, &sc->lights[0], vs, cls, rm, params, 1, NULL};
    ExactCasters cs;
    CHECK(exact_casters_init(&ctx, true, &cs, &err));
    LightPoints *lp = malloc(sizeof *lp);
    EdgeSet set = {cs.edges, lp, {0, 0}, calloc((size_t)cs.edges->num_listed + 1, 1), 0};
    CHECK(lp && set.mark);
    long samples = 0, found = 0, differ = 0;
    for (int s = 0; s < vs->width * vs->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || !exact_begin(&cs, &ctx, s, lp)) continue;
        exact_draw(lp, &ctx, s);
        if (lp->kept == 0) continue;
        samples++;
        set.cone = exact_cone(lp->cos_cone, EXACT_EDGE_CONE_MARGIN);
        memset(set.mark, 0, (size_t)cs.edges->num_listed);
        ExactConeQuery q = {&lp->f, set.cone};
        exact_tree_query(&cs.edges->edge_tree, exact_cone_test, &q, mark_item, &set);
        for (int e = 0; e < cs.edges->num_listed; e++) {
            bool in = exact_ball_in_cone(&cs.edges->edge_ball[e], &lp->f, &set.cone);
            found += in;
            differ += in != set.mark[e];
        }
    }
    printf("    %s: %ld samples, %d listed edges of %d; %ld edges reach the cones, the tree visited %ld, %ld differ\n",
           scene ? scene : "disk-box", samples, cs.edges->num_listed, cs.edges->num_welded, found, set.visited, differ);
    CHECK(samples > 100 && found > samples);
    CHECK(differ == 0);
    free(set.mark);
    free(lp);
    exact_casters_free(&cs);
    lab_close(lab);
}

TEST(test_exact_soft_silhouette_edge_tree_matches_every_listed_edge)
{
    edge_sets_on("sphere-on-plane.lua");
    edge_sets_on("contact.lua");
}

TEST(test_exact_soft_depth_complexity_silhouette_sums_match_all_edges)
{
    silhouette_sums_on(NULL);
    silhouette_sums_on("contact.lua");
    silhouette_sums_on("sphere-on-plane.lua");
}

/* masks=hough (each edge's mask that of its line quantised to the nearest
 * bin of a hough_bins x hough_bins angle x offset table) against the
 * reference: the lit candidates that differ by more than float rounding fall
 * strictly as the table grows from 64 to 256 to 1024 bins per axis (163, 44,
 * 4 of 2081 today), at 1024 at most 1% of them, at 2^20 at most 0.1% (the
 * error vanishes with the bins); masks=exact (the default) matches bit for
 * bit up to samples on a projected edge (exact_on). The contact scene (rect
 * light) at 64x48 with 64 r2 samples, about 0.3 s. */
TEST(test_exact_soft_view_sample_mapping_hough_error_falls_with_bins)
{
    Lab *lab = open_small("contact.lua");
    CHECK(lab);
    const int bins[] = {64, 256, 1024, 1048576};
    long differ[4] = {0};
    Match m = {0}, exact;
    CHECK(match_reference_with(lab, "view_sample_mapping", "masks=exact", 1e-6f, &exact));
    for (int k = 0; k < 4; k++) {
        char more[64];
        snprintf(more, sizeof more, "masks=hough,hough_bins=%d", bins[k]);
        CHECK(match_reference_with(lab, "view_sample_mapping", more, 1e-6f, &m));
        differ[k] = m.differ;
        printf("    hough_bins=%d: %ld of %ld lit candidates differ from the reference (%ld in penumbra; "
               "masks=exact: %ld), summed |difference| x N %.1f\n",
               bins[k], m.differ, m.candidates, m.penumbra, exact.differ, m.error * EXACT_SAMPLES);
    }
    CHECK(m.candidates > 1000 && m.penumbra > 100);
    CHECK(differ[0] > differ[1] && differ[1] > differ[2] && differ[2] >= differ[3]);
    CHECK(differ[2] * 100 <= m.candidates);
    CHECK(differ[3] * 1000 <= m.candidates);
    CHECK(exact.differ == exact.differ_near);
    lab_close(lab);
}

/* sample_set=shared: one light-sample set for the frame (the reference's
 * --sample-set shared), so masks=hough reads the papers' one stored table
 * (angle x offset bins over the light's plane). masks=exact matches the
 * shared reference up to samples on a projected edge, as with per-view-sample
 * sets (exact_on); the stored table's lit candidates that differ from the
 * reference fall with the bins (64, 256, 1024, 2^16: 129, 74, 10, 1 of 2081
 * today) and at 2^16 each that differs has a light sample within
 * EXACT_AMBIGUOUS_TAN of a projected edge (masks=exact's near_edge; today's
 * one, 3e-6 from it, still differs at 2^18: the angle bins' error pi / bins
 * |a| is not yet below its distance). The contact scene (rect light) at 64x48
 * with 64 r2 samples, about 1.5 s. */
TEST(test_exact_soft_view_sample_mapping_shared_table_matches_the_shared_reference)
{
    Lab *lab = open_small("contact.lua");
    CHECK(lab);
    Match exact;
    double params[TECH_MAX_PARAMS];
    RenderResult near;
    CHECK(render_with(lab, "view_sample_mapping", "sample_set=shared", params, &near));
    CHECK(match_reference_with(lab, "view_sample_mapping", "sample_set=shared", 1e-6f, &exact));
    printf("    sample_set=shared, masks=exact: %ld of %ld lit candidates differ from the shared reference (%ld with a "
           "light sample on a projected edge; %ld in penumbra)\n", exact.differ, exact.candidates, exact.differ_near,
           exact.penumbra);
    CHECK(exact.candidates > 1000 && exact.penumbra > 100);
    CHECK(exact.differ == exact.differ_near);
    const int bins[] = {64, 256, 1024, 65536};
    Match m[4];
    for (int k = 0; k < 4; k++) {
        char more[96];
        snprintf(more, sizeof more, "sample_set=shared,masks=hough,hough_bins=%d", bins[k]);
        CHECK(match_reference_near(lab, "view_sample_mapping", more, 1e-6f, &near.aux, &m[k]));
        printf("    stored table, hough_bins=%d: %ld of %ld lit candidates differ from the shared reference (%ld with "
               "a light sample on a projected edge), summed |difference| x N %.1f\n",
               bins[k], m[k].differ, m[k].candidates, m[k].differ_near, m[k].error * EXACT_SAMPLES);
    }
    CHECK(m[0].differ > m[1].differ && m[1].differ > m[2].differ && m[2].differ >= m[3].differ);
    CHECK(m[3].differ == m[3].differ_near);
    CHECK(m[3].differ * 1000 <= m[3].candidates);
    render_result_free(&near);
    lab_close(lab);
}

/* Coloured lights (seed 001's textured rect: three discs, red, green and
 * blue, on black): each light sample weighs by its texel's colour, the
 * reference's ratio (light_bitmask_visibility), so with the reference's
 * samples `tech` matches the RGB reference per channel to its grey bound
 * (exact_on) except where a light sample lies on a projected edge. The
 * textured-light scene at 64x48 with 64 r2 samples, about 0.5 s each. */
static void rgb_on(const char *tech, float tolerance)
{
    Lab *lab = open_small("textured-light.lua");
    CHECK(lab);
    double params[TECH_MAX_PARAMS];
    RenderResult r;
    Error err;
    CHECK(render_with(lab, tech, NULL, params, &r));
    RefRequest rr = {0, {MEASURE_VISIBILITY, EXACT_SAMPLES, SAMPLING_R2, 1, false}, NULL};
    RefInfo info;
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rr, &info, &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    CHECK(ref && cls && ref->value.channels == 3 && r.visibility.channels == 3);
    long candidates = 0, coloured = 0, differ = 0, differ_near = 0;
    for (long s = 0; ref && cls && s < (long)r.visibility.width * r.visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        const float *e = &r.visibility.data[s * 3], *v = &ref->value.data[s * 3];
        bool d = false;
        for (int c = 0; c < 3; c++) d |= !(fabsf(e[c] - v[c]) <= tolerance);
        candidates++;
        coloured += fabsf(v[0] - v[2]) > 0.05f; /* the red and blue discs' shadows apart */
        differ += d;
        differ_near += d && r.aux.data[s] > 0.0f;
    }
    printf("    %s on textured-light: %ld lit candidates (%ld with red and blue visibility apart), %ld differ in some "
           "channel by more than %g (%ld of them with a light sample on a projected edge)\n",
           tech, candidates, coloured, differ, (double)tolerance, differ_near);
    CHECK(candidates > 1000 && coloured > 50);
    CHECK_MSG(differ == differ_near, "%ld samples differ with no light sample near a projected edge",
              differ - differ_near);
    CHECK(differ * 100 <= candidates);
    render_result_free(&r);
    lab_close(lab);
}

TEST(test_exact_soft_view_sample_mapping_matches_the_rgb_reference) { rgb_on("view_sample_mapping", 1e-6f); }
TEST(test_exact_soft_depth_complexity_matches_the_rgb_reference)
{
    rgb_on("depth_complexity", 1.0f / EXACT_SAMPLES * 1.001f);
}

/* The stored table's refusals, by name: a sphere light (its samples are
 * directions from each view sample, not points of the light) and a table
 * over its memory bound (2^20 bins at 1024 samples: 137 GB). */
TEST(test_exact_soft_view_sample_mapping_shared_table_refusals)
{
    const char *cases[][2] = {{"sphere-on-plane.lua", "sample_set=shared,masks=hough"},
                              {"contact.lua", "sample_set=shared,masks=hough,hough_bins=1048576,samples=1024"}};
    const char *names[] = {"sphere light", "hough_bins=1048576"};
    for (int k = 0; k < 2; k++) {
        Lab *lab = open_small(cases[k][0]);
        CHECK(lab);
        Error err;
        const Technique *t = tech_find("view_sample_mapping", &err);
        double params[TECH_MAX_PARAMS];
        tech_params_default(t, params);
        char list[128];
        snprintf(list, sizeof list, "%s", cases[k][1]);
        for (char *a = strtok(list, ","); a; a = strtok(NULL, ",")) CHECK(tech_param_parse(t, a, params, &err));
        RenderRequest rq = {.tech = t, .params = params, .light_index = 0, .repeat = 1};
        RenderResult r;
        bool ok = lab_render(lab, &rq, &r, &err);
        if (ok) render_result_free(&r);
        else printf("    %s: %s\n", names[k], err.msg);
        CHECK(!ok && strstr(err.msg, k == 0 ? "sample_set=shared" : "hough_bins=1048576"));
        lab_close(lab);
    }
}
