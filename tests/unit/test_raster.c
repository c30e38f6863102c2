/* test_raster.c -- the depth rasterizer against exact answers: coverage of a
 * grid whose shared edges run through texel centres (top-left rule: every
 * texel exactly once), a closed sphere (front and back faces each exactly
 * once), depth against an Embree ray through every texel centre for
 * orthographic, perspective (linear and post-projective) and clipped
 * views, conservative coverage, quantisation, farthest/peeled layers, the
 * dual-paraboloid mapping and triangle ids. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "fixtures.h"
#include "raster/raster.h"
#include "test.h"

/* A flat grid of n x n quads (2 triangles each) in the plane y = h, spanning
 * [x0, x0 + n s] x [z0, z0 + n s]. */
typedef struct Grid { vec3 *p; uint32_t *ix; RasterMesh mesh; } Grid;

static Grid grid_make(int n, float x0, float z0, float s, float h)
{
    Grid g;
    g.p = malloc(sizeof(vec3) * (size_t)(n + 1) * (n + 1));
    g.ix = malloc(sizeof(uint32_t) * 6 * (size_t)n * n);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) g.p[j * (n + 1) + i] = v3(x0 + i * s, h, z0 + j * s);
    uint32_t *t = g.ix;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)(n + 1), d = c + 1;
            /* CCW seen from +y (the light above): normal +y */
            *t++ = a; *t++ = c; *t++ = b;
            *t++ = b; *t++ = c; *t++ = d;
        }
    g.mesh = (RasterMesh){g.p, g.ix, (n + 1) * (n + 1), 2 * n * n};
    return g;
}

static void grid_free(Grid *g)
{
    free(g->p);
    free(g->ix);
}

/* Directional light straight down onto y = 0: map x in [-1, 1] = u, map y
 * (v) = -z, depth = 10 - y. */
static RasterView overhead_ortho(void)
{
    RasterView v = {.mapping = RASTER_PROJECTIVE, .depth_near = 0.0, .depth_far = 20.0};
    mat4 view = m4_look(d3(0, 10, 0), d3(0, -1, 0), d3(0, 0, -1));
    mat4 proj = m4_ortho(-1, 1, -1, 1, 0.0, 20.0);
    v.clip_from_world = m4_mul(&proj, &view);
    double row[4] = {0, -1, 0, 10};
    memcpy(v.depth_row, row, sizeof row);
    return v;
}

/* Render each triangle alone and count how often each texel is covered. */
static int *coverage_counts(const RasterMesh *m, const RasterView *view, RasterCull cull, int w, int h)
{
    int *count = calloc((size_t)w * h, sizeof(int));
    DepthBuffer db;
    Error err;
    if (!count || !depth_buffer_init(&db, w, h, false, &err)) return count;
    RasterOptions opt = {.cull = cull};
    for (int t = 0; t < m->num_triangles; t++) {
        RasterMesh one = {m->positions, m->indices + 3 * t, m->num_vertices, 1};
        if (!raster_depth(&one, 1, view, &opt, &db, NULL, &err)) break;
        for (int i = 0; i < w * h; i++) count[i] += isfinite(db.depth[i]);
    }
    depth_buffer_free(&db);
    return count;
}

TEST(test_raster_grid_edges_through_texel_centres_cover_each_texel_once)
{
    /* 64^2 texels over [-1, 1]^2; quads of 4 texels with corners on texel
     * corners, so every quad diagonal runs through texel centres. */
    Grid g = grid_make(12, -0.75f, -0.75f, 0.125f, 0.0f);
    RasterView v = overhead_ortho();
    int *count = coverage_counts(&g.mesh, &v, RASTER_CULL_NONE, 64, 64);
    int wrong = 0, inside = 0;
    for (int j = 0; j < 64; j++)
        for (int i = 0; i < 64; i++) {
            int want = (i >= 8 && i < 56 && j >= 8 && j < 56) ? 1 : 0;
            inside += want;
            wrong += count[j * 64 + i] != want;
        }
    printf("    %d texels inside, %d covered a wrong number of times\n", inside, wrong);
    CHECK(inside == 48 * 48);
    CHECK_MSG(wrong == 0, "%d texels missed or hit twice", wrong);
    free(count);
    grid_free(&g);
}

TEST(test_raster_back_face_culling_follows_the_winding)
{
    Grid g = grid_make(2, -0.5f, -0.5f, 0.5f, 0.0f);
    RasterView v = overhead_ortho();
    DepthBuffer db;
    Error err;
    CHECK(depth_buffer_init(&db, 32, 32, false, &err));
    RasterOptions back = {.cull = RASTER_CULL_BACK}, front = {.cull = RASTER_CULL_FRONT};
    CHECK(raster_depth(&g.mesh, 1, &v, &back, &db, NULL, &err));
    CHECK_MSG(isfinite(db.depth[16 * 32 + 16]), "a face whose normal points at the light was culled as a back face");
    CHECK(raster_depth(&g.mesh, 1, &v, &front, &db, NULL, &err));
    CHECK_MSG(!isfinite(db.depth[16 * 32 + 16]), "front-face culling kept a face pointing at the light");
    depth_buffer_free(&db);
    grid_free(&g);
}

/* A buffer's working memory is kept between renders (DepthBuffer.scratch):
 * a render after a smaller mesh's and after a larger one's (the scratch
 * grown, then reused as it is) equals a fresh buffer's. */
TEST(test_raster_reused_scratch_renders_like_a_fresh_buffer)
{
    Grid small = grid_make(2, -0.5f, -0.5f, 0.5f, 0.0f), large = grid_make(60, -0.9f, -0.9f, 0.03f, 0.5f);
    RasterView v = overhead_ortho();
    RasterOptions opt = {0};
    DepthBuffer reused, fresh;
    Error err;
    CHECK(depth_buffer_init(&reused, 200, 200, false, &err));
    const RasterMesh *order[] = {&small.mesh, &large.mesh, &small.mesh, &large.mesh};
    int differing = 0;
    for (int k = 0; k < 4; k++) {
        CHECK(raster_depth(order[k], 1, &v, &opt, &reused, NULL, &err));
        CHECK(depth_buffer_init(&fresh, 200, 200, false, &err));
        CHECK(raster_depth(order[k], 1, &v, &opt, &fresh, NULL, &err));
        differing += memcmp(reused.depth, fresh.depth, sizeof(float) * 200 * 200) != 0;
        depth_buffer_free(&fresh);
    }
    CHECK_MSG(reused.scratch != NULL, "the buffer kept no working memory");
    CHECK_MSG(differing == 0, "%d of 4 renders into a reused buffer differ from a fresh buffer's", differing);
    depth_buffer_free(&reused);
    grid_free(&small);
    grid_free(&large);
}

/* A map over RASTER_STREAM_MIN_BYTES is stored around the caches
 * (raster.c's row_store): a 4097 x 2100 map (34 MB), whose rows start on
 * 16 bytes only every fourth row (the others take the plain copy) and
 * whose last tile column is one texel wide, holds the square
 * [-0.5, 0.5]^2 at depth 10 exactly where the texel centres fall inside
 * it (none lies within a quarter texel of its edges), +inf elsewhere. */
TEST(test_raster_streamed_large_map_holds_the_square_exactly)
{
    enum { W = 4097, H = 2100 };
    CHECK((size_t)W * H * sizeof(float) > RASTER_STREAM_MIN_BYTES);
    Grid g = grid_make(2, -0.5f, -0.5f, 0.5f, 0.0f);
    RasterView v = overhead_ortho();
    RasterOptions opt = {0};
    DepthBuffer db;
    Error err;
    CHECK(depth_buffer_init(&db, W, H, false, &err));
    CHECK(raster_depth(&g.mesh, 1, &v, &opt, &db, NULL, &err));
    long wrong = 0, inside = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double u = -1.0 + (i + 0.5) * 2.0 / W, w = -1.0 + (j + 0.5) * 2.0 / H; /* texel centre, map [-1, 1]^2 */
            bool in = u > -0.5 && u < 0.5 && w > -0.5 && w < 0.5;
            float d = db.depth[(size_t)j * W + i];
            inside += in;
            wrong += in ? !(fabsf(d - 10.0f) < 1e-5f) : !(isinf(d) && d > 0.0f);
        }
    printf("    %ld texels inside, %ld wrong\n", inside, wrong);
    CHECK(inside == 2049L * 1050L);
    CHECK_MSG(wrong == 0, "%ld texels of the streamed map wrong", wrong);
    depth_buffer_free(&db);
    grid_free(&g);
}

/* Triangle order survives the parallel set-up and binning: the same grid
 * twice, coplanar (every fragment ties), split into several set-up chunks;
 * ties keep the first fragment, so every texel holds the first copy's
 * triangle, and the map and ids are bit-identical at 1 to 4 threads. */
TEST(test_raster_tied_copies_keep_input_order_at_any_thread_count)
{
    Grid g = grid_make(60, -0.9f, -0.9f, 0.03f, 0.25f); /* 7200 triangles: 4 chunks for two copies */
    RasterMesh twice[2] = {g.mesh, g.mesh};
    RasterView v = overhead_ortho();
    RasterOptions opt = {.triangle_ids = true};
    enum { W = 160, H = 120 };
    DepthBuffer db[4];
    Error err;
    int threads = omp_get_max_threads(), later_copy = 0, covered = 0, differing = 0;
    for (int k = 0; k < 4; k++) {
        CHECK(depth_buffer_init(&db[k], W, H, true, &err));
        omp_set_num_threads(k + 1);
        CHECK(raster_depth(twice, 2, &v, &opt, &db[k], NULL, &err));
    }
    omp_set_num_threads(threads);
    for (int i = 0; i < W * H; i++) {
        covered += db[0].triangle[i] >= 0;
        later_copy += db[0].triangle[i] >= g.mesh.num_triangles;
    }
    for (int k = 1; k < 4; k++)
        differing += memcmp(db[k].depth, db[0].depth, sizeof(float) * W * H) != 0 ||
                     memcmp(db[k].triangle, db[0].triangle, sizeof(int32_t) * W * H) != 0;
    CHECK_MSG(covered > W * H / 2, "only %d texels covered", covered);
    CHECK_MSG(later_copy == 0, "%d of %d texels hold the second copy's triangle (ties must keep the first)", later_copy,
              covered);
    CHECK_MSG(differing == 0, "%d of 3 thread counts render a map or ids unlike 1 thread's", differing);
    for (int k = 0; k < 4; k++) depth_buffer_free(&db[k]);
    grid_free(&g);
}

/* ---- against Embree ---------------------------------------------------- */

static const char *const scene_text =
    "return {\n"
    "  camera = { position = {0, 3, 5}, target = {0, 0, 0}, width = 16, height = 16 },\n"
    "  lights = { { type = 'point', position = {1, 4, 1} } },\n"
    "  objects = {\n"
    "    { shape = 'plane', size = {30, 30} },\n"
    "    { shape = 'sphere', radius = 0.8, segments = 40, translate = {0, 1, 0} },\n"
    "    { shape = 'box', size = {0.6, 1.5, 0.4}, rotate = {10, 35, 0}, translate = {-1.2, 0.75, 0.4} },\n"
    "    { shape = 'torus', major = 0.6, minor = 0.15, rotate = {60, 0, 20}, translate = {1.3, 0.9, -0.6} },\n"
    "  },\n"
    "}\n";

static int scene_meshes(const Scene *sc, RasterMesh *out)
{
    for (int i = 0; i < sc->num_objects; i++) {
        const Mesh *m = &sc->objects[i].mesh;
        out[i] = (RasterMesh){m->positions, m->indices, m->num_vertices, m->num_triangles};
    }
    return sc->num_objects;
}

/* Embree hit of the ray through map point (s, t) (texels; texel (i, j)'s
 * centre is (i + 1/2, j + 1/2)), from the near plane to the far plane of the
 * view; returns the hit's linear depth (NAN: miss). */
static double embree_depth_at(RTCScene rtc, const RasterView *v, const mat4 *inv, double s, double t, int w, int h,
                              int *prim_out, unsigned *geom_out)
{
    double xn = s / w * 2.0 - 1.0, yn = t / h * 2.0 - 1.0;
    dvec4 a = m4_apply4(inv, (dvec4){xn, yn, 0.0, 1.0}), b = m4_apply4(inv, (dvec4){xn, yn, 1.0, 1.0});
    dvec3 pa = d3(a.x / a.w, a.y / a.w, a.z / a.w), pb = d3(b.x / b.w, b.y / b.w, b.z / b.w);
    dvec3 d = d3_sub(pb, pa);
    double len = d3_len(d);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = (float)pa.x; rh.ray.org_y = (float)pa.y; rh.ray.org_z = (float)pa.z;
    rh.ray.dir_x = (float)(d.x / len); rh.ray.dir_y = (float)(d.y / len); rh.ray.dir_z = (float)(d.z / len);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = (float)len;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return NAN;
    if (prim_out) *prim_out = (int)rh.hit.primID;
    if (geom_out) *geom_out = rh.hit.geomID;
    dvec3 p = d3_madd(pa, d3(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z), rh.ray.tfar);
    const double *r = v->depth_row;
    return r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3];
}

static double embree_depth(RTCScene rtc, const RasterView *v, const mat4 *inv, int i, int j, int w, int h,
                           int *prim_out, unsigned *geom_out)
{
    return embree_depth_at(rtc, v, inv, i + 0.5, j + 0.5, w, h, prim_out, geom_out);
}

/* The stored value Embree gives at (s, t): linear depth, or z_ndc. */
static double embree_value(RTCScene rtc, const RasterView *v, const mat4 *inv, const RasterOptions *opt, double s,
                           double t, int w, int h)
{
    double e = embree_depth_at(rtc, v, inv, s, t, w, h, NULL, NULL);
    if (opt->depth == RASTER_DEPTH_NDC && isfinite(e)) { /* the hit's z_ndc from its linear depth */
        double n = v->depth_near, f = v->depth_far;
        e = f / (f - n) * (1.0 - n / e);
    }
    return e;
}

static bool values_agree(double d, double e, double tol)
{
    return isfinite(d) == isfinite(e) && (!isfinite(d) || fabs(d - e) <= tol);
}

/* An edge texel's value is explained by snapping when Embree gives it at
 * some point within SNAP_REACH texels of the centre (vertices snap to 1/256
 * texel; Embree intersects in float32): a miss at one of the square's 9
 * points for an empty texel, else a value between the smallest and largest
 * of the surface's values there (continuity across the square), +- tol. */
#define SNAP_REACH (2.0 / (1 << RASTER_SUBPIXEL_BITS))
static bool explained_by_snapping(RTCScene rtc, const RasterView *v, const mat4 *inv, const RasterOptions *opt,
                                  int i, int j, int w, int h, double d, double tol)
{
    double lo = INFINITY, hi = -INFINITY;
    bool miss = false;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
            double e = embree_value(rtc, v, inv, opt, i + 0.5 + di * SNAP_REACH, j + 0.5 + dj * SNAP_REACH, w, h);
            miss |= !isfinite(e);
            if (isfinite(e)) lo = fmin(lo, e), hi = fmax(hi, e);
        }
    return isfinite(d) ? d >= lo - tol && d <= hi + tol : miss;
}

/* A texel at a depth discontinuity of the map (a second difference along x
 * or y above `jump`: planes give none) or next to an empty texel:
 * silhouettes are excluded from the comparisons. */
static bool near_edge(const DepthBuffer *db, int i, int j, double jump)
{
    if (i < 1 || j < 1 || i + 1 >= db->width || j + 1 >= db->height) return true;
    const float *d = db->depth + (size_t)j * db->width + i;
    int w = db->width;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++)
            if (!isfinite(d[dj * w + di])) return true;
    double dxx = d[-1] - 2.0 * d[0] + d[1], dyy = d[-w] - 2.0 * d[0] + d[w];
    return fabs(dxx) > jump || fabs(dyy) > jump;
}

/* Interior texels must agree with the ray through their centre (within
 * tol). Edge texels (near_edge) are compared too: where one disagrees with
 * its centre's ray, the value must be Embree's a snapping distance away
 * (explained_by_snapping); edge_snapped counts those, edge_wrong the rest,
 * which must be none. */
typedef struct Agreement {
    int compared, depth_wrong, coverage_wrong, edge, edge_snapped, edge_wrong;
    double worst;
} Agreement;

static Agreement compare_with_embree(Lab *lab, const RasterView *v, const RasterOptions *opt, int w, int h,
                                     double tol)
{
    Agreement ag = {0};
    Error err;
    const Scene *sc = lab_scene(lab);
    const RtScene *bvh = res_bvh(lab_resources(lab), sc, RT_ALL_OBJECTS, &err);
    RasterMesh meshes[16];
    int nm = scene_meshes(sc, meshes);
    DepthBuffer db;
    mat4 inv;
    if (!bvh || !depth_buffer_init(&db, w, h, false, &err) || !m4_invert(&v->clip_from_world, &inv)) {
        ag.depth_wrong = -1;
        return ag;
    }
    if (!raster_depth(meshes, nm, v, opt, &db, NULL, &err)) {
        printf("    raster: %s\n", err.msg);
        ag.depth_wrong = -1;
        depth_buffer_free(&db);
        return ag;
    }
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            double d = db.depth[(size_t)j * w + i];
            RTCScene rtc = rt_scene_handle(bvh);
            double e = embree_value(rtc, v, &inv, opt, i + 0.5, j + 0.5, w, h);
            if (near_edge(&db, i, j, 50 * tol)) {
                ag.edge++;
                if (values_agree(d, e, tol)) continue;
                if (explained_by_snapping(rtc, v, &inv, opt, i, j, w, h, d, tol)) ag.edge_snapped++;
                else ag.edge_wrong++;
                continue;
            }
            ag.compared++;
            if (isfinite(d) != isfinite(e)) { ag.coverage_wrong++; continue; }
            if (!isfinite(d)) continue;
            ag.worst = fmax(ag.worst, fabs(d - e));
            ag.depth_wrong += fabs(d - e) > tol;
        }
    depth_buffer_free(&db);
    printf("    %d interior texels: %d coverage and %d depth disagreements, worst |diff| %.3g; "
           "%d edge texels: %d agree only within %.3g texel, %d disagree\n",
           ag.compared, ag.coverage_wrong, ag.depth_wrong, ag.worst, ag.edge, ag.edge_snapped, SNAP_REACH,
           ag.edge_wrong);
    return ag;
}

static RasterView spot_view(double near, double far)
{
    RasterView v = {.mapping = RASTER_PROJECTIVE, .depth_near = near, .depth_far = far};
    dvec3 eye = d3(1, 4, 1), fwd = d3_normalize_or(d3_sub(d3(0, 0.5, 0), eye), d3(0, -1, 0));
    mat4 view = m4_look(eye, fwd, d3(0, 1, 0));
    double t = tan(35.0 * M_PI / 180.0) * near;
    mat4 proj = m4_frustum(-t, t, -t, t, near, far);
    v.clip_from_world = m4_mul(&proj, &view);
    /* linear depth = -z_view = the third row of the view matrix, negated */
    for (int k = 0; k < 4; k++) v.depth_row[k] = -view.m[2][k];
    return v;
}

TEST(test_raster_depth_matches_embree_perspective_linear)
{
    Lab *lab = fixture_lab("r.lua", scene_text);
    CHECK(lab);
    RasterView v = spot_view(0.5, 12.0);
    RasterOptions opt = {.depth = RASTER_DEPTH_LINEAR};
    Agreement ag = compare_with_embree(lab, &v, &opt, 256, 256, 2e-4);
    CHECK(ag.compared > 40000);
    CHECK_MSG(ag.coverage_wrong == 0 && ag.depth_wrong == 0, "see the counts above");
    CHECK_MSG(ag.edge_wrong == 0, "%d edge texels disagree beyond the snapping distance", ag.edge_wrong);
    lab_close(lab);
}

TEST(test_raster_depth_matches_embree_post_projective)
{
    Lab *lab = fixture_lab("r.lua", scene_text);
    CHECK(lab);
    RasterView v = spot_view(0.5, 12.0);
    RasterOptions opt = {.depth = RASTER_DEPTH_NDC};
    Agreement ag = compare_with_embree(lab, &v, &opt, 200, 160, 1e-5);
    CHECK(ag.compared > 20000);
    CHECK_MSG(ag.coverage_wrong == 0 && ag.depth_wrong == 0, "see the counts above");
    CHECK_MSG(ag.edge_wrong == 0, "%d edge texels disagree beyond the snapping distance", ag.edge_wrong);
    lab_close(lab);
}

TEST(test_raster_depth_matches_embree_orthographic_and_clipped)
{
    Lab *lab = fixture_lab("r.lua", scene_text);
    CHECK(lab);
    /* a tilted directional light whose box cuts the ground plane on all
     * four sides and the sphere at the near plane */
    RasterView v = {.mapping = RASTER_PROJECTIVE, .depth_near = 0.0, .depth_far = 10.0};
    dvec3 eye = d3(0.3, 2.6, 0.9), fwd = d3_normalize_or(d3(-0.3, -1.0, -0.45), d3(0, -1, 0));
    mat4 view = m4_look(eye, fwd, d3(0, 1, 0));
    mat4 proj = m4_ortho(-2.5, 2.0, -1.8, 2.2, 0.0, 10.0);
    v.clip_from_world = m4_mul(&proj, &view);
    for (int k = 0; k < 4; k++) v.depth_row[k] = -view.m[2][k];
    RasterOptions opt = {.depth = RASTER_DEPTH_LINEAR};
    Agreement ag = compare_with_embree(lab, &v, &opt, 300, 260, 2e-4);
    CHECK(ag.compared > 50000);
    CHECK_MSG(ag.coverage_wrong == 0 && ag.depth_wrong == 0, "see the counts above");
    CHECK_MSG(ag.edge_wrong == 0, "%d edge texels disagree beyond the snapping distance", ag.edge_wrong);
    lab_close(lab);
}

TEST(test_raster_closed_sphere_front_and_back_faces_each_once)
{
    Lab *lab = fixture_lab("r.lua", scene_text);
    CHECK(lab);
    const Mesh *m = &lab_scene(lab)->objects[1].mesh;
    RasterMesh mesh = {m->positions, m->indices, m->num_vertices, m->num_triangles};
    RasterView v = spot_view(0.5, 12.0);
    int w = 48, h = 48;
    int *front = coverage_counts(&mesh, &v, RASTER_CULL_BACK, w, h);
    int *back = coverage_counts(&mesh, &v, RASTER_CULL_FRONT, w, h);
    CHECK(front && back);
    int covered = 0, bad = 0;
    for (int i = 0; i < w * h; i++) {
        covered += front[i] == 1;
        bad += front[i] > 1 || back[i] > 1 || front[i] != back[i];
    }
    printf("    %d texels inside the silhouette, %d hit twice or unmatched\n", covered, bad);
    CHECK(covered > 100);
    CHECK_MSG(bad == 0, "%d texels", bad);
    free(front);
    free(back);
    lab_close(lab);
}

TEST(test_raster_triangle_ids_match_embree_primitives)
{
    Lab *lab = fixture_lab("r.lua", scene_text);
    CHECK(lab);
    Error err;
    const Scene *sc = lab_scene(lab);
    const RtScene *bvh = res_bvh(lab_resources(lab), sc, RT_ALL_OBJECTS, &err);
    RasterMesh meshes[16];
    int nm = scene_meshes(sc, meshes);
    RasterView v = spot_view(0.5, 12.0);
    DepthBuffer db;
    mat4 inv;
    CHECK(bvh && m4_invert(&v.clip_from_world, &inv) && depth_buffer_init(&db, 128, 128, true, &err));
    RasterOptions opt = {.triangle_ids = true};
    CHECK(raster_depth(meshes, nm, &v, &opt, &db, NULL, &err));
    int checked = 0, wrong = 0;
    for (int j = 1; j < 127; j++)
        for (int i = 1; i < 127; i++) {
            if (near_edge(&db, i, j, 4e-3)) continue;
            int prim;
            unsigned geom;
            if (!isfinite(embree_depth(rt_scene_handle(bvh), &v, &inv, i, j, 128, 128, &prim, &geom))) continue;
            int obj = rt_scene_object(bvh, geom), base = 0;
            for (int k = 0; k < obj; k++) base += meshes[k].num_triangles;
            checked++;
            wrong += db.triangle[j * 128 + i] != base + prim;
        }
    printf("    %d interior texels, %d with another triangle id than Embree's\n", checked, wrong);
    CHECK(checked > 5000);
    CHECK(wrong <= checked / 200); /* texel centres within float noise of an interior edge */
    depth_buffer_free(&db);
    lab_close(lab);
}

TEST(test_raster_conservative_covers_every_touched_texel)
{
    /* a thin sliver: standard coverage misses texels it crosses */
    const vec3 p[3] = {v3(-0.8f, 0, 0.71f), v3(0.77f, 0, -0.64f), v3(0.79f, 0, -0.60f)};
    const uint32_t ix[3] = {0, 2, 1};
    RasterMesh m = {p, ix, 3, 1};
    RasterView v = overhead_ortho();
    DepthBuffer plain, cons;
    Error err;
    CHECK(depth_buffer_init(&plain, 40, 40, false, &err) && depth_buffer_init(&cons, 40, 40, false, &err));
    RasterOptions o1 = {0}, o2 = {.conservative = true};
    CHECK(raster_depth(&m, 1, &v, &o1, &plain, NULL, &err) && raster_depth(&m, 1, &v, &o2, &cons, NULL, &err));
    int touched = 0, missed = 0, lost = 0, n_plain = 0;
    for (int j = 0; j < 40; j++)
        for (int i = 0; i < 40; i++) {
            bool hit = false; /* 16x16 probes inside the texel square against the triangle */
            for (int b = 0; b < 16 && !hit; b++)
                for (int a = 0; a < 16 && !hit; a++) {
                    double x = -1 + (i + (a + 0.5) / 16) / 20.0, y = -1 + (j + (b + 0.5) / 16) / 20.0;
                    double e[3]; /* edge functions in map space, where a vertex p sits at (p.x, -p.z) */
                    for (int k = 0; k < 3; k++) {
                        vec3 s = p[ix[k]], t = p[ix[(k + 1) % 3]];
                        e[k] = (t.x - s.x) * (y + s.z) - (s.z - t.z) * (x - s.x);
                    }
                    hit = (e[0] >= 0 && e[1] >= 0 && e[2] >= 0) || (e[0] <= 0 && e[1] <= 0 && e[2] <= 0);
                }
            bool c = isfinite(cons.depth[j * 40 + i]), q = isfinite(plain.depth[j * 40 + i]);
            touched += hit;
            missed += hit && !c;
            lost += q && !c;
            n_plain += q;
        }
    printf("    %d texels touched, %d by plain coverage; conservative missed %d\n", touched, n_plain, missed);
    CHECK(touched > n_plain);
    CHECK(missed == 0 && lost == 0);
    depth_buffer_free(&plain);
    depth_buffer_free(&cons);
}

TEST(test_raster_layers_quantisation_and_paraboloid)
{
    /* three stacked grids under an overhead light: nearest, farthest, peeled */
    Grid g[3] = {grid_make(4, -0.6f, -0.6f, 0.3f, 0.5f), grid_make(4, -0.6f, -0.6f, 0.3f, 0.25f),
                 grid_make(4, -0.6f, -0.6f, 0.3f, 0.0f)};
    RasterMesh m[3] = {g[0].mesh, g[1].mesh, g[2].mesh};
    RasterView v = overhead_ortho();
    DepthBuffer first, other;
    Error err;
    CHECK(depth_buffer_init(&first, 32, 32, false, &err) && depth_buffer_init(&other, 32, 32, false, &err));
    RasterOptions near = {0}, far = {.test = RASTER_FARTHEST}, q16 = {.depth_bits = 16};
    CHECK(raster_depth(m, 3, &v, &near, &first, NULL, &err));
    CHECK_NEAR(first.depth[16 * 32 + 16], 9.5, 1e-5);
    CHECK(raster_depth(m, 3, &v, &far, &other, NULL, &err));
    CHECK_NEAR(other.depth[16 * 32 + 16], 10.0, 1e-5);
    RasterOptions peel = {.peel = first.depth};
    CHECK(raster_depth(m, 3, &v, &peel, &other, NULL, &err));
    CHECK_NEAR(other.depth[16 * 32 + 16], 9.75, 1e-5);
    CHECK(raster_depth(m, 3, &v, &q16, &other, NULL, &err));
    double step = 20.0 / 65535.0, d = other.depth[16 * 32 + 16];
    CHECK_NEAR(d / step, round(d / step), 1e-2);
    CHECK(fabs(d - 9.5) <= step);
    for (int k = 0; k < 3; k++) grid_free(&g[k]);
    depth_buffer_free(&first);
    depth_buffer_free(&other);

    /* a tessellated sphere of radius 2 around a paraboloid map's centre */
    Lab *lab = fixture_lab("p.lua", "return { camera = { position = {0, 0, 9}, target = {0, 0, 0} },\n"
                                    "  lights = { { type = 'point', position = {0, 0, 0} } },\n"
                                    "  objects = { { shape = 'sphere', radius = 2, segments = 96 } } }\n");
    CHECK(lab);
    const Mesh *sm = &lab_scene(lab)->objects[0].mesh;
    RasterMesh sph = {sm->positions, sm->indices, sm->num_vertices, sm->num_triangles};
    RasterView pv = {.mapping = RASTER_PARABOLOID, .depth_near = 0.0, .depth_far = 4.0};
    pv.clip_from_world = m4_look(d3(0, 0, 0), d3(0, -1, 0), d3(0, 0, 1)); /* front hemisphere: -y */
    DepthBuffer pb;
    CHECK(depth_buffer_init(&pb, 64, 64, false, &err));
    CHECK(raster_depth(&sph, 1, &pv, &near, &pb, NULL, &err));
    int inside_ok = 0, inside = 0, outside_empty = 0, outside = 0;
    for (int j = 0; j < 64; j++)
        for (int i = 0; i < 64; i++) {
            double x = (i + 0.5) / 32 - 1, y = (j + 0.5) / 32 - 1, r = sqrt(x * x + y * y);
            float dd = pb.depth[j * 64 + i];
            if (r < 0.93) { inside++; inside_ok += dd > 1.97f && dd <= 2.0001f; }
            if (r > 1.03) { outside++; outside_empty += !isfinite(dd); }
        }
    printf("    paraboloid: %d/%d inside texels at radius 2, %d/%d outside the disc empty\n", inside_ok, inside,
           outside_empty, outside);
    CHECK(inside_ok == inside && outside_empty == outside);
    depth_buffer_free(&pb);
    lab_close(lab);
}
