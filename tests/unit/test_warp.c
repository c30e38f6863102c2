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
#include "resources/analysis/aliasing.h"
#include "resources/views/warp.h"
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

/* The map the shared parameters ask for ("name=value" assignments), or
 * NULL and why. */
static const ShadowMap *map_or_error(Lab *lab, const char *const *assign, int n, Error *err)
{
    const Technique *t = tech_find("aliasing", err);
    double p[TECH_MAX_PARAMS];
    tech_params_default(t, p);
    for (int i = 0; i < n; i++)
        if (!tech_param_parse(t, assign[i], p, err)) return NULL;
    ShadowMapSpec spec = smap_spec(p);
    return res_shadow_map(lab_resources(lab), lab_scene(lab), 0, &spec, err);
}

static const ShadowMap *map_with(Lab *lab, const char *const *assign, int n)
{
    Error err;
    const ShadowMap *m = map_or_error(lab, assign, n, &err);
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

/* The closed forms at view depth z; n is LiSPSM's (world units), unused by the others. */
typedef double (*ClosedForm)(double z, double n);
static const double D = Z_F - Z_N;
static double n_opt(void) { return Z_N + sqrt(Z_F * Z_N); }
static double uni_y(double z, double n) { (void)n; return D / z; }
static double uni_x(double z, double n) { (void)n; return Z_F / z; }
static double psm_y(double z, double n) { (void)n; return z * D / (Z_N * Z_F); }
static double psm_x(double z, double n) { (void)z; (void)n; return 1.0; }
static double lis_y(double z, double n) { double w = z - Z_N + n; return w * w * D / (z * n * (n + D)); }
static double lis_x(double z, double n) { return Z_F * (z - Z_N + n) / ((D + n) * z); }
static double log_y(double z, double n) { (void)z; (void)n; return log(Z_F / Z_N); }

/* Max relative deviation of the measured errors from the closed forms (at
 * LiSPSM's n) over z_n..z_f; the maxima of both axes go to *max_x, *max_y. */
static double deviation(Lab *lab, const ShadowMap *m, ClosedForm fx, ClosedForm fy, double n, double *max_x,
                        double *max_y)
{
    double worst = 0.0;
    *max_x = *max_y = 0.0;
    for (int i = 0; i < 40; i++) {
        double z = z_at(i, 40);
        AxisError e;
        if (!axis_error(lab_scene(lab), m, z, &e)) return INFINITY;
        e.e_x /= MARGIN;
        e.e_y /= MARGIN;
        worst = fmax(worst, fmax(fabs(e.e_x / fx(z, n) - 1.0), fabs(e.e_y / fy(z, n) - 1.0)));
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
        double mx, my, dev = deviation(lab, m, fx[k], fy[k], n_opt(), &mx, &my);
        prod[k] = mx * my;
        printf("    %-17s max e_x %8.3f  max e_y %8.3f  product %8.1f  worst deviation %.2f%%\n", projs[k], mx, my,
               prod[k], 100 * dev);
        CHECK_MSG(dev < 0.05, "%s deviates %.1f%% from the closed forms", projs[k], 100 * dev);
    }
    /* the comparison discriminates: twice n_opt is measurably another warp */
    const char *a2[] = {"fit=body", "map_size=1024", "projection=lispsm", "warp_n=2"};
    const ShadowMap *m2 = map_with(lab, a2, 4);
    CHECK(m2);
    double mx2, my2, dev2 = deviation(lab, m2, lis_x, lis_y, n_opt(), &mx2, &my2);
    printf("    lispsm warp_n=2 against the n_opt closed forms: worst deviation %.1f%%\n", 100 * dev2);
    CHECK(dev2 > 0.2);
    /* Lloyd et al. 2006: all perspective warps share the error product (99 for z_f / z_n = 100) */
    CHECK_NEAR(prod[1], 99.0, 99.0 * 0.05);
    CHECK_NEAR(prod[2], 99.0, 99.0 * 0.05);
    CHECK_NEAR(prod[0], 9900.0, 9900.0 * 0.05);
    lab_close(lab);
}

/* Course Fig. 3.6: "the parameter n is free and can vary between z_n (PSM)
 * and infinity (uniform)". Each way of giving it reaches the n it names:
 * warp_n x n_opt (no falloff), and a free n in world units (warp_n_world),
 * whose measured errors follow the closed forms at that n (n = z_n: PSM's);
 * the free n is used as given, whatever the falloff. */
TEST(test_warp_lispsm_n_free_or_a_multiple_of_n_opt)
{
    Lab *lab = open_plane();
    CHECK(lab);
    static const struct { const char *assign; double times_n_opt, world; } cases[] = {
        {"warp_n=2", 2, 0}, {"warp_n=0.3", 0.3, 0}, {"warp_n_world=1", 0, 1}, {"warp_n_world=3", 0, 3},
        {"warp_n_world=11", 0, 11}, {"warp_n_world=40", 0, 40}, {"warp_n_world=1000", 0, 1000},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *a[] = {"fit=body", "map_size=1024", "projection=lispsm", "warp_falloff=none", cases[k].assign};
        const ShadowMap *m = map_with(lab, a, 5);
        CHECK(m);
        double n = cases[k].world > 0 ? cases[k].world : cases[k].times_n_opt * n_opt();
        double mx, my, dev = deviation(lab, m, lis_x, lis_y, n, &mx, &my);
        printf("    %-18s n = %7.4g: max e_x %8.3f  max e_y %8.3f  product %6.2f  worst deviation %.3f%%\n",
               cases[k].assign, n, mx, my, mx * my, 100 * dev);
        CHECK_MSG(dev < 0.01, "%s deviates %.2f%% from the closed forms at n = %g", cases[k].assign, 100 * dev, n);
        if (n == Z_N) { /* n = z_n is PSM's depth-axis error */
            double px, py;
            CHECK(deviation(lab, m, lis_x, psm_y, Z_N, &px, &py) < 0.01);
        }
    }
    lab_close(lab);
    /* light 40 degrees off the view: the falloffs give different n, a free n stays as given */
    Error err;
    const char *ov[] = {"lights[1].direction={0,-0.6428,-0.7660}"};
    lab = lab_open("scenes/overhead-plane.lua", ov, 1, &err);
    CHECK(lab);
    double n_of[2][3];
    static const char *const falloffs[] = {"warp_falloff=lloyd", "warp_falloff=sin_gamma", "warp_falloff=none"};
    for (int f = 0; f < 3; f++) {
        const char *a[] = {"fit=body", "map_size=256", "projection=lispsm", falloffs[f]};
        const char *b[] = {"fit=body", "map_size=256", "projection=lispsm", falloffs[f], "warp_n_world=20"};
        const ShadowMap *ma = map_with(lab, a, 4), *mb = map_with(lab, b, 5);
        CHECK(ma && mb);
        n_of[0][f] = ma->view.face[0].warp_n;
        n_of[1][f] = mb->view.face[0].warp_n;
    }
    printf("    gamma 40 deg, n in base NDC: falloffs %.5g %.5g %.5g; warp_n_world=20: %.5g %.5g %.5g\n", n_of[0][0],
           n_of[0][1], n_of[0][2], n_of[1][0], n_of[1][1], n_of[1][2]);
    CHECK(fabs(n_of[0][0] - n_of[0][2]) > 0.01 * n_of[0][2] && fabs(n_of[0][1] - n_of[0][2]) > 0.01 * n_of[0][2]);
    CHECK(n_of[1][0] == n_of[1][2] && n_of[1][1] == n_of[1][2] && isfinite(n_of[1][0]));
    lab_close(lab);
}

/* Explicit split distances (split_scheme=explicit): the map's slices are the
 * given view depths, each slice's uniform map has the uniform closed form's
 * depth-axis error (b - a) / a at its near end; the given distances are part
 * of the map's key; too few, too many, unordered or out-of-range distances
 * are refused naming the parameter and the valid range. */
TEST(test_warp_explicit_splits_are_the_given_distances)
{
    Lab *lab = open_plane();
    CHECK(lab);
    const double given[5] = {Z_N, 3, 12, 40, Z_F};
    const char *a[] = {"fit=body", "map_size=1024", "projection=ortho", "split_scheme=explicit", "cascades=4",
                       "split_1=3", "split_2=12", "split_3=40"};
    const ShadowMap *m = map_with(lab, a, 8);
    CHECK(m && m->num_faces == 4 && m->view.num_cascades == 4);
    for (int i = 0; i <= 4; i++)
        CHECK_MSG(m->view.split[i] == given[i], "split %d: %g, not %g", i, m->view.split[i], given[i]);
    for (int i = 0; i < 4; i++) {
        double lo = given[i], hi = given[i + 1], max_y = 0.0;
        for (int k = 0; k < 40; k++) {
            double z = lo * pow(hi / lo, k / 39.0) * (1.0 + 1e-9 * (k == 0) - 1e-9 * (k == 39));
            AxisError e;
            CHECK(axis_error(lab_scene(lab), m, z, &e));
            CHECK_MSG(e.face == i, "depth %g uses map %d, not %d", z, e.face, i);
            max_y = fmax(max_y, e.e_y / MARGIN);
        }
        double bound = (hi - lo) / lo;
        printf("    slice [%g, %g]: max e_y %.4f, uniform closed form (b - a) / a = %.4f\n", lo, hi, max_y, bound);
        CHECK_NEAR(max_y, bound, 0.01 * bound);
    }
    const char *b[] = {"fit=body", "map_size=1024", "projection=ortho", "split_scheme=explicit", "cascades=4",
                       "split_1=5", "split_2=12", "split_3=40"};
    const ShadowMap *m5 = map_with(lab, b, 8);
    CHECK(m5 && m5 != m && m5->view.split[1] == 5.0);
    static const struct { const char *assign[4]; const char *want[2]; } refused[] = {
        {{"cascades=4", "split_1=3", "split_2=12", "split_3=0"}, {"split_3 is not given", "split_1..split_3"}},
        {{"cascades=5", "split_1=3", "split_2=12", "split_3=40"}, {"cascades 5", "[1, 4]"}},
        {{"cascades=4", "split_1=12", "split_2=3", "split_3=40"}, {"split_2 = 3", "(12, 100)"}},
        {{"cascades=4", "split_1=3", "split_2=12", "split_3=150"}, {"split_3 = 150", "(12, 100)"}},
        {{"cascades=4", "split_1=0.5", "split_2=12", "split_3=40"}, {"split_1 = 0.5", "(1, 100)"}},
        {{"cascades=2", "split_1=3", "split_2=12", "split_3=0"}, {"split_2 = 12 is given", "cascades 2"}},
        {{"cascades=1", "split_1=3", "split_2=0", "split_3=0"}, {"split_1 = 3 is given", "cascades 1"}},
    };
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        const char *c[] = {"fit=body", "map_size=64", "projection=ortho", "split_scheme=explicit", refused[k].assign[0],
                           refused[k].assign[1], refused[k].assign[2], refused[k].assign[3]};
        Error err = {{0}};
        const ShadowMap *bad = map_or_error(lab, c, 8, &err);
        printf("    %s %s %s %s: %s\n", c[4], c[5], c[6], c[7], bad ? "accepted" : err.msg);
        CHECK(!bad);
        for (int w = 0; w < 2; w++)
            CHECK_MSG(strstr(err.msg, refused[k].want[w]), "the refusal lacks '%s': %s", refused[k].want[w], err.msg);
    }
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

/* The instrument differentiates warp_log_forward, the formula this closed
 * form restates: a check of the formula's constants, not of the map that is
 * ray cast (test_aliasing_instrument.c compares the two). */
TEST(test_warp_logpsm_has_constant_error_ln_r)
{
    Lab *lab = open_plane();
    CHECK(lab);
    const char *a[] = {"fit=body", "map_size=1024", "projection=logpsm"};
    const ShadowMap *m = map_with(lab, a, 3);
    CHECK(m);
    double mx, my, dev = deviation(lab, m, psm_x, log_y, 0.0, &mx, &my);
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

/* Texel size and the texel phase of a world point in map face 0, with the
 * camera at two places (fit=body: an unstabilized map follows the view). */
typedef struct Phase { double texel[2], phase[2][2]; } Phase;

/* How far the grid moved, in texels (phases are modulo 1: 0.9999 and 0 are close). */
static double phase_shift(const Phase *p)
{
    double d = 0.0;
    for (int a = 0; a < 2; a++) {
        double x = fabs(p->phase[0][a] - p->phase[1][a]);
        d += fmin(x, 1.0 - x);
    }
    return d;
}

static bool phases(const char *light, const char *projection, bool stabilize, Phase *ph)
{
    const char *moves[] = {"camera.position={0,0,0}", "camera.position={0.37,0.05,-0.61}"};
    for (int k = 0; k < 2; k++) {
        Error err;
        const char *ov[] = {"camera.width=64", "camera.height=48", moves[k], "camera.target={0.2,0,-1}", light};
        Lab *lab = lab_open("scenes/overhead-plane.lua", ov, light ? 5 : 4, &err);
        if (!lab) { printf("    %s\n", err.msg); return false; }
        const char *a[] = {"fit=body", "map_size=1024", projection, stabilize ? "stabilize=true" : "stabilize=false"};
        const ShadowMap *m = map_with(lab, a, 4);
        if (m) {
            ph->texel[k] = (m->view.face[0].r - m->view.face[0].l) / m->res;
            MapCoord mc = lightview_locate_on(&m->view, 0, d3(0, -0.5, -30));
            ph->phase[k][0] = mc.s - floor(mc.s);
            ph->phase[k][1] = mc.t - floor(mc.t);
        }
        lab_close(lab);
        if (!m) return false;
    }
    return true;
}

/* Course §3.2.1: orientation-fixed, texel-snapped fitting keeps the texel
 * grid still in world space as the camera moves: uniform maps of a
 * directional light, and the perspective maps of a spot and a point light
 * (their window snapped in tangents at unit depth); without it the grid
 * moves. */
TEST(test_warp_stabilized_texels_stay_put_when_the_camera_moves)
{
    static const struct { const char *what, *light, *projection; } lights[] = {
        {"directional", NULL, "projection=ortho"},
        {"spot", "lights[1]={type='spot',position={0,30,-50},direction={0,-1,0},cone_angle=80}",
         "projection=perspective"},
        {"point", "lights[1]={type='point',position={0,30,-50}}", "projection=perspective"},
    };
    for (size_t k = 0; k < sizeof lights / sizeof lights[0]; k++) {
        Phase st, fr;
        CHECK(phases(lights[k].light, lights[k].projection, true, &st));
        CHECK(phases(lights[k].light, lights[k].projection, false, &fr));
        printf("    %-11s stabilized: texel %.6g -> %.6g, phase (%.4f, %.4f) -> (%.4f, %.4f); free: (%.4f, %.4f) -> "
               "(%.4f, %.4f)\n", lights[k].what, st.texel[0], st.texel[1], st.phase[0][0], st.phase[0][1],
               st.phase[1][0], st.phase[1][1], fr.phase[0][0], fr.phase[0][1], fr.phase[1][0], fr.phase[1][1]);
        CHECK_NEAR(st.texel[0], st.texel[1], 1e-12 * st.texel[0]);
        CHECK_MSG(phase_shift(&st) < 1e-6, "%s: the stabilized grid moved by %g texels", lights[k].what,
                  phase_shift(&st));
        CHECK_MSG(phase_shift(&fr) > 1e-3, "%s: the free map's grid did not move, the test would be vacuous",
                  lights[k].what);
    }
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
