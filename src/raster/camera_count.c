/* camera_count.c -- the camera's counting pass (see camera_count.h). */
#include "raster/camera_count.h"
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* World -> clip: x = right.(p - e h) / tan_x, y = up.(p - e h) / tan_y,
 * z = n h, w = forward.(p - e h) = d h, so x/w, y/w are the grid's NDC
 * (camera_axes) and z/w = n / d. */
static mat4 camera_clip_from_world(const Camera *cam, int w, int h)
{
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, w, h, &f, &r, &u, &tx, &ty);
    dvec3 e = d3_from(cam->position), df = d3_from(f), dr = d3_scale(d3_from(r), 1.0 / tx),
          du = d3_scale(d3_from(u), 1.0 / ty);
    return (mat4){{{dr.x, dr.y, dr.z, -d3_dot(dr, e)},
                   {du.x, du.y, du.z, -d3_dot(du, e)},
                   {0.0, 0.0, 0.0, cam->near_dist},
                   {df.x, df.y, df.z, -d3_dot(df, e)}}};
}

bool camera_count_init(CameraCount *cc, const Camera *cam, const ViewSamples *vs, const float *test_depth, Error *err)
{
    memset(cc, 0, sizeof *cc);
    if (!(cam->near_dist > 0.0f)) return error_set(err, "camera near = %g: the counting pass needs near > 0", cam->near_dist);
    size_t n = (size_t)vs->count;
    cc->width = vs->width;
    cc->height = vs->height;
    cc->ref = malloc(n * sizeof *cc->ref);
    cc->count = calloc(n, sizeof *cc->count);
    if (!cc->ref || !cc->count) {
        camera_count_free(cc);
        return error_set(err, "out of memory for %dx%d shadow-volume counters", vs->width, vs->height);
    }
    for (int s = 0; s < vs->count; s++) {
        int x = s % vs->width, y = s / vs->width;
        float d = test_depth[s];
        cc->ref[(size_t)(vs->height - 1 - y) * (size_t)vs->width + (size_t)x] =
            d > 0.0f && isfinite(d) ? cam->near_dist / d : 0.0f; /* n / d; 0: at infinity */
    }
    cc->view = (RasterView){.mapping = RASTER_PROJECTIVE,
                            .clip_from_world = camera_clip_from_world(cam, vs->width, vs->height),
                            .depth_near = cam->near_dist,
                            .depth_far = INFINITY};
    cc->db = (DepthBuffer){.width = vs->width, .height = vs->height};
    return true;
}

void camera_count_free(CameraCount *cc)
{
    free(cc->ref);
    free(cc->count);
    raster_scratch_free(cc->db.scratch);
    memset(cc, 0, sizeof *cc);
}

bool camera_count_render(CameraCount *cc, const RasterMesh *meshes, const RasterMeshExtra *extra, int num_meshes,
                         CountTest test, RasterStats *stats, Error *err)
{
    /* z_ndc = n / d grows toward the camera: nearer is greater */
    RasterOptions opt = {.cull = RASTER_CULL_NONE,
                         .test = test == COUNT_NEARER ? RASTER_COUNT_GREATER : RASTER_COUNT_LESS,
                         .depth = RASTER_DEPTH_NDC,
                         .count_ref = cc->ref,
                         .count = cc->count,
                         .extra = extra};
    return raster_depth(meshes, num_meshes, &cc->view, &opt, &cc->db, stats, err);
}

/* Clip from world for the near caps: the camera's rows 0, 1 and 3 after
 * Blinn's shadow matrix S = (pi.L) I - L pi^T, which takes x along the line
 * from L onto the near plane pi (pi.x = f.x - f.e - n); row 2 is
 * C n (pi.x). Then w = n (pi.L - pi.x) for a point light, and 0 <= z <= w
 * keeps the slab 0 <= pi.x <= pi.L / (1 + C): the parts between the centre
 * and the near plane (with C = 1e-9, all but a 1e-9 sliver at the centre).
 * The rows are negated when pi.L < 0, so the slab is [pi.L, 0] and w > 0. */
#define NEAR_CAP_SLAB 1e-9
static mat4 near_cap_clip_from_world(const CameraCount *cc, const Camera *cam, const double L[4], double *pi_L)
{
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, cc->width, cc->height, &f, &r, &u, &tx, &ty);
    double pi[4] = {f.x, f.y, f.z,
                    -(f.x * (double)cam->position.x + f.y * (double)cam->position.y + f.z * (double)cam->position.z) -
                        cam->near_dist};
    *pi_L = pi[0] * L[0] + pi[1] * L[1] + pi[2] * L[2] + pi[3] * L[3];
    mat4 S;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) S.m[i][j] = (i == j ? *pi_L : 0.0) - L[i] * pi[j];
    mat4 M = m4_mul(&cc->view.clip_from_world, &S);
    double sign = *pi_L < 0.0 ? -1.0 : 1.0;
    for (int j = 0; j < 4; j++) M.m[2][j] = NEAR_CAP_SLAB * cam->near_dist * pi[j];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) M.m[i][j] *= sign;
    return M;
}

bool camera_count_near_caps(CameraCount *cc, const Camera *cam, const RasterMesh *caps, const RasterMeshExtra *extra,
                            const double L[4], RasterStats *stats, Error *err)
{
    double pi_L;
    RasterView view = cc->view;
    view.clip_from_world = near_cap_clip_from_world(cc, cam, L, &pi_L);
    if (stats) memset(stats, 0, sizeof *stats);
    if (pi_L == 0.0) return true;
    size_t n = (size_t)cc->width * (size_t)cc->height;
    float *all = malloc(n * sizeof *all);
    int32_t *count = calloc(n, sizeof *count);
    if (!all || !count) {
        free(all);
        free(count);
        return error_set(err, "out of memory for %dx%d near-cap counters", cc->width, cc->height);
    }
    for (size_t i = 0; i < n; i++) all[i] = -1.0f; /* below every z_ndc >= 0: each fragment counts */
    RasterOptions opt = {.cull = RASTER_CULL_NONE, .test = RASTER_COUNT_GREATER, .depth = RASTER_DEPTH_NDC,
                         .count_ref = all, .count = count, .extra = extra};
    bool ok = raster_depth(caps, 1, &view, &opt, &cc->db, stats, err);
    /* A cap turned toward L, projected from L, keeps its orientation seen
     * from L's side of the plane: counter-clockwise from the camera when L
     * is on the camera's side (pi.L < 0), clockwise otherwise. */
    int32_t sign = pi_L < 0.0 ? 1 : -1;
    for (size_t i = 0; ok && i < n; i++) {
        int64_t c = (int64_t)cc->count[i] + (int64_t)sign * count[i];
        if (c > INT32_MAX || c < INT32_MIN) ok = error_set(err, "ZP+: a near-plane count leaves int32");
        else cc->count[i] = (int32_t)c;
    }
    free(all);
    free(count);
    return ok;
}

/* ---- per-sample lists ----------------------------------------------------------- */

void camera_lists_free(CameraLists *l)
{
    free(l->start);
    free(l->item);
    memset(l, 0, sizeof *l);
}

/* The texel box (raster rows) a polygon's fragments can reach: its vertices'
 * projections, a texel beyond; the whole grid when one is not in front. */
static void texel_box(const CameraCount *cc, const vec3 *v, int n, int box[4])
{
    const mat4 *M = &cc->view.clip_from_world;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < n; k++) {
        double p[4] = {v[k].x, v[k].y, v[k].z, 1.0}, c[4] = {0.0, 0.0, 0.0, 0.0};
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) c[i] += M->m[i][j] * p[j];
        if (!(c[3] > 0.0)) {
            lo[0] = lo[1] = -INFINITY;
            hi[0] = hi[1] = INFINITY;
            break;
        }
        for (int a = 0; a < 2; a++) {
            double t = (c[a] / c[3] + 1.0) * 0.5 * (a ? cc->height : cc->width); /* texels from the grid's edge */
            lo[a] = t < lo[a] ? t : lo[a];
            hi[a] = t > hi[a] ? t : hi[a];
        }
    }
    int size[2] = {cc->width, cc->height};
    for (int a = 0; a < 2; a++) {
        box[a] = lo[a] > 1.0 ? (int)floor(lo[a]) - 1 : 0;
        box[2 + a] = hi[a] < size[a] - 2.0 ? (int)ceil(hi[a]) + 1 : size[a] - 1;
    }
}

typedef struct Pairs {
    int32_t *sample, *item;
    long n, cap;
} Pairs;

static bool pairs_push(Pairs *p, int32_t sample, int32_t item, Error *err)
{
    if (p->n == CAMERA_LISTS_MAX)
        return error_set(err, "camera lists: over %ld entries (%ld MiB): fewer view samples or casters' edges",
                         (long)CAMERA_LISTS_MAX, (long)(CAMERA_LISTS_MAX * 12 >> 20));
    if (p->n == p->cap) {
        long cap = p->cap ? 2 * p->cap : 4096;
        int32_t *s = realloc(p->sample, sizeof *s * (size_t)cap);
        if (s) p->sample = s;
        int32_t *i = s ? realloc(p->item, sizeof *i * (size_t)cap) : NULL;
        if (!i) return error_set(err, "out of memory for %ld camera-list entries", cap);
        p->item = i;
        p->cap = cap;
    }
    p->sample[p->n] = sample;
    p->item[p->n++] = item;
    return true;
}

/* Whether the polygon turns clockwise on the grid (its projection's signed
 * area, vertices in front of the camera; false when one is not). */
static bool clockwise_on_grid(const CameraCount *cc, const vec3 *v, int n)
{
    const mat4 *M = &cc->view.clip_from_world;
    double x[CAMERA_POLY_MAX], y[CAMERA_POLY_MAX], area = 0.0;
    for (int k = 0; k < n; k++) {
        double c[4] = {0.0, 0.0, 0.0, 0.0}, p[4] = {v[k].x, v[k].y, v[k].z, 1.0};
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) c[i] += M->m[i][j] * p[j];
        if (!(c[3] > 0.0)) return false;
        x[k] = c[0] / c[3];
        y[k] = c[1] / c[3];
    }
    for (int k = 0; k < n; k++) area += x[k] * y[(k + 1) % n] - x[(k + 1) % n] * y[k];
    return area < 0.0;
}

/* Polygons drawn per render: polygon k of a batch adds 2^k (RasterMeshExtra
 * counts are int16), so a texel's counter holds the set of the batch's
 * polygons covering it (each covers a texel centre at most once, the
 * rasterizer's top-left rule, and is drawn counter-clockwise). */
#define LIST_BATCH 15

/* Render polygons first[0 .. n) into the zeroed counters `hit`, then move
 * each one's texels from `hit` (clearing its bit) into the pairs. */
static bool list_batch(CameraCount *cc, const vec3 *verts, const int *first, int n, int32_t id0,
                       const RasterOptions *opt, int32_t *hit, Pairs *pairs, RasterStats *stats, Error *err)
{
    uint32_t idx[3 * LIST_BATCH * (CAMERA_POLY_MAX - 2)];
    int16_t bit[LIST_BATCH * (CAMERA_POLY_MAX - 2)];
    int nt = 0, v0 = first[0];
    for (int k = 0; k < n; k++) {
        int ccw = clockwise_on_grid(cc, verts + first[k], first[k + 1] - first[k]) ? 0 : 1;
        for (int j = first[k] + 1; j + 1 < first[k + 1]; j++, nt++) {
            idx[3 * nt] = (uint32_t)(first[k] - v0);
            idx[3 * nt + 1] = (uint32_t)(j + 1 - ccw - v0);
            idx[3 * nt + 2] = (uint32_t)(j + ccw - v0);
            bit[nt] = (int16_t)(1 << k);
        }
    }
    RasterMesh mesh = {verts + v0, idx, first[n] - v0, nt};
    RasterMeshExtra extra = {NULL, bit};
    RasterOptions o = *opt;
    o.extra = &extra;
    RasterStats st;
    if (!raster_depth(&mesh, 1, &cc->view, &o, &cc->db, &st, err)) return false;
    stats->triangles_in += st.triangles_in;
    stats->triangles_clipped += st.triangles_clipped;
    stats->triangles_drawn += st.triangles_drawn;
    stats->texels_written += st.texels_written;
    for (int k = 0; k < n && st.texels_written > 0; k++) {
        if (first[k + 1] == first[k]) continue;
        int box[4];
        int32_t b = 1 << k;
        texel_box(cc, verts + first[k], first[k + 1] - first[k], box);
        for (int j = box[1]; j <= box[3]; j++)
            for (int i = box[0]; i <= box[2]; i++) {
                size_t t = (size_t)j * (size_t)cc->width + (size_t)i;
                if (!(hit[t] & b)) continue;
                hit[t] &= ~b;
                if (!pairs_push(pairs, (cc->height - 1 - j) * cc->width + i, id0 + k, err)) return false;
            }
    }
    return true;
}

bool camera_count_lists(CameraCount *cc, const vec3 *verts, const int *first, int num_polys, CountTest test,
                        CameraLists *out, RasterStats *stats, Error *err)
{
    int ns = cc->width * cc->height;
    memset(out, 0, sizeof *out);
    memset(stats, 0, sizeof *stats);
    int32_t *hit = calloc((size_t)ns, sizeof *hit);
    out->start = calloc((size_t)ns + 1, sizeof *out->start);
    if (!hit || !out->start) {
        free(hit);
        camera_lists_free(out);
        return error_set(err, "out of memory for %dx%d camera lists", cc->width, cc->height);
    }
    out->num_samples = ns;
    RasterOptions opt = {.cull = RASTER_CULL_NONE,
                         .test = test == COUNT_NEARER ? RASTER_COUNT_GREATER : RASTER_COUNT_LESS,
                         .depth = RASTER_DEPTH_NDC,
                         .count_ref = cc->ref,
                         .count = hit};
    Pairs pairs = {0};
    bool ok = true;
    /* the batches are small renders (a few thousand texels): on one thread,
     * each skips the rasterizer's four parallel regions, whose start and
     * barriers cost more than the fill on a loaded machine (bunny, 160x120,
     * 2 threads at load 4: 2.1 s of lists against 0.3 s on one) */
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    for (int i = 0; ok && i < num_polys; i++) {
        int n = first[i + 1] - first[i];
        if (n != 0 && (n < 3 || n > CAMERA_POLY_MAX))
            ok = error_set(err, "camera lists: polygon %d has %d vertices (0, or 3 to %d)", i, n, CAMERA_POLY_MAX);
    }
    for (int i = 0; ok && i < num_polys; i += LIST_BATCH) {
        int n = num_polys - i < LIST_BATCH ? num_polys - i : LIST_BATCH;
        ok = list_batch(cc, verts, first + i, n, i, &opt, hit, &pairs, stats, err);
    }
    omp_set_num_threads(threads);
    /* counting sort by sample, stable: the pairs come in item order */
    out->item = ok ? malloc(sizeof *out->item * (size_t)(pairs.n ? pairs.n : 1)) : NULL;
    if (ok && !out->item) ok = error_set(err, "out of memory for %ld camera-list entries", pairs.n);
    if (ok) {
        for (long k = 0; k < pairs.n; k++) out->start[pairs.sample[k] + 1]++;
        for (int s = 0; s < ns; s++) out->start[s + 1] += out->start[s];
    }
    long *fill = ok ? malloc(sizeof *fill * (size_t)ns) : NULL;
    if (ok && !fill) ok = error_set(err, "out of memory for %dx%d camera lists", cc->width, cc->height);
    if (ok) {
        memcpy(fill, out->start, sizeof *fill * (size_t)ns);
        for (long k = 0; k < pairs.n; k++) out->item[fill[pairs.sample[k]]++] = pairs.item[k];
    }
    free(fill);
    free(hit);
    free(pairs.sample);
    free(pairs.item);
    if (!ok) camera_lists_free(out);
    return ok;
}

/* ---- stand-in polygons ------------------------------------------------------------ */

typedef struct Q2 { double x, y; } Q2;

static double turn(Q2 o, Q2 a, Q2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

static int by_x_then_y(const void *pa, const void *pb)
{
    const Q2 *a = pa, *b = pb;
    return a->x < b->x ? -1 : a->x > b->x ? 1 : a->y < b->y ? -1 : a->y > b->y ? 1 : 0;
}

/* Andrew's monotone chain: the counter-clockwise hull of p[0 .. n) into h
 * (room for n + 1), collinear points dropped; returns its size. */
static int hull_2d(Q2 *p, int n, Q2 *h)
{
    qsort(p, (size_t)n, sizeof *p, by_x_then_y);
    int k = 0;
    for (int i = 0; i < n; i++) {
        while (k >= 2 && turn(h[k - 2], h[k - 1], p[i]) <= 0.0) k--;
        h[k++] = p[i];
    }
    for (int i = n - 2, lower = k + 1; i >= 0; i--) {
        while (k >= lower && turn(h[k - 2], h[k - 1], p[i]) <= 0.0) k--;
        h[k++] = p[i];
    }
    return k > 1 ? k - 1 : k;
}

/* Keep the part of the convex polygon where s * (axis coordinate) <= lim. */
static int clip_axis(Q2 *poly, int n, int axis, double s, double lim)
{
    Q2 out[CAMERA_POLY_MAX];
    int m = 0;
    for (int i = 0; i < n; i++) {
        Q2 a = poly[i], b = poly[(i + 1) % n];
        double da = lim - s * (axis ? a.y : a.x), db = lim - s * (axis ? b.y : b.x);
        if (da >= 0.0 && m < CAMERA_POLY_MAX) out[m++] = a;
        if ((da >= 0.0) != (db >= 0.0) && m < CAMERA_POLY_MAX) {
            double t = da / (da - db); /* opposite signs: da != db */
            out[m++] = (Q2){a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
        }
    }
    memcpy(poly, out, sizeof *poly * (size_t)m);
    return m;
}

#define STAND_IN_GEN_MAX 24 /* its hull, a texel wider (+4) and clipped to the grid (+4): CAMERA_POLY_MAX */
#define STAND_IN_NEARER 1e-4 /* the polygon's depth below the nearest point's, relative: past float's rounding of n / d */
bool camera_count_stand_in(const CameraCount *cc, const Camera *cam, const double (*gen)[4], int num_gen, vec3 *poly,
                           int *n)
{
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, cc->width, cc->height, &f, &r, &u, &tx, &ty);
    dvec3 e = d3_from(cam->position), df = d3_from(f), dr = d3_from(r), du = d3_from(u);
    /* a texel in NDC: each projected point stands for the texel square
     * around it, so every texel centre within a texel of the projection is
     * inside (Minkowski sum with the square) */
    double tex_x = 2.0 / cc->width, tex_y = 2.0 / cc->height, d_min = INFINITY;
    Q2 pts[4 * STAND_IN_GEN_MAX], h[4 * STAND_IN_GEN_MAX + 1];
    int m = 0;
    if (num_gen > STAND_IN_GEN_MAX) return false;
    for (int i = 0; i < num_gen; i++) {
        dvec3 q = d3(gen[i][0], gen[i][1], gen[i][2]);
        if (gen[i][3] != 0.0) q = d3_sub(d3_scale(q, 1.0 / gen[i][3]), e);
        else if (d3_dot(q, q) == 0.0) continue; /* no direction */
        double d = d3_dot(q, df);
        /* a point nearer than the near plane, or a direction not away from
         * the camera's plane (its ray reaches every depth) */
        if (gen[i][3] != 0.0 ? !(d * (1.0 - STAND_IN_NEARER) > cam->near_dist * (1.0 + 1e-6)) : !(d > 1e-9 * d3_len(q)))
            return false;
        if (gen[i][3] != 0.0) d_min = d < d_min ? d : d_min;
        double x = d3_dot(q, dr) / (tx * d), y = d3_dot(q, du) / (ty * d);
        for (int c = 0; c < 4; c++) pts[m++] = (Q2){x + (c & 1 ? tex_x : -tex_x), y + (c & 2 ? tex_y : -tex_y)};
    }
    if (!(d_min < INFINITY)) return false; /* only directions: no nearest point */
    int k = hull_2d(pts, m, h);
    k = clip_axis(h, k, 0, 1.0, 1.0 + 2.0 * tex_x);
    k = clip_axis(h, k, 0, -1.0, 1.0 + 2.0 * tex_x);
    k = clip_axis(h, k, 1, 1.0, 1.0 + 2.0 * tex_y);
    k = clip_axis(h, k, 1, -1.0, 1.0 + 2.0 * tex_y);
    *n = k >= 3 ? k : 0;
    double dz = d_min * (1.0 - STAND_IN_NEARER);
    for (int i = 0; i < *n; i++) {
        dvec3 dir = d3_add(df, d3_add(d3_scale(dr, h[i].x * tx), d3_scale(du, h[i].y * ty)));
        dvec3 w = d3_madd(e, dir, dz);
        poly[i] = (vec3){(float)w.x, (float)w.y, (float)w.z};
    }
    return true;
}
