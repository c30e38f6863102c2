/* test_warp.c -- warps, fitting and z-partitioning (course §3.2) measured by
 * the aliasing instrument (course §3.1): on scenes/overhead-plane.lua (an
 * overhead directional light, the view perpendicular to it, z_n = 1,
 * z_f = 100) the measured error along the view axis matches the closed
 * forms of ../shared/docs/course-ch1-3-catalogue.md §3.1.2 for uniform, PSM
 * and LiSPSM with n_opt on both map axes, the PSM and LiSPSM error products
 * are equal (99), log splits bound the depth-axis error by r^(1/m) - 1 and
 * LogPSM's is ln r; TSM's focus lands on the 80% line; Lloyd's falloff is
 * continuous. The errors are the catalogue's normalised dp/ds: e_y in
 * image-plane units at unit depth per map, e_x in viewport widths per map. */
#include <string.h>
#include "fixtures.h"
#include "resources/aliasing.h"
#include "resources/warp.h"
#include "techniques/smap.h"
#include "test.h"

#define Z_N 1.0
#define Z_F 100.0
#define RES 1024
#define MARGIN (1.0 + 4.0 / RES) /* lightview's 2-texel border on each side widens every fit */

static Lab *open_plane(void)
{
    Error err;
    Lab *lab = lab_open("scenes/overhead-plane.lua", NULL, 0, &err);
    if (!lab) printf("    %s\n", err.msg);
    return lab;
}

/* The map the shared parameters ask for ("name=value" assignments). */
static const ShadowMap *map_with(Lab *lab, const char *const *assign, int n)
{
    Error err;
    const Technique *t = tech_find("aliasing", &err);
    double p[TECH_MAX_PARAMS];
    tech_params_default(t, p);
    for (int i = 0; i < n; i++)
        if (!tech_param_parse(t, assign[i], p, &err)) { printf("    %s\n", err.msg); return NULL; }
    ShadowMapSpec spec = smap_spec(p);
    const ShadowMap *m = res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, &err);
    if (!m) printf("    %s\n", err.msg);
    return m;
}

/* The normalised errors at view depth z on the view axis, for a surface
 * element whose normal bisects the eye and light directions (cos alpha =
 * cos beta, the catalogue's setting). */
typedef struct AxisError { double e_x, e_y; int face; } AxisError;

static bool axis_error(const Scene *sc, const ShadowMap *m, double z, AxisError *out)
{
    AliasingView av = aliasing_view(&sc->camera);
    AliasingPoint pt;
    if (!aliasing_on_axis(&m->view, &av, &sc->lights[0], z, &pt)) return false;
    aliasing_normalised(&av, m->res, &pt, &out->e_x, &out->e_y);
    out->face = pt.face;
    return true;
}

/* n view depths from z_n to z_f inclusive, log spaced (a hair inside the ends) */
static double z_at(int i, int n) { return Z_N * pow(Z_F / Z_N, (double)i / (n - 1)) * (1.0 + 1e-9 * (i == 0) - 1e-9 * (i == n - 1)); }

typedef double (*ClosedForm)(double z);
static const double D = Z_F - Z_N;
static double n_opt(void) { return Z_N + sqrt(Z_F * Z_N); }
static double uni_y(double z) { return D / z; }
static double uni_x(double z) { return Z_F / z; }
static double psm_y(double z) { return z * D / (Z_N * Z_F); }
static double psm_x(double z) { (void)z; return 1.0; }
static double lis_y(double z) { double n = n_opt(), w = z - Z_N + n; return w * w * D / (z * n * (n + D)); }
static double lis_x(double z) { double n = n_opt(); return Z_F * (z - Z_N + n) / ((D + n) * z); }
static double log_y(double z) { (void)z; return log(Z_F / Z_N); }

/* Max relative deviation of the measured errors from the closed forms over
 * z_n..z_f; the maxima of both axes go to *max_x, *max_y. */
static double deviation(Lab *lab, const ShadowMap *m, ClosedForm fx, ClosedForm fy, double *max_x, double *max_y)
{
    double worst = 0.0;
    *max_x = *max_y = 0.0;
    for (int i = 0; i < 40; i++) {
        double z = z_at(i, 40);
        AxisError e;
        if (!axis_error(lab_scene(lab), m, z, &e)) return INFINITY;
        e.e_x /= MARGIN;
        e.e_y /= MARGIN;
        worst = fmax(worst, fmax(fabs(e.e_x / fx(z) - 1.0), fabs(e.e_y / fy(z) - 1.0)));
        *max_x = fmax(*max_x, e.e_x);
        *max_y = fmax(*max_y, e.e_y);
    }
    return worst;
}

TEST(test_warp_measured_error_matches_the_closed_forms)
{
    Lab *lab = open_plane();
    CHECK(lab);
    static const char *const projs[] = {"projection=ortho", "projection=psm", "projection=lispsm"};
    const ClosedForm fx[] = {uni_x, psm_x, lis_x}, fy[] = {uni_y, psm_y, lis_y};
    double prod[3];
    for (int k = 0; k < 3; k++) {
        const char *a[] = {"fit=body", "map_size=1024", projs[k]};
        const ShadowMap *m = map_with(lab, a, 3);
        CHECK(m);
        double mx, my, dev = deviation(lab, m, fx[k], fy[k], &mx, &my);
        prod[k] = mx * my;
        printf("    %-17s max e_x %8.3f  max e_y %8.3f  product %8.1f  worst deviation %.2f%%\n", projs[k], mx, my,
               prod[k], 100 * dev);
        CHECK_MSG(dev < 0.05, "%s deviates %.1f%% from the closed forms", projs[k], 100 * dev);
    }
    /* the comparison discriminates: twice n_opt is measurably another warp */
    const char *a2[] = {"fit=body", "map_size=1024", "projection=lispsm", "warp_n=2"};
    const ShadowMap *m2 = map_with(lab, a2, 4);
    CHECK(m2);
    double mx2, my2, dev2 = deviation(lab, m2, lis_x, lis_y, &mx2, &my2);
    printf("    lispsm warp_n=2 against the n_opt closed forms: worst deviation %.1f%%\n", 100 * dev2);
    CHECK(dev2 > 0.2);
    /* Lloyd et al. 2006: all perspective warps share the error product (99 for z_f / z_n = 100) */
    CHECK_NEAR(prod[1], 99.0, 99.0 * 0.05);
    CHECK_NEAR(prod[2], 99.0, 99.0 * 0.05);
    CHECK_NEAR(prod[0], 9900.0, 9900.0 * 0.05);
    lab_close(lab);
}

TEST(test_warp_log_splits_bound_the_depth_axis_error)
{
    Lab *lab = open_plane();
    CHECK(lab);
    for (int m = 2; m <= 8; m *= 2) {
        char cascades[32];
        snprintf(cascades, sizeof cascades, "cascades=%d", m);
        const char *a[] = {"fit=body", "map_size=1024", "projection=ortho", "split_scheme=log", cascades};
        const ShadowMap *map = map_with(lab, a, 5);
        CHECK(map && map->num_faces == m);
        double bound_y = pow(Z_F / Z_N, 1.0 / m) - 1.0, bound_x = pow(Z_F / Z_N, 1.0 / m), my = 0, mx = 0;
        int faces_seen = 0;
        for (int i = 0; i < 200; i++) {
            AxisError e;
            CHECK(axis_error(lab_scene(lab), map, z_at(i, 200), &e));
            my = fmax(my, e.e_y);
            mx = fmax(mx, e.e_x);
            faces_seen |= 1 << e.face;
        }
        printf("    m = %d: max e_y %.3f (bound r^(1/m) - 1 = %.3f), max e_x %.3f (bound %.3f)\n", m, my, bound_y, mx,
               bound_x);
        CHECK(faces_seen == (1 << m) - 1); /* every slice is used, each by its own depths */
        CHECK_MSG(my <= bound_y * 1.05, "m = %d: depth-axis error %.3f above %.3f", m, my, bound_y);
        CHECK_MSG(my >= bound_y * 0.9, "m = %d: the bound %.3f is not reached (%.3f): the test would be vacuous", m,
                  bound_y, my);
        CHECK(mx <= bound_x * 1.05);
    }
    lab_close(lab);
}

TEST(test_warp_logpsm_has_constant_error_ln_r)
{
    Lab *lab = open_plane();
    CHECK(lab);
    const char *a[] = {"fit=body", "map_size=1024", "projection=logpsm"};
    const ShadowMap *m = map_with(lab, a, 3);
    CHECK(m);
    double mx, my, dev = deviation(lab, m, psm_x, log_y, &mx, &my);
    printf("    logpsm: max e_y %.3f (ln r = %.3f), max e_x %.3f, worst deviation %.2f%%\n", my, log(Z_F / Z_N), mx,
           100 * dev);
    CHECK(dev < 0.05);
    lab_close(lab);
}

TEST(test_warp_tsm_focus_maps_to_the_80_percent_line)
{
    Lab *lab = open_plane();
    CHECK(lab);
    for (int k = 0; k < 3; k++) {
        double f = 0.1 + 0.25 * k;
        char focus[32];
        snprintf(focus, sizeof focus, "tsm_focus=%g", f);
        const char *a[] = {"fit=body", "map_size=1024", "projection=tsm", "warp_falloff=none", focus};
        const ShadowMap *m = map_with(lab, a, 5);
        CHECK(m);
        AliasingView av = aliasing_view(&lab_scene(lab)->camera);
        MapCoord mc = lightview_locate(&m->view, d3_madd(av.frustum.eye, av.frustum.fwd, Z_N + f * D));
        double t = mc.t / m->res;
        printf("    tsm_focus %.2f: the focus point lands at t = %.4f of the map\n", f, t);
        CHECK(mc.inside);
        CHECK_NEAR(t, 0.8, 0.01); /* Martin & Tan 2004: the focus region gets 80% of the map */
    }
    lab_close(lab);
}

TEST(test_warp_lloyd_falloff_and_n_are_continuous)
{
    double theta = 30.0 * M_PI / 180.0, prev = -2.0;
    for (int i = 0; i <= 9000; i++) { /* 0 to 90 degrees in 0.01 degree steps */
        double eta = warp_eta_lloyd(i * 0.01 * M_PI / 180.0, theta);
        CHECK(eta >= -1.0 && eta <= 0.0);
        CHECK_MSG(eta >= prev - 1e-12 && eta - prev <= 0.01 + (prev < -1.5 ? 2.0 : 0.0),
                  "eta jumps from %g to %g at %.2f degrees", prev, eta, i * 0.01);
        prev = eta;
    }
    CHECK(warp_eta_lloyd(0.0, theta) == -1.0);
    CHECK(warp_eta_lloyd(0.5 * M_PI, theta) == 0.0);
    double alpha = Z_F / Z_N;
    /* eta = 0 is Wimmer's n_opt = z_n + sqrt(z_f z_n); eta = 1 is PSM's n = z_n; -1 uniform */
    CHECK_NEAR(D * warp_n_over_d(0.0, alpha), n_opt(), 1e-9);
    CHECK_NEAR(D * warp_n_over_d(1.0, alpha), Z_N, 1e-9);
    CHECK(isinf(warp_n_over_d(-1.0, alpha)));
    CHECK_NEAR(warp_n_over_d(-1e-9, alpha), warp_n_over_d(1e-9, alpha), 1e-6);
    CHECK(isinf(warp_n_over_d(0.0, 1.0))); /* no depth range: nothing to warp */
}

TEST(test_warp_stabilized_texels_stay_put_when_the_camera_moves)
{
    const char *moves[] = {"camera.position={0,0,0}", "camera.position={0.37,0.05,-0.61}"};
    double origin[2][2], texel[2], origin_free[2][2];
    for (int k = 0; k < 2; k++) {
        Error err;
        const char *ov[] = {moves[k], "camera.target={0.2,0,-1}"};
        Lab *lab = lab_open("scenes/overhead-plane.lua", ov, 2, &err);
        CHECK(lab);
        const char *st[] = {"fit=body", "map_size=1024", "stabilize=true"}, *fr[] = {"fit=body", "map_size=1024"};
        const ShadowMap *a = map_with(lab, st, 3), *b = map_with(lab, fr, 2);
        CHECK(a && b);
        texel[k] = (a->view.face[0].r - a->view.face[0].l) / a->res;
        /* where world point (0, 0, 0) falls, in texels: its fraction is the grid's phase */
        MapCoord ma = lightview_locate_on(&a->view, 0, d3(0, -0.5, -30)), mb = lightview_locate_on(&b->view, 0, d3(0, -0.5, -30));
        origin[k][0] = ma.s - floor(ma.s);
        origin[k][1] = ma.t - floor(ma.t);
        origin_free[k][0] = mb.s - floor(mb.s);
        origin_free[k][1] = mb.t - floor(mb.t);
        lab_close(lab);
    }
    printf("    stabilized: texel %.6f -> %.6f, phase (%.4f, %.4f) -> (%.4f, %.4f); free: (%.4f, %.4f) -> (%.4f, %.4f)\n",
           texel[0], texel[1], origin[0][0], origin[0][1], origin[1][0], origin[1][1], origin_free[0][0],
           origin_free[0][1], origin_free[1][0], origin_free[1][1]);
    CHECK_NEAR(texel[0], texel[1], 1e-12 * texel[0]);
    CHECK_NEAR(origin[0][0], origin[1][0], 1e-6);
    CHECK_NEAR(origin[0][1], origin[1][1], 1e-6);
    CHECK(fabs(origin_free[0][0] - origin_free[1][0]) + fabs(origin_free[0][1] - origin_free[1][1]) > 1e-3);
}

/* Course §3.2.3.2: under an overhead light only the top face of the view
 * frustum faces the light, so frustum-face partitioning is one warped map,
 * LiSPSM itself; with the light behind the viewer the near face and the
 * side faces each get a map, and every point of the frustum finds one. */
TEST(test_warp_frustum_faces_overhead_is_warping_behind_is_several_maps)
{
    Lab *lab = open_plane();
    CHECK(lab);
    const char *fp[] = {"fit=body", "map_size=1024", "projection=lispsm", "split_scheme=faces"};
    const char *w[] = {"fit=body", "map_size=1024", "projection=lispsm"};
    const ShadowMap *a = map_with(lab, fp, 4), *b = map_with(lab, w, 3);
    CHECK(a && b && a->num_faces == 1);
    AliasingSummary sa, sb;
    const Scene *sc = lab_scene(lab);
    aliasing_frustum(&a->view, sc, &sc->lights[0], 12, 12, 12, &sa);
    aliasing_frustum(&b->view, sc, &sc->lights[0], 12, 12, 12, &sb);
    printf("    overhead: faces %d, storage factor %.2f (lispsm %.2f)\n", a->num_faces, sa.storage, sb.storage);
    CHECK_NEAR(sa.storage, sb.storage, 1e-6 * sb.storage);
    lab_close(lab);
    Error err;
    const char *ov[] = {"lights[1].direction={0.1,-0.4,-1}"};
    lab = lab_open("scenes/overhead-plane.lua", ov, 1, &err);
    CHECK(lab);
    a = map_with(lab, fp, 4);
    CHECK(a && a->num_faces >= 3);
    sc = lab_scene(lab);
    aliasing_frustum(&a->view, sc, &sc->lights[0], 12, 12, 12, &sa);
    long per_face = 0;
    for (int f = 0; f < a->num_faces; f++) per_face += sa.face_count[f] > 0;
    printf("    light behind: %d faces, %ld of them used, %ld frustum points measured\n", a->num_faces, per_face,
           sa.measured);
    CHECK(per_face >= 3 && sa.measured > 0);
    lab_close(lab);
}
