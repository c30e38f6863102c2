/* raster.c -- the depth rasterizer of raster.h in four passes:
 *   1. vertices: world -> clip (or light view space for paraboloid maps);
 *   2. triangles (one static chunk per thread): cull, clip, snap to fixed
 *      point, orient counter-clockwise, fan into triangles, count per tile;
 *   3. binning: prefix sums give every tile a list of triangles in input
 *      order (chunks are contiguous, so the order is deterministic);
 *   4. tiles in parallel: 8x8 blocks trivially rejected, trivially accepted
 *      (no edge tests) or tested per texel with exact edge functions.
 * Edge functions are integers below 2^47 (8 sub-texel bits, maps up to
 * 16384^2) held in doubles, which represent them exactly and vectorise. */
#include "raster/raster.h"
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "raster/clip.h"

#define SUB (1 << RASTER_SUBPIXEL_BITS) /* sub-texel steps per texel */
#define HALF (SUB / 2)                  /* texel centre offset */
#define TILE 64                          /* texels per tile side */
#define BLOCK 8                          /* texels per block side */
#define SMALL_TRIANGLE 64                /* bbox texels below which blocks are not worth it */

/* How the stored value is interpolated over a triangle. */
typedef enum ValueMode {
    VALUE_AFFINE,      /* f interpolated directly: z_ndc, or linear depth when w is constant */
    VALUE_PERSPECTIVE, /* f = a/w and q = 1/w interpolated, value = f / q */
} ValueMode;

/* A triangle after clipping and snapping: counter-clockwise, non-degenerate. */
typedef struct SnapTri {
    int32_t x[3], y[3]; /* sub-texel fixed point */
    double f[3];        /* value (or a/w) at the vertices */
    double q[3];        /* 1/w at the vertices (VALUE_PERSPECTIVE) */
    int32_t id;
    int32_t i0, j0, i1, j1; /* covered texel range, inclusive */
} SnapTri;

typedef struct ThreadTris {
    SnapTri *tri;
    int count, cap;
    int *tile_count; /* triangles of this thread per tile */
    long culled, clipped;
} ThreadTris;

typedef struct Setup {
    const RasterView *view;
    const RasterOptions *opt;
    ValueMode mode;
    int width, height, tiles_x, tiles_y;
} Setup;

static long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

bool depth_buffer_init(DepthBuffer *db, int width, int height, bool triangle_ids, Error *err)
{
    memset(db, 0, sizeof *db);
    if (width < 1 || height < 1 || width > RASTER_MAX_SIZE || height > RASTER_MAX_SIZE)
        return error_set(err, "depth map %dx%d outside [1, %d] per side", width, height, RASTER_MAX_SIZE);
    size_t n = (size_t)width * (size_t)height;
    db->depth = malloc(n * sizeof *db->depth);
    if (triangle_ids) db->triangle = malloc(n * sizeof *db->triangle);
    if (!db->depth || (triangle_ids && !db->triangle)) {
        depth_buffer_free(db);
        return error_set(err, "out of memory for a %dx%d depth map (%.0f MiB)", width, height,
                         (double)n * (triangle_ids ? 8.0 : 4.0) / 1048576.0);
    }
    db->width = width;
    db->height = height;
    return true;
}

void depth_buffer_free(DepthBuffer *db)
{
    free(db->depth);
    free(db->triangle);
    memset(db, 0, sizeof *db);
}

/* ---- 1. vertices ---------------------------------------------------------- */

static void transform_vertices(const RasterMesh *m, const RasterView *v, ClipVertex *out)
{
    const double *r = v->depth_row;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < m->num_vertices; i++) {
        dvec3 p = d3_from(m->positions[i]);
        dvec4 c = m4_apply(&v->clip_from_world, p);
        if (v->mapping == RASTER_PARABOLOID) /* light view space, front = -z: clip z = -z_view >= 0 */
            out[i] = (ClipVertex){c.x, c.y, -c.z, 1.0, 0.0};
        else
            out[i] = (ClipVertex){c.x, c.y, c.z, c.w, r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3]};
    }
}

/* ---- 2. triangles ---------------------------------------------------------- */

/* Screen position (texels), value and 1/w of a clipped vertex. */
typedef struct ScreenVertex { double sx, sy, f, q; } ScreenVertex;

static bool to_screen(const Setup *s, const ClipVertex *c, ScreenVertex *out)
{
    const RasterView *v = s->view;
    double xn, yn;
    if (v->mapping == RASTER_PARABOLOID) {
        double r;
        paraboloid_ndc(d3(c->x, c->y, -c->z), &xn, &yn, &r);
        double range = v->depth_far - v->depth_near;
        out->f = s->opt->depth == RASTER_DEPTH_NDC ? (range > 0.0 ? (r - v->depth_near) / range : 0.0) : r;
        out->q = 1.0;
    } else {
        if (!(c->w > 0.0)) return false; /* only at w = 0 exactly, a degenerate frustum corner */
        double q = 1.0 / c->w;
        xn = c->x * q;
        yn = c->y * q;
        out->q = q;
        out->f = s->opt->depth == RASTER_DEPTH_NDC ? c->z * q : s->mode == VALUE_PERSPECTIVE ? c->a * q : c->a;
    }
    out->sx = (xn + 1.0) * 0.5 * s->width;
    out->sy = (yn + 1.0) * 0.5 * s->height;
    return isfinite(out->sx) && isfinite(out->sy) && isfinite(out->f);
}

static bool push_tri(ThreadTris *tt, const SnapTri *t)
{
    if (tt->count == tt->cap) {
        int cap = tt->cap ? 2 * tt->cap : 1024;
        SnapTri *n = realloc(tt->tri, sizeof *n * (size_t)cap);
        if (!n) return false;
        tt->tri = n;
        tt->cap = cap;
    }
    tt->tri[tt->count++] = *t;
    return true;
}

/* Texel range whose centres (or, conservatively, squares) the triangle's
 * bounding box covers; false when it covers none. */
static bool texel_range(const Setup *s, SnapTri *t)
{
    long xmin = t->x[0], xmax = t->x[0], ymin = t->y[0], ymax = t->y[0];
    for (int k = 1; k < 3; k++) {
        xmin = t->x[k] < xmin ? t->x[k] : xmin;
        xmax = t->x[k] > xmax ? t->x[k] : xmax;
        ymin = t->y[k] < ymin ? t->y[k] : ymin;
        ymax = t->y[k] > ymax ? t->y[k] : ymax;
    }
    long c = s->opt->conservative ? HALF : 0; /* squares within half a texel of the box */
    long i0 = -floor_div(-(xmin - HALF - c), SUB), i1 = floor_div(xmax - HALF + c, SUB);
    long j0 = -floor_div(-(ymin - HALF - c), SUB), j1 = floor_div(ymax - HALF + c, SUB);
    if (i0 < 0) i0 = 0;
    if (j0 < 0) j0 = 0;
    if (i1 > s->width - 1) i1 = s->width - 1;
    if (j1 > s->height - 1) j1 = s->height - 1;
    if (i0 > i1 || j0 > j1) return false;
    t->i0 = (int32_t)i0; t->i1 = (int32_t)i1; t->j0 = (int32_t)j0; t->j1 = (int32_t)j1;
    return true;
}

static void count_tiles(const Setup *s, const SnapTri *t, int *tile_count)
{
    for (int ty = t->j0 / TILE; ty <= t->j1 / TILE; ty++)
        for (int tx = t->i0 / TILE; tx <= t->i1 / TILE; tx++) tile_count[ty * s->tiles_x + tx]++;
}

static int64_t area2(const int32_t *x, const int32_t *y, int a, int b, int c)
{
    return (int64_t)(x[b] - x[a]) * (y[c] - y[a]) - (int64_t)(x[c] - x[a]) * (y[b] - y[a]);
}

/* Fan the clipped, snapped polygon into counter-clockwise triangles. */
static bool emit_polygon(const Setup *s, const ScreenVertex *sv, int n, int32_t id, ThreadTris *tt, bool *culled)
{
    int32_t x[CLIP_MAX_VERTS], y[CLIP_MAX_VERTS];
    for (int k = 0; k < n; k++) {
        x[k] = (int32_t)llround(sv[k].sx * SUB);
        y[k] = (int32_t)llround(sv[k].sy * SUB);
    }
    int64_t area = 0;
    for (int k = 1; k + 1 < n; k++) area += area2(x, y, 0, k, k + 1);
    /* Counter-clockwise on the map (y up) is front-facing: the light sees the
     * side the right-hand-rule normal points to. */
    RasterCull cull = s->opt->cull;
    *culled = area == 0 || (cull == RASTER_CULL_BACK && area < 0) || (cull == RASTER_CULL_FRONT && area > 0);
    if (*culled) return true;
    for (int k = 1; k + 1 < n; k++) {
        int b = area > 0 ? k : k + 1, c = area > 0 ? k + 1 : k;
        if (area2(x, y, 0, b, c) <= 0) continue; /* a sliver that snapped to nothing */
        const int idx[3] = {0, b, c};
        SnapTri t;
        for (int v = 0; v < 3; v++) {
            t.x[v] = x[idx[v]];
            t.y[v] = y[idx[v]];
            t.f[v] = sv[idx[v]].f;
            t.q[v] = sv[idx[v]].q;
        }
        t.id = id;
        if (texel_range(s, &t)) {
            if (!push_tri(tt, &t)) return false;
            count_tiles(s, &t, tt->tile_count);
        }
    }
    return true;
}

static bool setup_triangle(const Setup *s, const ClipVertex *cv, const uint32_t *ix, int32_t id, ThreadTris *tt)
{
    ClipPlanes planes = s->view->mapping == RASTER_PARABOLOID ? CLIP_FRONT_ONLY : CLIP_FRUSTUM;
    const ClipVertex tri[3] = {cv[ix[0]], cv[ix[1]], cv[ix[2]]};
    unsigned o0 = clip_outcode(&tri[0], planes), o1 = clip_outcode(&tri[1], planes), o2 = clip_outcode(&tri[2], planes);
    if (o0 & o1 & o2) { tt->culled++; return true; } /* entirely outside one plane */
    ClipVertex poly[CLIP_MAX_VERTS];
    int n = 3;
    if (o0 | o1 | o2) {
        n = clip_triangle(tri, o0 | o1 | o2, poly);
        tt->clipped++;
    } else {
        memcpy(poly, tri, sizeof tri);
    }
    ScreenVertex sv[CLIP_MAX_VERTS];
    for (int k = 0; k < n; k++)
        if (!to_screen(s, &poly[k], &sv[k])) { tt->culled++; return true; }
    bool culled = n < 3;
    if (!culled && !emit_polygon(s, sv, n, id, tt, &culled)) return false;
    tt->culled += culled;
    return true;
}

/* ---- 4. tiles -------------------------------------------------------------- */

/* Per-triangle constants of the fill. */
typedef struct Fill {
    double a[3], b[3], c[3]; /* E_k(P) = a P.x + b P.y + c >= 0 inside (bias folded into c) */
    double fx, fy, f0, qx, qy, q0; /* value and 1/w planes at sub-texel P: f0 + fx (P.x - x0) + ... */
    double x0, y0;
    float fmin, fmax;
} Fill;

static void fill_setup(const SnapTri *t, const RasterOptions *opt, bool perspective, Fill *F)
{
    for (int k = 0; k < 3; k++) {
        int i = k, j = (k + 1) % 3;
        int64_t a = (int64_t)t->y[i] - t->y[j], b = (int64_t)t->x[j] - t->x[i];
        int64_t c = -(a * t->x[i] + b * t->y[i]);
        if (opt->conservative) c += (llabs(a) + llabs(b)) * HALF; /* any point of the texel square inside */
        else if (!(a > 0 || (a == 0 && b < 0))) c -= 1;       /* top-left rule: only left and top edges own their texels */
        F->a[k] = (double)a;
        F->b[k] = (double)b;
        F->c[k] = (double)c;
    }
    double dx1 = t->x[1] - t->x[0], dy1 = t->y[1] - t->y[0], dx2 = t->x[2] - t->x[0], dy2 = t->y[2] - t->y[0];
    double inv = 1.0 / (dx1 * dy2 - dx2 * dy1); /* > 0: emit_polygon keeps only positive areas */
    double df1 = t->f[1] - t->f[0], df2 = t->f[2] - t->f[0], dq1 = t->q[1] - t->q[0], dq2 = t->q[2] - t->q[0];
    F->fx = (df1 * dy2 - df2 * dy1) * inv;
    F->fy = (df2 * dx1 - df1 * dx2) * inv;
    F->qx = (dq1 * dy2 - dq2 * dy1) * inv;
    F->qy = (dq2 * dx1 - dq1 * dx2) * inv;
    F->f0 = t->f[0];
    F->q0 = t->q[0];
    F->x0 = t->x[0];
    F->y0 = t->y[0];
    F->fmin = (float)fmin(t->f[0], fmin(t->f[1], t->f[2]));
    F->fmax = (float)fmax(t->f[0], fmax(t->f[1], t->f[2]));
    if (perspective) { /* the range of the value a = f / q */
        F->fmin = (float)fmin(t->f[0] / t->q[0], fmin(t->f[1] / t->q[1], t->f[2] / t->q[2]));
        F->fmax = (float)fmax(t->f[0] / t->q[0], fmax(t->f[1] / t->q[1], t->f[2] / t->q[2]));
    }
}

typedef struct Target {
    float *depth;
    int32_t *id;
    const float *peel;
    int stride;
    bool farthest, perspective, conservative;
} Target;

/* Texels [i0, i1] of row j; `test` false when the whole span is known inside. */
static inline long fill_span(const Fill *F, const Target *T, int32_t id, int j, int i0, int i1, bool test)
{
    double py = (double)j * SUB + HALF, px0 = (double)i0 * SUB + HALF;
    double e0 = F->a[0] * px0 + F->b[0] * py + F->c[0];
    double e1 = F->a[1] * px0 + F->b[1] * py + F->c[1];
    double e2 = F->a[2] * px0 + F->b[2] * py + F->c[2];
    double f_row = F->f0 + F->fx * (px0 - F->x0) + F->fy * (py - F->y0);
    double q_row = F->q0 + F->qx * (px0 - F->x0) + F->qy * (py - F->y0);
    double fs = F->fx * SUB, qs = F->qx * SUB, a0 = F->a[0] * SUB, a1 = F->a[1] * SUB, a2 = F->a[2] * SUB;
    size_t row = (size_t)j * (size_t)T->stride;
    long written = 0;
    for (int i = i0; i <= i1; i++) {
        double k = i - i0;
        if (test && !(e0 + a0 * k >= 0.0 && e1 + a1 * k >= 0.0 && e2 + a2 * k >= 0.0)) continue;
        float v = T->perspective ? (float)((f_row + fs * k) / (q_row + qs * k)) : (float)(f_row + fs * k);
        if (T->conservative) v = fminf(fmaxf(v, F->fmin), F->fmax);
        size_t at = row + (size_t)i;
        if (T->peel && !(v > T->peel[at])) continue;
        if (T->farthest ? !(v > T->depth[at]) : !(v < T->depth[at])) continue;
        T->depth[at] = v;
        if (T->id) T->id[at] = id;
        written++;
    }
    return written;
}

/* Edge k's smallest and largest value over the block's texel centres. */
static void edge_bounds(const Fill *F, int k, double px0, double py0, double span, double *lo, double *hi)
{
    double e = F->a[k] * px0 + F->b[k] * py0 + F->c[k];
    double ax = F->a[k] * span, by = F->b[k] * span;
    *lo = e + fmin(ax, 0.0) + fmin(by, 0.0);
    *hi = e + fmax(ax, 0.0) + fmax(by, 0.0);
}

static long fill_rect(const Fill *F, const Target *T, int32_t id, int i0, int j0, int i1, int j1)
{
    long written = 0;
    if ((long)(i1 - i0 + 1) * (j1 - j0 + 1) <= SMALL_TRIANGLE) {
        for (int j = j0; j <= j1; j++) written += fill_span(F, T, id, j, i0, i1, true);
        return written;
    }
    for (int bj = j0; bj <= j1; bj += BLOCK) {
        int bj1 = bj + BLOCK - 1 < j1 ? bj + BLOCK - 1 : j1;
        for (int bi = i0; bi <= i1; bi += BLOCK) {
            int bi1 = bi + BLOCK - 1 < i1 ? bi + BLOCK - 1 : i1;
            double px0 = (double)bi * SUB + HALF, py0 = (double)bj * SUB + HALF;
            double span = (double)(BLOCK - 1) * SUB;
            bool inside = true, outside = false;
            for (int k = 0; k < 3; k++) {
                double lo, hi;
                edge_bounds(F, k, px0, py0, span, &lo, &hi);
                inside = inside && lo >= 0.0;
                outside = outside || hi < 0.0;
            }
            if (outside) continue;
            for (int j = bj; j <= bj1; j++) written += fill_span(F, T, id, j, bi, bi1, !inside);
        }
    }
    return written;
}

/* Quantise finished depths to `bits` over [lo, hi] (course §2.1.2's precision
 * discussion): round(d' (2^b - 1)) / (2^b - 1) with d' the normalised depth. */
static void quantise(float *d, size_t n, int bits, double lo, double hi)
{
    double levels = (double)((1u << bits) - 1u), range = hi - lo;
    if (!(range > 0.0)) return;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(d[i])) continue;
        double t = fmin(fmax((d[i] - lo) / range, 0.0), 1.0);
        d[i] = (float)(lo + round(t * levels) / levels * range);
    }
}

static long fill_tile(const Setup *s, int tile, const SnapTri *const *bins, const int *bin_start, DepthBuffer *db)
{
    int tx = tile % s->tiles_x, ty = tile / s->tiles_x;
    int ti0 = tx * TILE, tj0 = ty * TILE;
    int ti1 = ti0 + TILE - 1 < s->width - 1 ? ti0 + TILE - 1 : s->width - 1;
    int tj1 = tj0 + TILE - 1 < s->height - 1 ? tj0 + TILE - 1 : s->height - 1;
    const RasterOptions *opt = s->opt;
    Target T = {db->depth, db->triangle, opt->peel, s->width, opt->test == RASTER_FARTHEST,
                s->mode == VALUE_PERSPECTIVE && opt->depth == RASTER_DEPTH_LINEAR, opt->conservative};
    float empty = T.farthest ? -INFINITY : INFINITY;
    for (int j = tj0; j <= tj1; j++)
        for (int i = ti0; i <= ti1; i++) {
            db->depth[(size_t)j * s->width + i] = empty;
            if (db->triangle) db->triangle[(size_t)j * s->width + i] = -1;
        }
    long written = 0;
    for (int b = bin_start[tile]; b < bin_start[tile + 1]; b++) {
        const SnapTri *t = bins[b];
        Fill F;
        fill_setup(t, opt, T.perspective, &F);
        int i0 = t->i0 > ti0 ? t->i0 : ti0, i1 = t->i1 < ti1 ? t->i1 : ti1;
        int j0 = t->j0 > tj0 ? t->j0 : tj0, j1 = t->j1 < tj1 ? t->j1 : tj1;
        if (i0 <= i1 && j0 <= j1) written += fill_rect(&F, &T, t->id, i0, j0, i1, j1);
    }
    if (opt->depth_bits == 16 || opt->depth_bits == 24) {
        double lo = opt->depth == RASTER_DEPTH_NDC ? 0.0 : s->view->depth_near;
        double hi = opt->depth == RASTER_DEPTH_NDC ? 1.0 : s->view->depth_far;
        for (int j = tj0; j <= tj1; j++)
            quantise(db->depth + (size_t)j * s->width + ti0, (size_t)(ti1 - ti0 + 1), opt->depth_bits, lo, hi);
    }
    return written;
}

/* ---- driver ---------------------------------------------------------------- */

static ValueMode value_mode(const RasterView *v, const RasterOptions *opt)
{
    const double(*m)[4] = v->clip_from_world.m;
    bool affine_w = m[3][0] == 0.0 && m[3][1] == 0.0 && m[3][2] == 0.0;
    if (v->mapping == RASTER_PARABOLOID || opt->depth == RASTER_DEPTH_NDC || affine_w) return VALUE_AFFINE;
    return VALUE_PERSPECTIVE;
}

/* Pass 2 over this thread's chunk of the triangles of every mesh. */
static bool setup_chunk(const Setup *s, const RasterMesh *meshes, int num_meshes, ClipVertex *const *cv, long t0,
                        long t1, ThreadTris *tt)
{
    long base = 0;
    for (int m = 0; m < num_meshes; m++) {
        long n = meshes[m].num_triangles;
        long lo = t0 > base ? t0 : base, hi = t1 < base + n ? t1 : base + n;
        for (long t = lo; t < hi; t++)
            if (!setup_triangle(s, cv[m], &meshes[m].indices[3 * (t - base)], (int32_t)t, tt)) return false;
        base += n;
    }
    return true;
}

/* Passes 3 and 4: bins from the per-thread counts, then the tiles. */
static long bin_and_fill(const Setup *s, ThreadTris *tt, int nthreads, DepthBuffer *db, bool *ok)
{
    int ntiles = s->tiles_x * s->tiles_y;
    int *bin_start = malloc(sizeof(int) * (size_t)(ntiles + 1));
    int *cursor = malloc(sizeof(int) * (size_t)ntiles * (size_t)nthreads);
    long total = 0;
    for (int k = 0; k < nthreads; k++)
        for (int i = 0; i < tt[k].count; i++)
            total += (long)(tt[k].tri[i].i1 / TILE - tt[k].tri[i].i0 / TILE + 1) *
                     (tt[k].tri[i].j1 / TILE - tt[k].tri[i].j0 / TILE + 1);
    const SnapTri **bins = total < (long)1 << 31 ? malloc(sizeof *bins * (size_t)(total > 0 ? total : 1)) : NULL;
    if (!bin_start || !cursor || !bins) {
        free(bin_start); free(cursor); free(bins);
        *ok = false;
        return 0;
    }
    int at = 0;
    for (int tile = 0; tile < ntiles; tile++) { /* tile-major, thread order within a tile */
        bin_start[tile] = at;
        for (int k = 0; k < nthreads; k++) {
            cursor[(size_t)k * ntiles + tile] = at;
            at += tt[k].tile_count[tile];
        }
    }
    bin_start[ntiles] = at;
#pragma omp parallel for schedule(static, 1)
    for (int k = 0; k < nthreads; k++) {
        int *cur = cursor + (size_t)k * ntiles;
        for (int i = 0; i < tt[k].count; i++) {
            const SnapTri *t = &tt[k].tri[i];
            for (int ty = t->j0 / TILE; ty <= t->j1 / TILE; ty++)
                for (int tx = t->i0 / TILE; tx <= t->i1 / TILE; tx++) bins[cur[ty * s->tiles_x + tx]++] = t;
        }
    }
    long written = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : written)
    for (int tile = 0; tile < ntiles; tile++) written += fill_tile(s, tile, bins, bin_start, db);
    free(bin_start); free(cursor); free(bins);
    *ok = true;
    return written;
}

static bool check_inputs(const RasterMesh *meshes, int num_meshes, const RasterView *view, const RasterOptions *opt,
                         const DepthBuffer *db, Error *err)
{
    if (!db->depth || db->width < 1 || db->height < 1) return error_set(err, "raster: depth buffer not initialised");
    if (opt->triangle_ids && !db->triangle) return error_set(err, "raster: triangle ids asked for but not allocated");
    if (opt->depth_bits != 0 && opt->depth_bits != 16 && opt->depth_bits != 24)
        return error_set(err, "raster: depth_bits %d is not one of 0 (float32), 16, 24", opt->depth_bits);
    if (view->mapping == RASTER_PARABOLOID && !(view->depth_far > view->depth_near))
        return error_set(err, "raster: paraboloid depth range [%g, %g] is empty", view->depth_near, view->depth_far);
    long total = 0;
    for (int m = 0; m < num_meshes; m++) total += meshes[m].num_triangles;
    if (total >= INT32_MAX) return error_set(err, "raster: %ld triangles exceed the id range", total);
    return true;
}

bool raster_depth(const RasterMesh *meshes, int num_meshes, const RasterView *view, const RasterOptions *opt,
                  DepthBuffer *db, RasterStats *stats, Error *err)
{
    if (!check_inputs(meshes, num_meshes, view, opt, db, err)) return false;
    Setup s = {view, opt, value_mode(view, opt), db->width, db->height, (db->width + TILE - 1) / TILE,
               (db->height + TILE - 1) / TILE};
    int nthreads = omp_get_max_threads();
    long total = 0;
    ClipVertex **cv = calloc((size_t)(num_meshes > 0 ? num_meshes : 1), sizeof *cv);
    ThreadTris *tt = calloc((size_t)nthreads, sizeof *tt);
    bool ok = cv && tt;
    for (int m = 0; ok && m < num_meshes; m++) {
        total += meshes[m].num_triangles;
        cv[m] = malloc(sizeof **cv * (size_t)(meshes[m].num_vertices > 0 ? meshes[m].num_vertices : 1));
        ok = cv[m] != NULL;
        if (ok) transform_vertices(&meshes[m], view, cv[m]);
    }
    for (int k = 0; ok && k < nthreads; k++) ok = (tt[k].tile_count = calloc((size_t)s.tiles_x * s.tiles_y, sizeof(int))) != NULL;
    if (ok) {
        long chunk = (total + nthreads - 1) / nthreads;
        int failed = 0;
#pragma omp parallel for schedule(static, 1) reduction(+ : failed)
        for (int k = 0; k < nthreads; k++) failed += !setup_chunk(&s, meshes, num_meshes, cv, k * chunk,
                                                               (k + 1) * chunk < total ? (k + 1) * chunk : total, &tt[k]);
        ok = failed == 0;
    }
    long written = ok ? bin_and_fill(&s, tt, nthreads, db, &ok) : 0;
    RasterStats st = {total, 0, 0, 0, written};
    for (int k = 0; tt && k < nthreads; k++) {
        st.triangles_culled += tt[k].culled;
        st.triangles_clipped += tt[k].clipped;
        st.triangles_drawn += tt[k].count;
        free(tt[k].tri);
        free(tt[k].tile_count);
    }
    for (int m = 0; cv && m < num_meshes; m++) free(cv[m]);
    free(cv);
    free(tt);
    if (stats) *stats = st;
    if (!ok) return error_set(err, "raster: out of memory (%ld triangles into %dx%d)", total, db->width, db->height);
    return true;
}
