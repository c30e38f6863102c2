/* test_reference.c -- the Embree ground truth against exact answers:
 * a square occluder under a rectangular light (visible fraction by polygon
 * clipping, course Eq. 1.4), 1/sqrt(N) convergence, the point-light limit of
 * a shrinking sphere light, and self-intersection at a contact. */
#include <math.h>
#include <string.h>
#include "core/mat4.h"
#include "fixtures.h"
#include "test.h"

/* Light: 2 x 1.5 rectangle at y = 4 facing down. Occluder: unit square at
 * y = 2, turned 30 degrees about Y, centred at (0.3, 2, 0.1). */
static const char *const rect_scene =
    "return {\n"
    "  camera = { position = {0, 3, 4.5}, target = {0, 0, 0}, fov = 50, width = 96, height = 96 },\n"
    "  lights = { { type = 'rect', position = {0, 4, 0}, direction = {0, -1, 0}, up = {0, 0, 1},\n"
    "               width = 2, height = 1.5 } },\n"
    "  objects = {\n"
    "    { name = 'ground', shape = 'plane', size = {8, 8} },\n"
    "    { name = 'occluder', shape = 'plane', size = {1, 1}, rotate = {0, 30, 0},\n"
    "      translate = {0.3, 2, 0.1}, receiver = false },\n"
    "  },\n"
    "}\n";

#define LIGHT_Y 4.0
#define OCC_Y 2.0
#define LIGHT_HALF_X 1.0
#define LIGHT_HALF_Z 0.75

typedef struct Poly { double x[16], z[16]; int n; } Poly;

/* Sutherland-Hodgman: keep the part of poly on the side s * (coord - bound) <= 0. */
static Poly clip(const Poly *in, int axis_x, double bound, double s)
{
    Poly out = {.n = 0};
    for (int i = 0; i < in->n; i++) {
        int j = (i + 1) % in->n;
        double a = (axis_x ? in->x[i] : in->z[i]) - bound, b = (axis_x ? in->x[j] : in->z[j]) - bound;
        bool ina = s * a <= 0, inb = s * b <= 0;
        if (ina) { out.x[out.n] = in->x[i]; out.z[out.n] = in->z[i]; out.n++; }
        if (ina != inb) {
            double t = a / (a - b);
            out.x[out.n] = in->x[i] + t * (in->x[j] - in->x[i]);
            out.z[out.n] = in->z[i] + t * (in->z[j] - in->z[i]);
            out.n++;
        }
    }
    return out;
}

static double area(const Poly *p)
{
    double a = 0;
    for (int i = 0; i < p->n; i++) {
        int j = (i + 1) % p->n;
        a += p->x[i] * p->z[j] - p->x[j] * p->z[i];
    }
    return 0.5 * fabs(a);
}

/* Exact visible fraction of the light from ground point p: 1 - area(light ∩
 * occluder projected from p onto the light's plane) / area(light). */
static double exact_visibility(vec3 p)
{
    const double th = 30.0 * M_PI / 180.0, c = cos(th), s = sin(th);
    const double corners[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    double k = (LIGHT_Y - p.y) / (OCC_Y - p.y);
    Poly q = {.n = 4};
    for (int i = 0; i < 4; i++) {
        double x = c * corners[i][0] + s * corners[i][1] + 0.3, z = -s * corners[i][0] + c * corners[i][1] + 0.1;
        q.x[i] = p.x + (x - p.x) * k;
        q.z[i] = p.z + (z - p.z) * k;
    }
    q = clip(&q, 1, LIGHT_HALF_X, 1);
    q = clip(&q, 1, -LIGHT_HALF_X, -1);
    q = clip(&q, 0, LIGHT_HALF_Z, 1);
    q = clip(&q, 0, -LIGHT_HALF_Z, -1);
    return 1.0 - area(&q) / (4.0 * LIGHT_HALF_X * LIGHT_HALF_Z);
}

static const Reference *reference(Lab *lab, int samples, SamplingPattern pattern)
{
    Error err;
    RefInfo info;
    RefRequest rq = {0, {MEASURE_VISIBILITY, samples, pattern, 7, false}, NULL};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info, &err);
    if (!ref) printf("    reference: %s\n", err.msg);
    return ref;
}

/* Against the exact answer, over the penumbra: the RMSE equals the reported
 * error, sqrt(mean se^2), within 0.75x to 1.33x, and few samples lie beyond
 * 3 standard errors (a spread of 16 batches is t-distributed with 15 degrees
 * of freedom: 0.9% beyond 3; allowed 2%). Samples whose batches all agree
 * report 0 and must lie within the lit and umbra thresholds (0.01). */
TEST(test_reference_matches_exact_rect_light)
{
    Lab *lab = fixture_lab("rect.lua", rect_scene);
    CHECK(lab);
    Error err;
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const Reference *ref = reference(lab, 1024, SAMPLING_R2);
    CHECK(vs && cls && ref);
    double sq = 0, se_sq = 0, worst_agreed = 0;
    int penumbra = 0, beyond = 0, agreed = 0;
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || vs->object[s] != 0) continue;
        double exact = exact_visibility(vs->p_world[s]);
        double e = fabs(ref->value.data[s] - exact), se = ref->std_error.data[s];
        if (se == 0) { /* every randomisation agreed: all rays lit or all blocked */
            agreed++;
            worst_agreed = fmax(worst_agreed, e);
        }
        if (exact <= 0.01 || exact >= 0.99) continue;
        penumbra++;
        sq += e * e;
        se_sq += se * se;
        beyond += e > 3 * se;
    }
    double ratio = sqrt(se_sq / sq), frac = (double)beyond / penumbra;
    printf("    %d penumbra samples: RMSE %.5f, reported %.5f (ratio %.2f), %.2f%% beyond 3 std errors; %d samples "
           "with all %d batches agreeing, max |error| %.4f\n",
           penumbra, sqrt(sq / penumbra), sqrt(se_sq / penumbra), ratio, 100 * frac, agreed, ref->batches, worst_agreed);
    CHECK_MSG(penumbra > 300, "only %d penumbra samples: the test scene lost its penumbra", penumbra);
    CHECK_MSG(ratio >= 0.75 && ratio <= 1.33, "reported error %.2fx the RMSE against the exact answer", ratio);
    CHECK_MSG(frac <= 0.02, "%.2f%% of penumbra samples beyond 3 standard errors", 100 * frac);
    CHECK_MSG(worst_agreed <= 0.01, "a sample whose batches all agree is %.4f off the exact answer", worst_agreed);
    lab_close(lab);
}

/* RMSE over the penumbra of the exact answer. */
static double penumbra_rmse(Lab *lab, int samples, SamplingPattern pattern)
{
    Error err;
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const Reference *ref = reference(lab, samples, pattern);
    if (!ref) return NAN;
    double sq = 0;
    int n = 0;
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || vs->object[s] != 0) continue;
        double exact = exact_visibility(vs->p_world[s]);
        if (exact <= 0.01 || exact >= 0.99) continue;
        double e = ref->value.data[s] - exact;
        sq += e * e;
        n++;
    }
    return sqrt(sq / n);
}

TEST(test_reference_rmse_falls_as_inverse_sqrt_n)
{
    Lab *lab = fixture_lab("rect.lua", rect_scene);
    CHECK(lab);
    /* Independent samples: RMSE ~ 1/sqrt(N), so 64 -> 1024 divides it by 4. */
    double r64 = penumbra_rmse(lab, 64, SAMPLING_RANDOM), r1024 = penumbra_rmse(lab, 1024, SAMPLING_RANDOM);
    /* Low-discrepancy samples converge at least that fast. */
    double q64 = penumbra_rmse(lab, 64, SAMPLING_R2), q1024 = penumbra_rmse(lab, 1024, SAMPLING_R2);
    printf("    random: RMSE %.5f -> %.5f (ratio %.2f); r2: %.5f -> %.5f (ratio %.2f)\n", r64, r1024, r64 / r1024, q64,
           q1024, q64 / q1024);
    CHECK_MSG(r64 / r1024 > 3.3 && r64 / r1024 < 4.8, "random-sampling RMSE ratio %.2f, expected about 4",
              r64 / r1024);
    CHECK_MSG(q64 / q1024 > 3.3, "r2 RMSE ratio %.2f, expected at least about 4", q64 / q1024);
    lab_close(lab);
}

static const char *const tiny_sphere_scene =
    "return {\n"
    "  camera = { position = {0, 3.2, 5.5}, target = {0, 0.4, 0}, width = 120, height = 90 },\n"
    "  lights = { { type = 'sphere', position = {1.5, 5, 1}, radius = 1e-6 } },\n"
    "  objects = {\n"
    "    { shape = 'plane', size = {10, 10} },\n"
    "    { shape = 'sphere', radius = 0.6, segments = 48, translate = {0, 1, 0} },\n"
    "    { shape = 'box', size = {0.5, 1, 0.5}, rotate = {0, 20, 0}, translate = {-1.2, 0.5, 0.4} },\n"
    "  },\n"
    "}\n";

TEST(test_reference_tiny_sphere_light_equals_hard)
{
    Lab *lab = fixture_lab("tiny.lua", tiny_sphere_scene);
    CHECK(lab);
    Error err;
    const Technique *hard = tech_find("hard", &err);
    CHECK(hard);
    double params[TECH_MAX_PARAMS];
    tech_params_default(hard, params);
    RenderRequest rq = {hard, params, 0, 1};
    RenderResult rr;
    CHECK_MSG(lab_render(lab, &rq, &rr, &err), "%s", err.msg);
    const Reference *ref = reference(lab, 64, SAMPLING_R2);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    CHECK(ref && cls);
    int candidates = 0, shadowed = 0, differ = 0;
    for (int s = 0; s < rr.visibility.width * rr.visibility.height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        candidates++;
        shadowed += rr.visibility.data[s] < 0.5f;
        differ += ref->value.data[s] != rr.visibility.data[s];
    }
    printf("    %d candidates, %d in hard shadow, %d differ from hard\n", candidates, shadowed, differ);
    CHECK_MSG(shadowed > 200, "only %d shadowed samples", shadowed);
    CHECK_MSG(differ == 0, "%d of %d samples differ between the R = 1e-6 reference and hard", differ, candidates);
    render_result_free(&rr);
    lab_close(lab);
}

/* A unit cube resting on the ground (bottom face at y = 0) under a point light. */
static const char *const contact_scene =
    "return {\n"
    "  camera = { position = {2.5, 2.5, 3.5}, target = {0, 0, 0}, width = 128, height = 128 },\n"
    "  lights = { { type = 'point', position = {-2, 4, -1} } },\n"
    "  objects = {\n"
    "    { shape = 'plane', size = {12, 12} },\n"
    "    { shape = 'box', size = {1, 1, 1}, translate = {0, 0.5, 0} },\n"
    "  },\n"
    "}\n";

/* Does the segment p -> q cross the cube [-0.5, 0.5] x [0, 1] x [-0.5, 0.5]? (slab test) */
static bool segment_hits_cube(vec3 p, vec3 q)
{
    double t0 = 0, t1 = 1;
    const double lo[3] = {-0.5, 0, -0.5}, hi[3] = {0.5, 1, 0.5};
    const double o[3] = {p.x, p.y, p.z}, d[3] = {q.x - p.x, q.y - p.y, q.z - p.z};
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }
    return t0 <= t1;
}

TEST(test_reference_no_self_intersection_at_contact)
{
    Lab *lab = fixture_lab("contact.lua", contact_scene);
    CHECK(lab);
    Error err;
    const ViewSamples *vs = res_view_samples(lab_resources(lab), lab_scene(lab), &err);
    const uint8_t *cls = res_classes(lab_resources(lab), lab_scene(lab), 0, &err);
    const Reference *ref = reference(lab, 1, SAMPLING_R2);
    CHECK(vs && cls && ref);
    int checked = 0, wrong = 0, near_contact = 0;
    vec3 light = v3(-2, 4, -1);
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || vs->object[s] != 0) continue;
        vec3 p = vs->p_world[s];
        /* distance to the cube's footprint; closer than 1e-3 the answer is a matter of offset */
        double dx = fmax(fabs(p.x) - 0.5, 0), dz = fmax(fabs(p.z) - 0.5, 0);
        if (sqrt(dx * dx + dz * dz) < 1e-3) continue;
        near_contact += sqrt(dx * dx + dz * dz) < 0.05;
        float exact = segment_hits_cube(p, light) ? 0.0f : 1.0f;
        wrong += ref->value.data[s] != exact;
        checked++;
    }
    printf("    %d ground samples (%d within 0.05 of the contact), %d wrong\n", checked, near_contact, wrong);
    CHECK(near_contact > 20);
    CHECK_MSG(wrong == 0, "%d ground samples disagree with the exact point-light shadow", wrong);
    lab_close(lab);
}

/* Does the segment p -> q cross triangle abc? (Moller-Trumbore in double,
 * the segment's open interior: 1e-9 < t < 1 - 1e-9) */
static bool segment_hits_triangle(dvec3 p, dvec3 q, dvec3 a, dvec3 b, dvec3 c)
{
    dvec3 d = d3_sub(q, p), e1 = d3_sub(b, a), e2 = d3_sub(c, a), h = d3_cross(d, e2);
    double det = d3_dot(e1, h);
    if (fabs(det) < 1e-15) return false;
    dvec3 s = d3_sub(p, a), qv = d3_cross(s, e1);
    double u = d3_dot(s, h) / det, v = d3_dot(d, qv) / det, t = d3_dot(e2, qv) / det;
    return u >= 0 && v >= 0 && u + v <= 1 && t > 1e-9 && t < 1 - 1e-9;
}

static bool segment_hits_objects(const Scene *sc, int first_object, dvec3 p, dvec3 q)
{
    for (int o = first_object; o < sc->num_objects; o++) {
        const Mesh *m = &sc->objects[o].mesh;
        for (int t = 0; t < m->num_triangles; t++) {
            const uint32_t *ix = &m->indices[3 * t];
            if (segment_hits_triangle(p, q, d3_from(m->positions[ix[0]]), d3_from(m->positions[ix[1]]),
                                      d3_from(m->positions[ix[2]])))
                return true;
        }
    }
    return false;
}

/* Of a GRID x GRID lattice over the rect light scaled by `scale` about its
 * centre (border included), how many points the ground point p sees, by
 * exact segment tests against the boxes (objects 1..: the ground, object 0,
 * cannot occlude its own points). */
#define CONTACT_GRID 16
static int lattice_visible(const Scene *sc, const Light *L, double scale, dvec3 p)
{
    dvec3 n = d3_from(L->direction), up = d3_from(L->up), right = d3_cross(up, n), c = d3_from(L->position);
    int seen = 0;
    for (int j = 0; j < CONTACT_GRID; j++)
        for (int i = 0; i < CONTACT_GRID; i++) {
            double x = ((double)i / (CONTACT_GRID - 1) - 0.5) * L->width * scale;
            double y = ((double)j / (CONTACT_GRID - 1) - 0.5) * L->height * scale;
            seen += !segment_hits_objects(sc, 1, p, d3_add(c, d3_add(d3_scale(right, x), d3_scale(up, y))));
        }
    return seen;
}

/* Is a box's base within r of ground point p? (8 horizontal segments 1 mm up) */
static bool near_contact(const Scene *sc, dvec3 p, double r)
{
    dvec3 lifted = d3_add(p, d3(0, 1e-3, 0));
    for (int k = 0; k < 8; k++) {
        double a = k * M_PI / 4;
        if (segment_hits_objects(sc, 1, lifted, d3_add(lifted, d3(r * cos(a), 0, r * sin(a))))) return true;
    }
    return false;
}

/* The shipped contact scene (boxes resting exactly on the floor under a
 * rect light), at a reduced view: ground samples that see the whole
 * lattice of a light 1.25x the size (a margin, so no shadow edge slips
 * between lattice points into the light) must have visibility exactly 1 (a
 * self-intersection would darken them), and those that see none of the
 * light's own lattice at most 2% (slivers between lattice points). */
TEST(test_reference_self_intersection_on_the_contact_scene)
{
    const char *ov[] = {"camera.width=160", "camera.height=120"};
    Error err;
    Lab *lab = lab_open("scenes/contact.lua", ov, 2, &err);
    CHECK_MSG(lab, "%s", err.msg);
    const Scene *sc = lab_scene(lab);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), sc, &err);
    const uint8_t *cls = res_classes(lab_resources(lab), sc, 0, &err);
    const Reference *ref = reference(lab, 256, SAMPLING_R2);
    CHECK(vs && cls && ref && sc->lights[0].kind == LIGHT_RECT && strcmp(sc->objects[0].name, "ground") == 0);
    int lit = 0, dark = 0, lit_wrong = 0, dark_wrong = 0, near = 0;
    for (int s = 0; s < vs->count; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE || vs->object[s] != 0) continue;
        dvec3 p = d3_from(vs->p_world[s]);
        float v = ref->value.data[s];
        if (lattice_visible(sc, &sc->lights[0], 1.25, p) == CONTACT_GRID * CONTACT_GRID) {
            lit++;
            lit_wrong += v != 1.0f;
            near += near_contact(sc, p, 0.1);
        } else if (lattice_visible(sc, &sc->lights[0], 1.0, p) == 0) {
            dark++;
            dark_wrong += v > 0.02f;
        }
    }
    printf("    %d fully lit ground samples (%d within 10 cm of a contact), %d below 1; %d fully shadowed, %d above 0.02\n",
           lit, near, lit_wrong, dark, dark_wrong);
    CHECK(lit > 5000 && near > 40 && dark > 200);
    CHECK_MSG(lit_wrong == 0, "%d fully lit ground samples are darkened (self-intersection)", lit_wrong);
    CHECK_MSG(dark_wrong == 0, "%d fully shadowed ground samples see the light (leaks at the contact)", dark_wrong);
    lab_close(lab);
}

/* Distance from p to triangle abc (Ericson, Real-Time Collision Detection §5.1.5). */
static double point_triangle_distance(vec3 p, vec3 a, vec3 b, vec3 c)
{
    vec3 ab = v3_sub(b, a), ac = v3_sub(c, a), n = v3_cross(ab, ac);
    double nn = v3_dot(n, n);
    if (nn <= 0) return INFINITY;
    /* inside the prism: plane distance; else nearest edge */
    vec3 ap = v3_sub(p, a);
    double u = v3_dot(v3_cross(ap, ac), n) / nn, v = v3_dot(v3_cross(ab, ap), n) / nn;
    if (u >= 0 && v >= 0 && u + v <= 1) return fabs(v3_dot(ap, n)) / sqrt(nn);
    double best = INFINITY;
    vec3 e0[3] = {a, b, c}, e1[3] = {b, c, a};
    for (int i = 0; i < 3; i++) {
        vec3 d = v3_sub(e1[i], e0[i]);
        double t = fmax(0, fmin(1, v3_dot(v3_sub(p, e0[i]), d) / fmax(v3_dot(d, d), 1e-30)));
        best = fmin(best, v3_len(v3_sub(p, v3_madd(e0[i], d, (float)t))));
    }
    return best;
}

TEST(test_view_samples_lie_on_geometry)
{
    Lab *lab = fixture_lab("tiny.lua", tiny_sphere_scene);
    CHECK(lab);
    Error err;
    const Scene *sc = lab_scene(lab);
    const ViewSamples *vs = res_view_samples(lab_resources(lab), sc, &err);
    CHECK(vs);
    double worst = 0, extent = scene_extent(sc);
    int hits = 0;
    for (int s = 0; s < vs->count; s++) {
        if (vs->object[s] < 0) continue;
        const Mesh *m = &sc->objects[vs->object[s]].mesh;
        const uint32_t *t = &m->indices[3 * vs->prim[s]];
        double d = point_triangle_distance(vs->p_world[s], m->positions[t[0]], m->positions[t[1]], m->positions[t[2]]);
        worst = fmax(worst, d);
        hits++;
    }
    printf("    %d hits, max distance to the hit triangle %.3g (extent %.3g)\n", hits, worst, extent);
    CHECK(hits > 1000);
    CHECK_MSG(worst < 1e-5 * extent, "a view sample lies %.3g from its triangle", worst);
    lab_close(lab);
}
