/* test_counters.c -- the work counters (core/counters.h, issue 17) against
 * counts known by hand on small scenes: a K x K box PCF reads K^2 depth
 * texels per lit candidate (every sample of sphere-on-plane lies inside its
 * scene-fitted cube map, so no early-out applies), `hard` traces one ray per
 * lit candidate, the reference N rays per sample whose light lies wholly
 * above its tangent plane, and a depth map of one axis-aligned quad writes
 * exactly the texels whose centres it covers. Then the whole registry: every
 * technique's record has a `work` block, and every technique counts the work
 * of its kind (those that acquire a shadow map fetch texels and render or
 * ray cast the map, the ray-traced family traces rays, the geometry family
 * sets up triangles, and every frame counts some work). 48 x 36 samples,
 * 128^2 maps, one thread: about 2 s on a loaded 2-core machine. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "filtered_fixtures.h"
#include "fixtures.h"
#include "lab/report.h"
#include "raster/raster.h"
#include "resources/standard.h"
#include "rt/reference.h"
#include "techniques/smap.h"
#include "test.h"

#define COUNT_W 48
#define COUNT_H 36

/* Lit candidates of a render, counted from the classes themselves. */
static long lit_candidates(Lab *lab)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    long n = 0;
    for (long s = 0; cls && vs && s < (long)vs->width * vs->height; s++) n += cls[s] == SAMPLE_LIT_CANDIDATE;
    return n;
}

TEST(test_counters_pcf_box_reads_k_squared_texels_per_lit_candidate)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", COUNT_W, COUNT_H);
    CHECK(lab);
    long lit = lit_candidates(lab);
    CHECK(lit > 0);
    static const char *const settings[] = {"K=1 map_size=128", "K=3 map_size=128", "K=7 map_size=128",
                                           "K=7 map_size=128 receiver_plane=true"};
    static const int K[] = {1, 3, 7, 7};
    for (int i = 0; i < 4; i++) {
        RenderResult r;
        CHECK(filtered_render(lab, "pcf", settings[i], &r));
        uint64_t want = (uint64_t)K[i] * (uint64_t)K[i] * (uint64_t)lit;
        bool ok = r.lit_candidates == lit && r.eval_work.texel_fetches == want &&
                  r.eval_work.texel_bytes == 4 * want && r.eval_work.rays == 0;
        printf("    pcf %s: %llu texel fetches, %ld lit candidates x K^2 = %llu\n", settings[i],
               (unsigned long long)r.eval_work.texel_fetches, lit, (unsigned long long)want);
        render_result_free(&r);
        CHECK_MSG(ok, "pcf %s: counted %s", settings[i], "other than K^2 float32 texels per lit candidate");
    }
    lab_close(lab);
}

TEST(test_counters_hard_traces_one_ray_per_lit_candidate)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", COUNT_W, COUNT_H);
    CHECK(lab);
    RenderResult r;
    CHECK(filtered_render(lab, "hard", NULL, &r));
    long lit = lit_candidates(lab);
    bool ok = lit > 0 && r.eval_work.rays == (uint64_t)lit && r.eval_work.ray_calls == (uint64_t)lit &&
              r.eval_work.texel_fetches == 0 && r.frame_work.triangles == 0;
    printf("    hard: %llu rays in %llu calls, %ld lit candidates\n", (unsigned long long)r.eval_work.rays,
           (unsigned long long)r.eval_work.ray_calls, lit);
    render_result_free(&r);
    lab_close(lab);
    CHECK(ok);
}

/* An overhead sphere light above a plane that every sample lies on (the
 * occluder receives nothing): no light sample is below a tangent plane, so
 * the reference traces exactly N rays per lit candidate, 16 to a call: N =
 * 40 is two full packets and one of 8 lanes. */
static const char *const overhead_scene =
    "return { name = 'overhead', camera = { position = {0, 6, 0.01}, target = {0, 0, 0}, up = {0, 1, 0},\n"
    "  fov = 40, width = 24, height = 18 },\n"
    "  lights = { { type = 'sphere', position = {0, 8, 0}, radius = 0.5, intensity = 10 } },\n"
    "  objects = { { name = 'ground', shape = 'plane', size = {20, 20} },\n"
    "    { name = 'blocker', shape = 'box', size = {1, 0.2, 1}, translate = {0.3, 2, 0}, receiver = false } } }\n";

TEST(test_counters_reference_traces_n_rays_per_sample)
{
    Lab *lab = fixture_lab("overhead.lua", overhead_scene);
    CHECK(lab);
    Error err;
    ResourceManager *rm = lab_resources(lab);
    const Scene *sc = lab_scene(lab);
    const ViewSamples *vs = res_view_samples(rm, sc, &err);
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, &err) : NULL;
    const RtScene *casters = res_bvh(rm, sc, RT_CASTERS, &err);
    CHECK(vs && cls && casters);
    long lit = lit_candidates(lab), not_receiver = 0;
    for (long s = 0; s < (long)vs->width * vs->height; s++) not_receiver += cls[s] == SAMPLE_NOT_RECEIVER;
    ReferenceParams p = {MEASURE_VISIBILITY, 40, SAMPLING_R2, 1, false};
    Reference ref;
    WorkCounters w0, w1;
    work_snapshot(&w0);
    CHECK(reference_compute(casters, sc, 0, vs, cls, &p, &ref, &err));
    work_snapshot(&w1);
    WorkCounters w = work_diff(&w1, &w0);
    bool penumbra = false;
    for (long s = 0; s < (long)vs->width * vs->height; s++)
        penumbra = penumbra || (cls[s] == SAMPLE_LIT_CANDIDATE && ref.value.data[s] > 0.0f && ref.value.data[s] < 1.0f);
    reference_free(&ref);
    lab_close(lab);
    printf("    reference: %llu rays in %llu calls, %ld lit candidates x 40 (%ld on the blocker, untraced)\n",
           (unsigned long long)w.rays, (unsigned long long)w.ray_calls, lit, not_receiver);
    CHECK(lit > 0 && not_receiver > 0 && penumbra); /* the scene is what the count assumes */
    CHECK(w.rays == 40 * (uint64_t)lit && (long long)w.rays == ref.rays);
    CHECK(w.ray_calls == 3 * (uint64_t)lit);
}

/* One quad over x in [-0.5, 0.5], z in [-0.25, 0.5] under an orthographic
 * view of [-1, 1]^2 onto 64 x 64 texels: its edges lie on texel edges
 * (texel width 1/32), so it covers columns 16..47 and 24 rows, 768 texels,
 * whatever the edge rule; two triangles set up. */
TEST(test_counters_quad_depth_map_writes_its_texels)
{
    vec3 p[4] = {v3(-0.5f, 0, -0.25f), v3(0.5f, 0, -0.25f), v3(-0.5f, 0, 0.5f), v3(0.5f, 0, 0.5f)};
    uint32_t ix[6] = {0, 2, 1, 1, 2, 3};
    RasterMesh quad = {p, ix, 4, 2};
    RasterView v = {.mapping = RASTER_PROJECTIVE, .depth_near = 0.0, .depth_far = 20.0};
    mat4 view = m4_look(d3(0, 10, 0), d3(0, -1, 0), d3(0, 0, -1));
    mat4 proj = m4_ortho(-1, 1, -1, 1, 0.0, 20.0);
    v.clip_from_world = m4_mul(&proj, &view);
    double row[4] = {0, -1, 0, 10};
    memcpy(v.depth_row, row, sizeof row);
    DepthBuffer db;
    Error err;
    CHECK(depth_buffer_init(&db, 64, 64, false, &err));
    RasterOptions opt = {.cull = RASTER_CULL_NONE};
    WorkCounters w0, w1;
    work_snapshot(&w0);
    bool ok = raster_depth(&quad, 1, &v, &opt, &db, NULL, &err);
    work_snapshot(&w1);
    long covered = 0;
    for (int i = 0; ok && i < 64 * 64; i++) covered += isfinite(db.depth[i]);
    depth_buffer_free(&db);
    WorkCounters w = work_diff(&w1, &w0);
    printf("    quad: %llu triangles, %llu fragments (%ld texels covered)\n", (unsigned long long)w.triangles,
           (unsigned long long)w.fragments, covered);
    CHECK(ok);
    CHECK(covered == 32 * 24);
    CHECK(w.triangles == 2 && w.fragments == 32 * 24);
}

/* view_sample_mapping's influence pairs (work.influence) against a hand
 * count: a 1 x 1 quad (two triangles, receiver = false) at height 2 over a
 * ground plane under a disk light of radius 3 at height 8 facing down, seen
 * from the side below the quad. The disk seen from the ground (atan 3/8 =
 * 0.36 rad) is wider than the quad (atan 0.25 = 0.24 rad), so no triangle
 * hides all of a view sample's light samples and no sample stops taking
 * triangles: each sample in the quad's influence region takes both of its
 * triangles, two pairs. The ground's own triangles pass its ball tests but
 * their plane separates it from the light (exact_triangle_reaches): none of
 * their pairs is counted. The region is the samples whose cone toward their
 * kept light samples (about the ray to the light's centre) meets the quad's
 * bounding ball (bound_corners: the box's centre (0, 2, 0), its half-diagonal
 * sqrt(2) / 2). So the count is even, and half of it lies between the
 * samples whose ray to the light's centre passes through that ball (the
 * cone's axis) and those whose cone toward the light's bounding sphere
 * (half-angle asin(R / |L - p|), which holds the disk) meets it, 1e-3 rad of
 * slack; the latter fewer than the lit candidates (a region, not every
 * pair). The stored-table path (masks=hough sample_set=shared) counts the
 * same way. About 0.5 s. */
static const char *const quad_scene =
    "return { name = 'quad', camera = { position = {0, 1, 4}, target = {0, 0, 0}, up = {0, 1, 0},\n"
    "  fov = 50, width = 48, height = 36 },\n"
    "  lights = { { type = 'disk', position = {0, 8, 0}, direction = {0, -1, 0}, radius = 3, intensity = 10 } },\n"
    "  objects = { { name = 'ground', shape = 'plane', size = {20, 20} },\n"
    "    { name = 'quad', shape = 'plane', size = {1, 1}, translate = {0, 2, 0}, receiver = false } } }\n";

/* Lit candidates whose ray to the light's centre meets the quad's ball
 * (inner) and whose cone toward the whole light does (outer), by hand
 * (world space; the angle between the centre ray and the ball's centre
 * against the ball's angular radius asin(r / |w|), plus the light's). */
static void quad_influence_bounds(Lab *lab, long *inner, long *outer, long *lit)
{
    Error err;
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const dvec3 light = d3(0, 8, 0), ball = d3(0, 2, 0);
    const double light_r = 3.0, ball_r = sqrt(0.5), slack = 1e-3;
    *inner = *outer = *lit = 0;
    for (int s = 0; cls && vs && s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        dvec3 p = d3_from(vs->p_world[s]), a = d3_sub(light, p), w = d3_sub(ball, p);
        double angle = acos(d3_dot(a, w) / (d3_len(a) * d3_len(w))), ball_angle = asin(ball_r / d3_len(w));
        *lit += 1;
        *inner += angle <= ball_angle - slack;
        *outer += angle <= ball_angle + asin(light_r / d3_len(a)) + slack;
    }
}

TEST(test_counters_vsm_influence_is_the_quads_footprint)
{
    Lab *lab = fixture_lab("quad.lua", quad_scene);
    CHECK(lab);
    long inner, outer, lit;
    quad_influence_bounds(lab, &inner, &outer, &lit);
    printf("    quad: %ld lit candidates, %ld with the light's centre ray through the quad's ball, %ld with its cone "
           "reaching it\n", lit, inner,
           outer);
    CHECK(inner > 0 && outer < lit); /* the view holds the region and samples outside it */
    static const char *const settings[] = {"samples=64", "samples=64 masks=hough sample_set=shared"};
    for (int i = 0; i < 2; i++) {
        RenderResult r;
        CHECK(filtered_render(lab, "view_sample_mapping", settings[i], &r));
        uint64_t pairs = r.frame_work.influence;
        printf("    view_sample_mapping %s: %llu influence pairs (%llu per sample in the region)\n", settings[i],
               (unsigned long long)pairs, (unsigned long long)(pairs / 2));
        render_result_free(&r);
        CHECK_MSG(pairs % 2 == 0 && pairs / 2 >= (uint64_t)inner && pairs / 2 <= (uint64_t)outer,
                  "%s: %llu pairs, not two per sample of the quad's influence region (%ld ... %ld samples)",
                  settings[i], (unsigned long long)pairs, inner, outer);
    }
    lab_close(lab);
}

/* work.micropatches: backprojection counts each occluder polygon it
 * backprojects onto the light (cover()), whichever way it accumulates them
 * (the same polygons reach the samples under bitmask and area), and a
 * technique that backprojects none counts none. */
TEST(test_counters_backprojection_counts_its_micropatches)
{
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", COUNT_W, COUNT_H);
    CHECK(lab);
    static const char *const settings[] = {"occluder=micropatch accumulate=bitmask map_size=128",
                                           "occluder=micropatch accumulate=area map_size=128"};
    uint64_t counted[2] = {0, 0};
    for (int i = 0; i < 2; i++) {
        RenderResult r;
        CHECK(filtered_render(lab, "backprojection", settings[i], &r));
        counted[i] = r.eval_work.micropatches;
        printf("    backprojection %s: %llu micropatches, %ld lit candidates\n", settings[i],
               (unsigned long long)counted[i], r.lit_candidates);
        render_result_free(&r);
    }
    CHECK(counted[0] > 0 && counted[0] == counted[1]);
    RenderResult r;
    CHECK(filtered_render(lab, "pcf", "map_size=128", &r));
    CHECK(r.eval_work.micropatches == 0);
    render_result_free(&r);
    lab_close(lab);
}

/* The scenes the registry test renders on: the first whose light 1 a
 * technique handles (sphere, rect, textured rect, directional). */
static const char *const registry_scenes[] = {"scenes/sphere-on-plane.lua", "scenes/contact.lua",
                                              "scenes/textured-light.lua", "scenes/terrain.lua"};
#define NUM_REGISTRY_SCENES ((int)(sizeof registry_scenes / sizeof registry_scenes[0]))

static bool declares(const Technique *t, const char *kind)
{
    for (int i = 0; t->resources && t->resources[i]; i++)
        if (strcmp(t->resources[i], kind) == 0) return true;
    return false;
}

/* The record written for a render has a work block with its counters. */
static bool record_has_work(Lab *lab, const Technique *t, const double *params, const RenderResult *r)
{
    char *text = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&text, &len);
    if (!fp) return false;
    RunReport rep = {.command = "render", .lab = lab, .tech = t, .params = params, .render = r, .threads = 1};
    report_write_record_fp(&rep, fp);
    fclose(fp);
    bool ok = text && strstr(text, "\"work\": {") && strstr(text, "\"per_sample\": {") &&
              strstr(text, "\"bytes_built\": ");
    free(text);
    return ok;
}

/* What a technique must have counted, by the resources it declares; NULL
 * when it did. */
static const char *missing_work(const Technique *t, const RenderResult *r)
{
    const WorkCounters *e = &r->eval_work, *f = &r->frame_work;
    if (declares(t, "shadow_map") && e->texel_fetches == 0) return "a map technique fetched no texel";
    if (declares(t, "shadow_map") && f->triangles + f->rays == 0) return "its map was neither rasterised nor ray cast";
    if (strcmp(t->family, "ray traced") == 0 && e->rays == 0) return "a ray-traced technique traced no ray";
    if (strcmp(t->family, "geometry") == 0 && f->triangles == 0) return "a geometry technique set up no triangle";
    if (f->texel_fetches + f->rays + f->triangles == 0) return "its frame counted no work at all";
    if (e->texel_bytes < e->texel_fetches) return "fewer bytes read than texels fetched";
    return NULL;
}

TEST(test_counters_every_technique_counts_its_work)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *labs[NUM_REGISTRY_SCENES];
    for (int i = 0; i < NUM_REGISTRY_SCENES; i++) labs[i] = filtered_open(registry_scenes[i], COUNT_W, COUNT_H);
    int failed = 0, checked = 0;
    for (int ti = 0; ti < tech_count(); ti++) {
        const Technique *t = tech_at(ti);
        Lab *lab = NULL;
        for (int s = 0; s < NUM_REGISTRY_SCENES && !lab; s++)
            if (labs[s] && (t->lights & LIGHT_BIT(lab_scene(labs[s])->lights[0].kind))) lab = labs[s];
        double v[TECH_MAX_PARAMS];
        tech_params_default(t, v);
        if (smap_has_map_params(t)) v[SMAP_P_MAP_SIZE] = 128;
        Error err;
        RenderRequest rq = {.tech = t, .params = v, .light_index = 0, .repeat = 1};
        RenderResult r;
        const char *why = !lab ? "no scene has a light it handles" : NULL;
        if (!why && !lab_render(lab, &rq, &r, &err)) why = err.msg;
        if (!why) {
            why = missing_work(t, &r);
            if (!why && !record_has_work(lab, t, v, &r)) why = "its record has no work block";
            printf("    %-22s texels/sample %7.2f  rays/sample %6.2f  frame: %9llu triangles %9llu fragments "
                   "%8llu texels %7llu rays\n",
                   t->name, (double)r.eval_work.texel_fetches / (double)(r.lit_candidates ? r.lit_candidates : 1),
                   (double)r.eval_work.rays / (double)(r.lit_candidates ? r.lit_candidates : 1),
                   (unsigned long long)r.frame_work.triangles, (unsigned long long)r.frame_work.fragments,
                   (unsigned long long)r.frame_work.texel_fetches, (unsigned long long)r.frame_work.rays);
            render_result_free(&r);
        }
        checked++;
        if (why) {
            failed++;
            printf("    FAILED %s: %s\n", t->name, why);
        }
    }
    for (int i = 0; i < NUM_REGISTRY_SCENES; i++) lab_close(labs[i]);
    omp_set_num_threads(threads);
    CHECK_MSG(failed == 0, "%d of %d techniques did not count their work", failed, checked);
}
