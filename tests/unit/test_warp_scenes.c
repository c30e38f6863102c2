/* test_warp_scenes.c -- warps and cascades against the ray-traced truth on
 * scenes/terrain.lua (a directional sun, so one shadow ray per sample is
 * exact): misclassification falls as the split count grows (course
 * §3.2.3.1), LiSPSM beats the uniform map of the same size under an
 * overhead sun and equals it when the light is behind the viewer (§3.2.2,
 * §3.2.3: "warping degenerates to uniform shadow mapping"); the degenerate
 * configurations of the issue give finite maps, visibilities in [0, 1] and
 * finite error figures for directional, spot and point lights, and PSM
 * with a light behind the eye classifies like the unwarped map (on
 * scenes/overhead-plane.lua); the analysis is built only when asked for. */
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "lab/compare.h"
#include "resources/analysis/aliasing.h"
#include "techniques/smap.h"
#include "test.h"

#define SMALL "camera.width=192", "camera.height=144"

static Lab *open_with(const char *scene, const char *const *ov, int n)
{
    Error err;
    Lab *lab = lab_open(scene, ov, n, &err);
    if (!lab) printf("    %s\n", err.msg);
    return lab;
}

static bool params_of(const Technique *t, const char *const *assign, int n, double *p)
{
    Error err;
    tech_params_default(t, p);
    for (int i = 0; i < n; i++)
        if (!tech_param_parse(t, assign[i], p, &err)) { printf("    %s\n", err.msg); return false; }
    return true;
}

/* Samples where `sm` with these map parameters disagrees with the truth. */
static long misclassified(Lab *lab, const char *const *assign, int n)
{
    Error err;
    const Technique *t = tech_find("sm", &err);
    CompareRequest rq = {.tech = t, .light_index = 0, .repeat = 1, .reference = true,
                         .ref = {MEASURE_VISIBILITY, 1, SAMPLING_R2, 1, false}};
    double p[TECH_MAX_PARAMS];
    if (!params_of(t, assign, n, p)) return -1;
    rq.params = p;
    CompareResult res;
    if (!lab_compare(lab, &rq, &res, &err)) { printf("    %s\n", err.msg); return -1; }
    long wrong = res.metrics.false_shadow + res.metrics.false_lit;
    compare_result_free(&res);
    return wrong;
}

TEST(test_cascades_misclassification_falls_as_the_split_count_grows)
{
    const char *ov[] = {SMALL};
    Lab *lab = open_with("scenes/terrain.lua", ov, 2);
    CHECK(lab);
    long wrong[4];
    for (int k = 0; k < 4; k++) {
        char c[32];
        snprintf(c, sizeof c, "cascades=%d", 1 << k);
        const char *a[] = {"fit=body", "map_size=1024", c};
        wrong[k] = misclassified(lab, a, 3);
        printf("    %-11s %5ld misclassified\n", c, wrong[k]);
        CHECK(wrong[k] >= 0);
    }
    for (int k = 1; k < 4; k++) CHECK_MSG(wrong[k] < wrong[k - 1], "%ld cascades: %ld, not below %ld", 1L << k, wrong[k], wrong[k - 1]);
    CHECK(wrong[3] * 4 < wrong[0]);
    lab_close(lab);
}

/* The terrain's camera with its view along `view` and the sun along `sun`. */
static Lab *terrain_looking(dvec3 view, dvec3 sun)
{
    const char *ov0[] = {SMALL};
    Lab *base = open_with("scenes/terrain.lua", ov0, 2);
    if (!base) return NULL;
    vec3 e = lab_scene(base)->camera.position;
    char target[128], light[128];
    snprintf(target, sizeof target, "camera.target={%.9g,%.9g,%.9g}", e.x + view.x, e.y + view.y, e.z + view.z);
    snprintf(light, sizeof light, "lights[1].direction={%.9g,%.9g,%.9g}", sun.x, sun.y, sun.z);
    lab_close(base);
    const char *ov[] = {SMALL, target, light};
    return open_with("scenes/terrain.lua", ov, 4);
}

TEST(test_lispsm_beats_uniform_overhead_and_equals_it_with_the_light_behind)
{
    const char *uni[] = {"fit=body", "map_size=1024", "projection=ortho"};
    const char *lis[] = {"fit=body", "map_size=1024", "projection=lispsm"};
    Lab *lab = terrain_looking(d3(-40, -1.5, -400), d3(0.3, -1, 0.2)); /* the scene's view, a high sun */
    CHECK(lab);
    long u = misclassified(lab, uni, 3), l = misclassified(lab, lis, 3);
    printf("    overhead sun:        uniform %5ld, lispsm %5ld misclassified\n", u, l);
    CHECK(u > 0 && l >= 0);
    CHECK_MSG(l * 5 < u, "lispsm %ld is not well below uniform %ld", l, u);
    lab_close(lab);
    /* the sun 5 degrees off the view direction, from behind the viewer (Lloyd's falloff: uniform below theta/3) */
    dvec3 v = d3_normalize_or(d3(-40, -150, -400), d3(0, 0, -1)), side = d3_normalize_or(d3_cross(v, d3(0, 1, 0)), d3(1, 0, 0));
    lab = terrain_looking(v, d3_add(v, d3_scale(side, tan(5.0 * M_PI / 180.0))));
    CHECK(lab);
    u = misclassified(lab, uni, 3);
    l = misclassified(lab, lis, 3);
    printf("    sun behind the view: uniform %5ld, lispsm %5ld misclassified\n", u, l);
    CHECK(u > 0 && l >= 0);
    CHECK_MSG(labs(l - u) <= u / 10 + 10, "lispsm %ld differs from uniform %ld with the light behind", l, u);
    lab_close(lab);
}

/* Every warp (LiSPSM also with a free n), cascades and frustum faces on a
 * scene: the map builds, the aliasing render is finite and in [0, 1], its
 * readings and summary are finite. Lights with a position take
 * perspective slices where a directional light takes ortho ones. */
static void check_finite(const char *what, Lab *lab)
{
    bool directional = lab_scene(lab)->lights[0].kind == LIGHT_DIRECTIONAL;
    const char *flat = directional ? "projection=ortho" : "projection=perspective";
    const char *const projs[] = {"projection=psm", "projection=lispsm", "projection=tsm", "projection=logpsm",
                                 flat, "projection=lispsm", "projection=lispsm"};
    static const char *const parts[] = {"cascades=1", "cascades=1", "cascades=1", "cascades=1", "cascades=4",
                                        "split_scheme=faces", "warp_n_world=2"};
    Error err;
    const Technique *t = tech_find("aliasing", &err);
    for (int k = 0; k < 7; k++) {
        const char *a[] = {"fit=body", "map_size=256", projs[k], parts[k], k == 5 ? "cascades=1" : "split_scheme=log"};
        double p[TECH_MAX_PARAMS];
        CHECK(params_of(t, a, 5, p));
        RenderRequest rq = {.tech = t, .params = p, .light_index = 0, .repeat = 1};
        RenderResult r;
        CHECK_MSG(lab_render(lab, &rq, &r, &err), "%s, %s: %s", what, projs[k], err.msg);
        long bad = 0;
        for (size_t i = 0; i < image_count(&r.visibility); i++) bad += !(r.visibility.data[i] >= 0 && r.visibility.data[i] <= 1);
        for (size_t i = 0; i < image_count(&r.aux); i++) bad += !isfinite(r.aux.data[i]);
        render_result_free(&r);
        ShadowMapSpec spec = smap_spec(p);
        const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
        CHECK(m);
        const AliasingMap *an = res_aliasing(lab_resources(lab), lab_scene(lab), 0, m, &err);
        CHECK(an);
        const AliasingSummary *s = &an->sum;
        for (size_t i = 0; i < (size_t)m->num_faces * m->res * m->res; i++) bad += isnan(m->depth[i]);
        AliasingSummary fr; /* the frustum measure's boundary probes and climbs, on the same extremes */
        aliasing_frustum(&m->view, lab_scene(lab), &lab_scene(lab)->lights[0], 6, 6, 6, &fr);
        bad += !isfinite(s->m_max) + !isfinite(s->m_mean) + !isfinite(s->storage);
        bad += !isfinite(fr.m_max) + !isfinite(fr.m_mean) + !isfinite(fr.storage);
        printf("    %-11s %-30s %-17s %-18s %5ld measured, m max %-9.4g %s %-9.4g storage factor %-9.4g "
               "non-finite %ld%s\n", light_kind_name(lab_scene(lab)->lights[0].kind), what, projs[k], parts[k],
               s->measured, s->m_max, aliasing_storage_name(s), s->storage, fr.storage, bad,
               m->view.face[0].warp_fallback ? " (fell back)" : "");
        CHECK_MSG(bad == 0, "%s, %s: %ld non-finite or out-of-range values", what, projs[k], bad);
    }
}

static void check_cases(const char *kind, const char *const (*cases)[5], int n_cases)
{
    for (int c = 0; c < n_cases; c++) {
        const char *ov[6] = {"camera.width=64", "camera.height=48"};
        int n = 2;
        for (int k = 1; k < 5 && cases[c][k]; k++) ov[n++] = cases[c][k];
        Lab *lab = open_with("scenes/overhead-plane.lua", ov, n);
        CHECK_MSG(lab, "%s light, %s", kind, cases[c][0]);
        check_finite(cases[c][0], lab);
        lab_close(lab);
    }
}

/* A spot or point light at `pos` (spots aimed along `dir`), as an override. */
#define SPOT(pos, dir) "lights[1]={type='spot',position=" pos ",direction=" dir ",cone_angle=60}"
#define POINT(pos) "lights[1]={type='point',position=" pos "}"

/* The degenerate configurations of the issue, for directional, spot and
 * point lights (the view on overhead-plane.lua: the eye at the origin
 * looking down -z, the ground 0.5 below): light along the view (behind the
 * eye, ahead of it, at the eye), a light behind the viewer casting onto the
 * receivers in front (for PSM such a light lies behind the eye's plane: its
 * post-perspective image is past infinity, and points behind it swap
 * sides), near 1e-6, far / near 1e6, an empty body, a light grazing the
 * ground. */
TEST(test_warp_degenerate_configurations_stay_finite)
{
    static const char *const directional[][5] = {
        {"light along the view", "lights[1].direction={0,0,-1}", NULL, NULL},          /* gamma = 0, light behind */
        {"light against the view", "lights[1].direction={0,-0.01,1}", NULL, NULL},     /* toward the eye */
        {"near 1e-6, far 1", "camera.near=0.000001", "camera.far=1", NULL},
        {"far / near = 1e6", "camera.near=0.0001", "camera.far=100", NULL},
        {"empty body", "camera.position={0,50,0}", "camera.target={0,60,0}", "camera.up={1,0,0}"}, /* the sky */
        {"light grazing the ground", "lights[1].direction={0,-0.0001,-1}", NULL, NULL},
    };
    static const char *const spot[][5] = {
        {"behind the viewer, casting ahead", SPOT("{0,3,12}", "{0,-3.5,-52}"), NULL, NULL},
        {"on the view axis behind the eye", SPOT("{0,0,8}", "{0,0,-1}"), NULL, NULL},
        {"on the view axis, facing the eye", SPOT("{0,0,-150}", "{0,0,1}"), NULL, NULL},
        {"at the eye", SPOT("{0,0,0}", "{0,-0.2,-1}"), NULL, NULL},
        {"near 1e-6, far 1", SPOT("{0,2,-0.5}", "{0,-1,0}"), "camera.near=0.000001", "camera.far=1"},
        {"far / near = 1e6", SPOT("{0,20,-30}", "{0,-1,0}"), "camera.near=0.0001", "camera.far=100"},
        {"empty body", SPOT("{0,20,-30}", "{0,-1,0}"), "camera.position={0,50,0}", "camera.target={0,60,0}",
         "camera.up={1,0,0}"},
        {"grazing the ground", SPOT("{0,-0.45,20}", "{0,0,-1}"), NULL, NULL},
    };
    static const char *const point[][5] = {
        {"behind the viewer, casting ahead", POINT("{0,3,12}"), NULL, NULL},
        {"on the view axis behind the eye", POINT("{0,0,8}"), NULL, NULL},
        {"on the view axis, ahead", POINT("{0,0,-150}"), NULL, NULL},
        {"at the eye", POINT("{0,0,0}"), NULL, NULL},
        {"near 1e-6, far 1", POINT("{0,2,-0.5}"), "camera.near=0.000001", "camera.far=1"},
        {"far / near = 1e6", POINT("{0,20,-30}"), "camera.near=0.0001", "camera.far=100"},
        {"empty body", POINT("{0,20,-30}"), "camera.position={0,50,0}", "camera.target={0,60,0}",
         "camera.up={1,0,0}"},
        {"grazing the ground", POINT("{0,-0.45,20}"), NULL, NULL},
    };
    check_cases("directional", directional, (int)(sizeof directional / sizeof directional[0]));
    check_cases("spot", spot, (int)(sizeof spot / sizeof spot[0]));
    check_cases("point", point, (int)(sizeof point / sizeof point[0]));
    /* a flat scene: the body has no height */
    Lab *flat = fixture_lab("flat.lua", "return { name = 'flat', camera = { position = {0, 1, 4}, target = {0, 0, 0},"
                                        " width = 64, height = 48 }, lights = { { type = 'directional',"
                                        " direction = {0.2, -1, 0.1} } }, objects = { { name = 'ground',"
                                        " shape = 'plane', size = {8, 8} } } }");
    CHECK(flat);
    check_finite("flat body", flat);
    lab_close(flat);
}

/* A light behind the viewer casting onto the receivers in front: in the
 * eye's post-perspective space it lies past infinity (behind the eye's
 * plane), where Stamminger & Drettakis's map must invert the depth order or
 * shadows land on the wrong side. Ours is a homography of the light's own
 * base plane, so PSM is used there as such (no fallback) and classifies as
 * well as the unwarped perspective map against the truth. */
TEST(test_warp_psm_with_the_light_behind_the_eye_matches_the_truth)
{
    static const char *const lights[] = {SPOT("{0,3,12}", "{0,-3.5,-52}"), POINT("{0,3,12}")};
    for (int k = 0; k < 2; k++) {
        const char *ov[] = {SMALL, lights[k]};
        Lab *lab = open_with("scenes/overhead-plane.lua", ov, 3);
        CHECK(lab);
        const char *psm[] = {"fit=body", "map_size=1024", "projection=psm"};
        const char *flat[] = {"fit=body", "map_size=1024", "projection=perspective"};
        long wp = misclassified(lab, psm, 3), wf = misclassified(lab, flat, 3);
        Error err;
        double p[TECH_MAX_PARAMS];
        CHECK(params_of(tech_find("sm", &err), psm, 3, p));
        ShadowMapSpec spec = smap_spec(p);
        const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
        CHECK(m);
        const MapFace *f = &m->view.face[0];
        bool own = f->warp == MAP_WARP_HOMOGRAPHY && f->warp_n == 0.0 && !f->warp_fallback; /* psm_homography's */
        long samples = (long)lab_scene(lab)->camera.width * lab_scene(lab)->camera.height;
        printf("    %s light behind the eye: psm %ld misclassified (%s), perspective %ld, of %ld pixels\n",
               light_kind_name(lab_scene(lab)->lights[0].kind), wp,
               own ? "its own homography" : "fell back", wf, samples);
        CHECK(own);
        CHECK(wp >= 0 && wf >= 0);
        CHECK_MSG(wp <= wf + 5 && wp * 200 < samples, "psm %ld misclassified, perspective %ld", wp, wf);
        lab_close(lab);
    }
}

TEST(test_aliasing_is_built_only_when_asked_for)
{
    const char *ov[] = {"camera.width=64", "camera.height=48"};
    Lab *lab = open_with("scenes/overhead-plane.lua", ov, 2);
    CHECK(lab);
    Error err;
    int built[3] = {0}, reused[3] = {0};
    const char *techs[] = {"sm", "aliasing", "aliasing"};
    for (int k = 0; k < 3; k++) {
        const Technique *t = tech_find(techs[k], &err);
        double p[TECH_MAX_PARAMS];
        const char *a[] = {"fit=body", "projection=lispsm"};
        CHECK(params_of(t, a, 2, p));
        RenderRequest rq = {.tech = t, .params = p, .light_index = 0, .repeat = 1};
        RenderResult r;
        CHECK(lab_render(lab, &rq, &r, &err));
        for (int i = 0; i < r.num_tech_resources; i++)
            if (strcmp(r.tech_resources[i].kind, "aliasing") == 0) (r.tech_resources[i].built ? built : reused)[k]++;
        render_result_free(&r);
    }
    printf("    aliasing resource: sm built %d; aliasing built %d, then reused %d\n", built[0], built[1], reused[2]);
    CHECK(built[0] == 0 && reused[0] == 0);
    CHECK(built[1] == 1 && built[2] == 0 && reused[2] == 1);
    lab_close(lab);
}
