/* raster.c -- the depth rasterizer of raster.h in four passes:
 *   1. vertices: world -> clip (or light view space for paraboloid maps);
 *   2. triangles (contiguous chunks, taken dynamically): cull, clip, snap to fixed
 *      point, orient counter-clockwise, fan into triangles, count per tile;
 *   3. binning: a parallel prefix sum over tiles x chunks gives every tile
 *      a list of triangles in input order (chunks are contiguous, so the
 *      order is deterministic); passes 3 and 4 share one parallel region;
 *   4. tiles in parallel: per row, the exact span the three edge functions
 *      allow (integer arithmetic), then a vectorised depth loop over it (or,
 *      for the counting tests, a loop adding the triangle's signed count).
 * Edge functions are integers below 2^47 (8 sub-texel bits, maps up to
 * 16384^2), evaluated in int64. */
#include "raster/raster.h"
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "raster/clip.h"
#include "core/array.h"
#include "core/bufpool.h"
#include "core/counters.h"
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#define SUB (1 << RASTER_SUBPIXEL_BITS) /* sub-texel steps per texel */
#define HALF (SUB / 2)                  /* texel centre offset */
#define TILE 64                          /* texels per tile side */
#define CHUNK_TRIANGLES 4096             /* triangles per set-up chunk (at most 4 chunks per thread) */
/* Triangles ahead whose data is fetched early: a mesh's index order jumps
 * around its vertex array, and a tile's bin around the triangle array. */
#define PREFETCH_AHEAD 8
/* Triangles whose vertices span at most this many texels (x, y) are filled
 * texel by texel (fill_small): their edge functions stay below 2^28 over the
 * box, so they fit int32 lanes. */
#define SMALL_W 16
#define SMALL_H 64

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
    int32_t count;          /* counting tests: +count front-facing (counter-clockwise before orienting), -count back */
    int32_t i0, j0, i1, j1; /* covered texel range, inclusive */
    bool small;             /* vertex box within SMALL_W x SMALL_H texels: fill_small's int32 edges are exact */
} SnapTri;

/* The tiles a set-up triangle covers, packed in one word (tile x0, y0, x1,
 * y1 in its bytes, low first: a map has at most 256 tiles a side), so the
 * binning pass reads 4 bytes a triangle rather than its 104-byte SnapTri
 * (for the 1M-triangle torus, 4 MB instead of 104 MB from memory). */
typedef uint32_t TileBox;
_Static_assert(RASTER_MAX_SIZE / TILE <= 256, "tile coordinates fit a byte");
static inline int box_x0(TileBox b) { return (int)(b & 0xffu); }
static inline int box_y0(TileBox b) { return (int)(b >> 8 & 0xffu); }
static inline int box_x1(TileBox b) { return (int)(b >> 16 & 0xffu); }
static inline int box_y1(TileBox b) { return (int)(b >> 24); }

typedef struct ThreadTris {
    SnapTri *tri;
    TileBox *box; /* per triangle, as tri */
    int count, cap;
    int *tile_count; /* triangles of this chunk per tile */
    long entries;    /* bin entries of this chunk: the sum of tile_count */
    long culled, clipped;
} ThreadTris;

typedef struct Setup {
    const RasterView *view;
    const RasterOptions *opt;
    ValueMode mode;
    int width, height, tiles_x, tiles_y;
    bool stream; /* row_store's non-temporal stores */
} Setup;

static long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
/* min/max that compile to one instruction (libm's fmin/fmax are calls) */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }

bool depth_buffer_init(DepthBuffer *db, int width, int height, bool triangle_ids, Error *err)
{
    memset(db, 0, sizeof *db);
    if (width < 1 || height < 1 || width > RASTER_MAX_SIZE || height > RASTER_MAX_SIZE)
        return error_set(err, "depth map %dx%d outside [1, %d] per side", width, height, RASTER_MAX_SIZE);
    size_t n = (size_t)width * (size_t)height;
    db->depth = bufpool_alloc(n * sizeof *db->depth);
    if (triangle_ids) db->triangle = bufpool_alloc(n * sizeof *db->triangle);
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
    bufpool_free(db->depth);
    bufpool_free(db->triangle);
    raster_scratch_free(db->scratch);
    memset(db, 0, sizeof *db);
}

/* ---- 1. vertices ---------------------------------------------------------- */

/* Screen position (texels), value and 1/w of a clip-space vertex. */
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

/* Fixed point, rounded; the map spans [0, size] texels (clipped vertices may
 * round a hair outside, hence the clamp). */
static int32_t snap(double texels, int size)
{
    double v = dmin(dmax(texels, 0.0), (double)size) * SUB + 0.5;
    return (int32_t)v; /* v >= 0: truncation rounds */
}

/* A transformed vertex as the triangle pass reads it (32 bytes, so a mesh's
 * vertices stay in cache): the planes it is outside and, when inside all of
 * them, its snapped map position and values (computed once per vertex, so
 * shared vertices snap identically). Its clip coordinates are not stored:
 * only triangles crossing a plane need them, and clip_vertex recomputes
 * them there, the same arithmetic giving the same doubles. */
#define OUTCODE_INVALID (1u << 6) /* inside, but no finite screen position */
typedef struct RVertex {
    unsigned outcode;
    int32_t x, y;
    double f, q;
} RVertex;

typedef struct Vertices {
    RVertex *v;
    const RasterMesh *mesh;
    const float *weights; /* RasterMeshExtra.weights, or NULL */
} Vertices;

/* Clip coordinates of vertex i of a mesh (for paraboloid maps light view
 * space, front = -z: clip z = -z_view >= 0), with its linear depth. */
static ClipVertex clip_vertex(const Setup *s, const Vertices *vx, uint32_t i)
{
    const RasterView *v = s->view;
    const double *r = v->depth_row;
    dvec3 p = d3_from(vx->mesh->positions[i]);
    double h = vx->weights ? vx->weights[i] : 1.0; /* homogeneous (p, h) */
    dvec4 c = m4_apply4(&v->clip_from_world, (dvec4){p.x, p.y, p.z, h});
    if (v->mapping == RASTER_PARABOLOID) return (ClipVertex){c.x, c.y, -c.z, 1.0, 0.0};
    return (ClipVertex){c.x, c.y, c.z, c.w, r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3] * h};
}

/* ---- working memory kept between renders (DepthBuffer.scratch) ------------- */

/* A block reused while large enough; its contents do not survive growth. */
typedef struct Block { void *p; size_t bytes; } Block;

/* Room for `bytes` in b, from the buffers kept between builds
 * (core/bufpool.h): a map's faces share one scratch, and the next map's
 * takes the same buffers back. */
static void *block_reserve(Block *b, size_t bytes)
{
    if (bytes <= b->bytes && b->p) return b->p;
    bufpool_free(b->p);
    b->p = bufpool_alloc(bytes);
    b->bytes = b->p ? bytes : 0;
    return b->p;
}

struct RasterScratch {
    Block vertices;                     /* every mesh's, one after the other */
    Block tile_counts;                  /* chunks x tiles */
    Block bin_start, cursor, bins;      /* pass 3 */
    Block block_sum;                    /* pass 3: one per thread */
    ThreadTris *chunk;                  /* per set-up chunk; push_tri grows its triangles */
    int num_chunks;
};

void raster_scratch_free(RasterScratch *scratch)
{
    if (!scratch) return;
    Block *blocks[] = {&scratch->vertices, &scratch->tile_counts, &scratch->bin_start,
                       &scratch->cursor, &scratch->bins, &scratch->block_sum};
    for (size_t i = 0; i < sizeof blocks / sizeof *blocks; i++) bufpool_free(blocks[i]->p);
    for (int k = 0; k < scratch->num_chunks; k++) {
        free(scratch->chunk[k].tri);
        free(scratch->chunk[k].box);
    }
    free(scratch->chunk);
    free(scratch);
}

/* Static schedules here and in the set-up: thread i transforms the i-th
 * contiguous part of the vertices and sets up the i-th part of the
 * triangles, which in a mesh stored in spatial order read mostly the
 * vertices its own core wrote (a line the other core wrote costs a transfer:
 * bench/coherence). Measured against schedule(dynamic): the 1M-triangle
 * torus at 2048^2, 1 -> 2 threads 1.70-1.73 -> 1.81-1.91, the bunny 1.58 ->
 * 1.55-1.59 (quiet, two alternating runs of 9 rounds). */
static void transform_vertices(const Setup *s, const Vertices *vx)
{
    ClipPlanes planes = s->view->mapping == RASTER_PARABOLOID ? CLIP_FRONT_ONLY : CLIP_FRUSTUM;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < vx->mesh->num_vertices; i++) {
        ClipVertex cv = clip_vertex(s, vx, (uint32_t)i);
        RVertex *o = &vx->v[i];
        *o = (RVertex){clip_outcode(&cv, planes), 0, 0, 0.0, 0.0};
        ScreenVertex sv;
        if (o->outcode) continue;
        if (!to_screen(s, &cv, &sv)) { o->outcode = OUTCODE_INVALID; continue; }
        o->x = snap(sv.sx, s->width);
        o->y = snap(sv.sy, s->height);
        o->f = sv.f;
        o->q = sv.q;
    }
}

/* ---- 2. triangles ---------------------------------------------------------- */

/* Append t with its tile box; the two arrays grow together (cap is both's). */
static bool push_tri(ThreadTris *tt, const SnapTri *t)
{
    int tri_cap = tt->cap, box_cap = tt->cap;
    SnapTri *tri = array_room(tt->tri, tt->count, &tri_cap, sizeof *tri, 1024);
    if (!tri) return false;
    tt->tri = tri;
    TileBox *box = array_room(tt->box, tt->count, &box_cap, sizeof *box, 1024);
    if (!box) return false;
    tt->box = box;
    tt->cap = tri_cap;
    tt->box[tt->count] = (TileBox)(t->i0 / TILE) | (TileBox)(t->j0 / TILE) << 8 | (TileBox)(t->i1 / TILE) << 16 |
                         (TileBox)(t->j1 / TILE) << 24;
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
    t->small = xmax - xmin <= SMALL_W * SUB && ymax - ymin <= SMALL_H * SUB;
    t->i0 = (int32_t)i0; t->i1 = (int32_t)i1; t->j0 = (int32_t)j0; t->j1 = (int32_t)j1;
    return true;
}

static void count_tiles(const Setup *s, TileBox b, ThreadTris *tt)
{
    for (int ty = box_y0(b); ty <= box_y1(b); ty++)
        for (int tx = box_x0(b); tx <= box_x1(b); tx++) tt->tile_count[ty * s->tiles_x + tx]++;
    tt->entries += (long)(box_y1(b) - box_y0(b) + 1) * (box_x1(b) - box_x0(b) + 1);
}

static int64_t area2(const int32_t *x, const int32_t *y, int a, int b, int c)
{
    return (int64_t)(x[b] - x[a]) * (y[c] - y[a]) - (int64_t)(x[c] - x[a]) * (y[b] - y[a]);
}

/* Fan the snapped polygon into counter-clockwise triangles. */
static bool emit_polygon(const Setup *s, const int32_t *x, const int32_t *y, const double *f, const double *q, int n,
                         int32_t id, int32_t count, ThreadTris *tt, bool *culled)
{
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
            t.f[v] = f[idx[v]];
            t.q[v] = q[idx[v]];
        }
        t.id = id;
        t.count = area > 0 ? count : -count;
        if (texel_range(s, &t)) {
            if (!push_tri(tt, &t)) return false;
            count_tiles(s, tt->box[tt->count - 1], tt);
        }
    }
    return true;
}

/* A triangle that crosses frustum planes: clip, project and snap its polygon. */
static bool emit_clipped(const Setup *s, const Vertices *vx, const uint32_t *ix, unsigned crossing, int32_t id,
                         int32_t count, ThreadTris *tt, bool *culled)
{
    const ClipVertex tri[3] = {clip_vertex(s, vx, ix[0]), clip_vertex(s, vx, ix[1]), clip_vertex(s, vx, ix[2])};
    ClipVertex poly[CLIP_MAX_VERTS];
    int n = clip_triangle(tri, crossing & ~OUTCODE_INVALID, poly);
    int32_t x[CLIP_MAX_VERTS], y[CLIP_MAX_VERTS];
    double f[CLIP_MAX_VERTS], q[CLIP_MAX_VERTS];
    for (int k = 0; k < n; k++) {
        ScreenVertex sv;
        if (!to_screen(s, &poly[k], &sv)) { *culled = true; return true; }
        x[k] = snap(sv.sx, s->width);
        y[k] = snap(sv.sy, s->height);
        f[k] = sv.f;
        q[k] = sv.q;
    }
    *culled = n < 3;
    return *culled || emit_polygon(s, x, y, f, q, n, id, count, tt, culled);
}

static bool setup_triangle(const Setup *s, const Vertices *vx, const uint32_t *ix, int32_t id, int32_t count,
                           ThreadTris *tt)
{
    const RVertex *v[3] = {&vx->v[ix[0]], &vx->v[ix[1]], &vx->v[ix[2]]};
    unsigned all = v[0]->outcode & v[1]->outcode & v[2]->outcode, any = v[0]->outcode | v[1]->outcode | v[2]->outcode;
    bool culled;
    if (all & ~OUTCODE_INVALID) { tt->culled++; return true; } /* entirely outside one plane */
    bool ok;
    if (any) {
        tt->clipped++;
        ok = emit_clipped(s, vx, ix, any, id, count, tt, &culled);
    } else {
        const int32_t x[3] = {v[0]->x, v[1]->x, v[2]->x}, y[3] = {v[0]->y, v[1]->y, v[2]->y};
        const double f[3] = {v[0]->f, v[1]->f, v[2]->f}, q[3] = {v[0]->q, v[1]->q, v[2]->q};
        ok = emit_polygon(s, x, y, f, q, 3, id, count, tt, &culled);
    }
    tt->culled += ok && culled;
    return ok;
}

/* ---- 4. tiles -------------------------------------------------------------- */

/* Per-triangle constants of the fill. */
typedef struct Fill {
    int64_t a[3], b[3], c[3]; /* E_k(P) = a P.x + b P.y + c >= 0 inside (bias folded into c), sub-texel units */
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
        F->a[k] = a;
        F->b[k] = b;
        F->c[k] = c;
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
    F->fmin = -INFINITY;
    F->fmax = INFINITY;
    if (!opt->conservative) return;
    double v[3];
    for (int k = 0; k < 3; k++) v[k] = perspective ? t->f[k] / t->q[k] : t->f[k]; /* the value a = f / q */
    F->fmin = (float)dmin(v[0], dmin(v[1], v[2]));
    F->fmax = (float)dmax(v[0], dmax(v[1], v[2]));
}

/* Where a tile's fragments go: depth into a tile-local buffer (it stays in
 * L1 while the tile's triangles are drawn, and is written to the map once),
 * ids and the peeling layer in the map's own rows. */
typedef struct Target {
    float *depth;     /* texel (i, j) at (j - tj0) * TILE + (i - ti0) */
    int ti0, tj0;
    int32_t *id;      /* texel (i, j) at j * stride + i, as peel */
    const float *peel;
    float peel_epsilon; /* RasterOptions.peel_epsilon */
    int stride;
    bool farthest, perspective, conservative;
    int32_t *count;         /* counting tests: counters and reference values at j * stride + i */
    const float *count_ref;
    bool count_less;        /* RASTER_COUNT_LESS (else GREATER) */
    long *overflow;         /* updates refused because the counter would leave int32 */
} Target;

static inline float *tile_row(const Target *T, int j, int i) { return T->depth + (size_t)(j - T->tj0) * TILE + (i - T->ti0); }

/* floor(n / d) for d > 0 without a 64-bit integer division (tens of cycles,
 * once per edge and row): |n| < 2^47 and d < 2^31 are exact doubles, so the
 * truncated double quotient is within one of the floor, then fixed up. */
static inline int64_t floor_div_pos(int64_t n, int64_t d)
{
    int64_t q = (int64_t)((double)n / (double)d);
    q -= q * d > n;
    q += (q + 1) * d <= n;
    return q;
}

/* Texels of row j inside the triangle, exactly: each edge E(i) = a (i SUB +
 * HALF) + r >= 0 bounds i from one side (a > 0: below, a < 0: above), in
 * integer arithmetic, so the span equals the per-texel edge tests. Only the
 * edges in the mask `edges` (bit k: edge k) are tested: the others hold over
 * the whole box the caller fills (crossing_edges). */
static inline __attribute__((always_inline)) bool row_span(const Fill *F, unsigned edges, int j, int *lo, int *hi)
{
    int64_t py = (int64_t)j * SUB + HALF;
    for (int k = 0; k < 3; k++) {
        if (!(edges >> k & 1u)) continue;
        int64_t a = F->a[k], r = F->b[k] * py + F->c[k], num = -r - a * HALF;
        if (a > 0) {
            int64_t m = -floor_div_pos(-num, a * SUB); /* ceil(num / den) */
            if (m > *lo) *lo = m > INT32_MAX ? INT32_MAX : (int)m;
        } else if (a < 0) {
            int64_t m = floor_div_pos(-num, -a * SUB); /* floor(num / den), den = a SUB < 0 */
            if (m < *hi) *hi = m < INT32_MIN ? INT32_MIN : (int)m;
        } else if (r < 0) {
            return false;
        }
    }
    return *lo <= *hi;
}

/* Value of texel k of a span from the row's start, perspective or affine.
 * Float lanes: the planes are evaluated in double at the row's start and
 * stepped in float, one rounding more than the float32 the map stores. */
static inline float span_value(float f_row, float fs, float q_row, float qs, float k, bool perspective)
{
    return perspective ? (f_row + fs * k) / (q_row + qs * k) : f_row + fs * k;
}

/* The nearest test over n texels of a row from d, in float lanes: texel i's
 * value (span_value) is stored where it is nearer than d[i] and, when
 * `edges`, the three edge values e[k] + step[k] i are all >= 0 (their
 * bitwise or is: fill_small's per-texel test). Inlined with persp and edges
 * constant, so every caller's loop is branch-free (a division under a branch
 * is not if-converted) and an affine span divides nothing. */
static inline __attribute__((always_inline)) int nearest_row_of(float *d, int n, float f_row, float fs, float q_row,
                                                                float qs, bool persp, bool edges, const int32_t *e,
                                                                const int32_t *step)
{
    int written = 0;
#pragma omp simd reduction(+ : written)
    for (int i = 0; i < n; i++) {
        float v = span_value(f_row, fs, q_row, qs, (float)i, persp), old = d[i];
        int pass = (!edges || ((e[0] + step[0] * i) | (e[1] + step[1] * i) | (e[2] + step[2] * i)) >= 0) && v < old;
        d[i] = pass ? v : old;
        written += pass;
    }
    return written;
}

/* nearest_row_of with persp made a constant (edges stays the caller's). */
static inline __attribute__((always_inline)) int nearest_row(float *d, int n, double f_row, double fs, double q_row,
                                                             double qs, bool persp, bool edges, const int32_t *e,
                                                             const int32_t *step)
{
    return persp ? nearest_row_of(d, n, (float)f_row, (float)fs, (float)q_row, (float)qs, true, edges, e, step)
                 : nearest_row_of(d, n, (float)f_row, (float)fs, 0.0f, 0.0f, false, edges, e, step);
}

/* A counting test's span: fragments that pass add inc to their counter,
 * unless it would leave int32 (then *overflow counts the update). */
static long count_span(const Target *T, int32_t inc, size_t row, int n, float f_row, float fs, float q_row, float qs)
{
    int32_t *c = T->count + row;
    const float *ref = T->count_ref + row;
    long counted = 0;
    for (int i = 0; i < n; i++) {
        float v = span_value(f_row, fs, q_row, qs, (float)i, T->perspective);
        if (T->count_less ? !(v < ref[i]) : !(v > ref[i])) continue;
        if (inc > 0 ? c[i] > INT32_MAX - inc : c[i] < INT32_MIN - inc) {
            (*T->overflow)++;
            continue;
        }
        c[i] += inc;
        counted++;
    }
    return counted;
}

/* The value and 1/w planes at the centre of texel (i, j), in double: where
 * a row's float steps start. */
static inline void row_planes(const Fill *F, int i, int j, double *f_row, double *q_row)
{
    double px = (double)i * SUB + HALF, py = (double)j * SUB + HALF;
    *f_row = F->f0 + F->fx * (px - F->x0) + F->fy * (py - F->y0);
    *q_row = F->q0 + F->qx * (px - F->x0) + F->qy * (py - F->y0);
}

/* The common case of a span (nearest test, no ids, peeling or clamping). */
static inline __attribute__((always_inline)) int span_nearest(const Fill *F, const Target *T, int j, int i0, int i1)
{
    double f_row, q_row, fs = F->fx * SUB, qs = F->qx * SUB;
    row_planes(F, i0, j, &f_row, &q_row);
    return nearest_row(tile_row(T, j, i0), i1 - i0 + 1, f_row, fs, q_row, qs, T->perspective, false, NULL, NULL);
}

/* Every other span: counting tests, farthest, ids, peeling, clamping. */
static long fill_span(const Fill *F, const Target *T, const SnapTri *t, int j, int i0, int i1)
{
    double f_row, q_row, fs = F->fx * SUB, qs = F->qx * SUB;
    row_planes(F, i0, j, &f_row, &q_row);
    size_t row = (size_t)j * (size_t)T->stride + (size_t)i0;
    float *d = tile_row(T, j, i0);
    int n = i1 - i0 + 1;
    bool persp = T->perspective;
    if (T->count) return count_span(T, t->count, row, n, (float)f_row, (float)fs, (float)q_row, (float)qs);
    int32_t id = t->id;
    long written = 0;
    for (int i = 0; i < n; i++) {
        float v = span_value((float)f_row, (float)fs, (float)q_row, (float)qs, (float)i, persp);
        if (T->conservative) v = v < F->fmin ? F->fmin : v > F->fmax ? F->fmax : v;
        if (T->peel && !(v > T->peel[row + (size_t)i] + T->peel_epsilon)) continue;
        if (T->farthest ? !(v > d[i]) : !(v < d[i])) continue;
        d[i] = v;
        if (T->id) T->id[row + (size_t)i] = id;
        written++;
    }
    return written;
}

/* The edges that leave some texel centre of the box [i0, i1] x [j0, j1]
 * outside (bit k: edge k). E is affine, so its least value over the box is
 * at a corner: an edge inside at the four corner centres is inside over
 * all of it, and row_span need not divide for it (a tile the triangle
 * covers whole, like a ground plane's at large maps, needs none). */
static inline __attribute__((always_inline)) unsigned crossing_edges(const Fill *F, int i0, int j0, int i1, int j1)
{
    int64_t x0 = (int64_t)i0 * SUB + HALF, x1 = (int64_t)i1 * SUB + HALF;
    int64_t y0 = (int64_t)j0 * SUB + HALF, y1 = (int64_t)j1 * SUB + HALF;
    unsigned edges = 0;
    for (int k = 0; k < 3; k++) {
        int64_t ex = F->a[k] * (F->a[k] < 0 ? x1 : x0), ey = F->b[k] * (F->b[k] < 0 ? y1 : y0);
        if (ex + ey + F->c[k] < 0) edges |= 1u << k; /* the least corner value */
    }
    return edges;
}

/* The triangle's texels in the box [i0, i1] x [j0, j1], row by row, each
 * row's exact span (row_span) drawn by span_nearest when `nearest` (inlined
 * with it constant), else by fill_span. */
static inline __attribute__((always_inline)) long rect_rows(const Fill *F, const Target *T, const SnapTri *t, int i0,
                                                            int j0, int i1, int j1, bool nearest)
{
    unsigned edges = crossing_edges(F, i0, j0, i1, j1);
    long written = 0;
    for (int j = j0; j <= j1; j++) {
        int lo = i0, hi = i1;
        if (!row_span(F, edges, j, &lo, &hi)) continue;
        written += nearest ? span_nearest(F, T, j, lo, hi) : fill_span(F, T, t, j, lo, hi);
    }
    return written;
}

/* The common case (nearest test, no ids, peeling or clamping) of a larger
 * triangle: one call per triangle and tile, its rows' edge solves and loops
 * inlined (AVX2 where the CPU has it) rather than a call per row (bunny
 * 4096^2: 7.6-7.7 -> 7.1-7.3 ms, bench/README.md, step 10). row_span and
 * crossing_edges are always inlined: called from the AVX2 clone as
 * functions of the default ISA, they took the bunny's 4096^2 map from 7.3 to
 * 10.3 ms. */
__attribute__((target_clones("avx2", "default")))
static long fill_rect_nearest(const Fill *F, const Target *T, int i0, int j0, int i1, int j1)
{
    return rect_rows(F, T, NULL, i0, j0, i1, j1, true);
}

static long fill_rect(const Fill *F, const Target *T, const SnapTri *t, int i0, int j0, int i1, int j1)
{
    return rect_rows(F, T, t, i0, j0, i1, j1, false);
}

/* The common case (nearest test, no ids, peeling or clamping) of a small
 * triangle: each texel of the box [i0, i1] x [j0, j1] (at most SMALL_W wide)
 * is tested against the three edge functions themselves, the definition
 * row_span solves exactly, in branch-free int32 lanes the compiler
 * vectorises (AVX2 where the CPU has it), instead of three divisions per
 * row. Edge values are exact: the box lies inside the vertex box, where
 * |E| < 2^28 (SnapTri.small). */
__attribute__((target_clones("avx2", "default")))
static long fill_small(const Fill *F, const Target *T, int i0, int j0, int i1, int j1)
{
    int n = i1 - i0 + 1;
    int64_t px = (int64_t)i0 * SUB + HALF;
    double fs = F->fx * SUB, qs = F->qx * SUB;
    const int32_t step[3] = {(int32_t)(F->a[0] * SUB), (int32_t)(F->a[1] * SUB), (int32_t)(F->a[2] * SUB)};
    bool persp = T->perspective;
    long written = 0;
    for (int j = j0; j <= j1; j++) {
        int64_t py = (int64_t)j * SUB + HALF;
        int32_t e[3];
        for (int k = 0; k < 3; k++) e[k] = (int32_t)(F->a[k] * px + F->b[k] * py + F->c[k]);
        double f_row, q_row;
        row_planes(F, i0, j, &f_row, &q_row);
        float *d = tile_row(T, j, i0);
        written += nearest_row(d, n, f_row, fs, q_row, qs, persp, true, e, step);
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
        double t = dmin(dmax((d[i] - lo) / range, 0.0), 1.0);
        d[i] = (float)(lo + round(t * levels) / levels * range);
    }
}

/* A finished tile row into the map: n floats from src to dst, with
 * non-temporal stores where `stream` (a map over RASTER_STREAM_MIN_BYTES, more than
 * a core complex's last-level cache on most CPUs: the lines go to memory
 * without being read first) and dst is 16-byte aligned. The same for the
 * set-up triangles (SnapTri) measured slower at every size (bench/README.md,
 * step 9). */
static void row_store(float *dst, const float *src, int n, bool stream)
{
#if defined(__SSE2__)
    if (stream && ((uintptr_t)dst & 15) == 0) {
        int i = 0;
        for (; i + 4 <= n; i += 4) _mm_stream_ps(dst + i, _mm_loadu_ps(src + i));
        for (; i < n; i++) dst[i] = src[i];
        return;
    }
#endif
    memcpy(dst, src, sizeof *dst * (size_t)n);
}

/* Non-temporal stores before are visible before any store after. */
static void store_fence(void)
{
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

static long fill_tile(const Setup *s, int tile, const SnapTri *const *bins, const int *bin_start, DepthBuffer *db,
                      long *overflow)
{
    int tx = tile % s->tiles_x, ty = tile / s->tiles_x;
    int ti0 = tx * TILE, tj0 = ty * TILE;
    int ti1 = ti0 + TILE - 1 < s->width - 1 ? ti0 + TILE - 1 : s->width - 1;
    int tj1 = tj0 + TILE - 1 < s->height - 1 ? tj0 + TILE - 1 : s->height - 1;
    const RasterOptions *opt = s->opt;
    float local[TILE * TILE];
    bool counting = opt->test == RASTER_COUNT_LESS || opt->test == RASTER_COUNT_GREATER;
    Target T = {local, ti0, tj0, db->triangle, opt->peel, opt->peel_epsilon, s->width, opt->test == RASTER_FARTHEST,
                s->mode == VALUE_PERSPECTIVE && opt->depth == RASTER_DEPTH_LINEAR, opt->conservative,
                counting ? opt->count : NULL, opt->count_ref, opt->test == RASTER_COUNT_LESS, overflow};
    float empty = T.farthest ? -INFINITY : INFINITY;
    bool fast = !T.farthest && !T.id && !T.peel && !T.conservative && !counting; /* fill_small's case */
    int n = ti1 - ti0 + 1;
    bool unbinned = bin_start[tile] == bin_start[tile + 1]; /* no triangle: one empty row stored to every row */
    for (int i = 0; !counting && i < (unbinned ? TILE : TILE * TILE); i++) local[i] = empty;
    for (int j = tj0; db->triangle && j <= tj1; j++) {
        int32_t *id = db->triangle + (size_t)j * s->width + ti0;
        for (int i = 0; i < n; i++) id[i] = -1;
    }
    /* The tile's map lines asked for with intent to write while its
     * triangles are drawn, so the rows' ordinary stores at the end find
     * them owned: a tile's rows lie a map row apart (8 KiB at 2048^2), a
     * stride the hardware prefetchers do not follow, and each store
     * otherwise waited for its line (bunny 2048^2, 2 threads: 4.9-6.3 ->
     * 3.4 ms; step 10). Streamed maps need no lines. */
    for (int j = tj0; !counting && !s->stream && j <= tj1; j++)
        for (int i = 0; i < n; i += BUFPOOL_ALIGN / (int)sizeof(float))
            __builtin_prefetch(db->depth + (size_t)j * s->width + ti0 + i, 1, 3);
    long written = 0;
    for (int b = bin_start[tile]; b < bin_start[tile + 1]; b++) {
        const SnapTri *t = bins[b];
        if (b + PREFETCH_AHEAD < bin_start[tile + 1]) __builtin_prefetch(bins[b + PREFETCH_AHEAD]);
        Fill F;
        fill_setup(t, opt, T.perspective, &F);
        int i0 = t->i0 > ti0 ? t->i0 : ti0, i1 = t->i1 < ti1 ? t->i1 : ti1;
        int j0 = t->j0 > tj0 ? t->j0 : tj0, j1 = t->j1 < tj1 ? t->j1 : tj1;
        if (i0 > i1 || j0 > j1) continue;
        written += !fast       ? fill_rect(&F, &T, t, i0, j0, i1, j1)
                   : t->small ? fill_small(&F, &T, i0, j0, i1, j1)
                              : fill_rect_nearest(&F, &T, i0, j0, i1, j1);
    }
    if (counting) return written;
    bool quantised = opt->depth_bits == 16 || opt->depth_bits == 24;
    double lo = opt->depth == RASTER_DEPTH_NDC ? 0.0 : s->view->depth_near;
    double hi = opt->depth == RASTER_DEPTH_NDC ? 1.0 : s->view->depth_far;
    for (int j = tj0; j <= tj1; j++) {
        float *row = unbinned ? local : tile_row(&T, j, ti0);
        if (quantised && !unbinned) quantise(row, (size_t)n, opt->depth_bits, lo, hi);
        row_store(db->depth + (size_t)j * s->width + ti0, row, n, s->stream);
    }
    if (s->stream) store_fence();
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

/* Pass 2 over one chunk of the triangles of every mesh, into a copy of the
 * chunk's ThreadTris on this thread's stack: the chunks' records share cache
 * lines, and two threads bumping neighbouring counts per triangle would pull
 * the line back and forth (false sharing). */
static bool setup_chunk(const Setup *s, const RasterMesh *meshes, int num_meshes, const Vertices *vx, long t0,
                        long t1, ThreadTris *chunk)
{
    ThreadTris local = *chunk, *tt = &local;
    bool ok = true;
    long base = 0;
    for (int m = 0; ok && m < num_meshes; m++) {
        long n = meshes[m].num_triangles;
        long lo = t0 > base ? t0 : base, hi = t1 < base + n ? t1 : base + n;
        const uint32_t *ix = meshes[m].indices;
        for (long t = lo; ok && t < hi; t++) {
            if (t + PREFETCH_AHEAD < hi) {
                const uint32_t *ahead = &ix[3 * (t + PREFETCH_AHEAD - base)];
                for (int k = 0; k < 3; k++) __builtin_prefetch(&vx[m].v[ahead[k]]);
            }
            const int16_t *counts = s->opt->extra ? s->opt->extra[m].counts : NULL;
            int32_t count = counts ? counts[t - base] : 1;
            ok = setup_triangle(s, &vx[m], &ix[3 * (t - base)], (int32_t)t, count, tt);
        }
        base += n;
    }
    *chunk = local;
    return ok;
}

/* Pass 3's offsets, a parallel prefix sum over tiles x chunks, run by every
 * thread of the region: bins are tile-major and in chunk order within a
 * tile, so bin_start[tile] is where the tile's bin begins and
 * cursor[k ntiles + tile] where chunk k's triangles of it go. Each thread
 * sums a contiguous block of tiles, waits for the others, then offsets its
 * block by the sums of the blocks before it (block_sum: one per thread). */
static void bin_offsets(const ThreadTris *tt, int nchunks, int ntiles, int *bin_start, int *cursor, long *block_sum)
{
    int nt = omp_get_num_threads(), id = omp_get_thread_num();
    int first = (int)((long)ntiles * id / nt), end = (int)((long)ntiles * (id + 1) / nt);
    long sum = 0;
    for (int tile = first; tile < end; tile++)
        for (int k = 0; k < nchunks; k++) sum += tt[k].tile_count[tile];
    block_sum[id] = sum;
#pragma omp barrier
    long at = 0;
    for (int i = 0; i < id; i++) at += block_sum[i];
    for (int tile = first; tile < end; tile++) {
        bin_start[tile] = (int)at;
        for (int k = 0; k < nchunks; k++) {
            cursor[(size_t)k * ntiles + tile] = (int)at;
            at += tt[k].tile_count[tile];
        }
    }
    if (id == nt - 1) bin_start[ntiles] = (int)at;
}

/* Pass 3's scatter of one chunk's triangles into their tiles' bins. */
static void bin_chunk(const Setup *s, const ThreadTris *tt, int *cursor, const SnapTri **bins)
{
    for (int i = 0; i < tt->count; i++) {
        TileBox b = tt->box[i];
        for (int ty = box_y0(b); ty <= box_y1(b); ty++)
            for (int tx = box_x0(b); tx <= box_x1(b); tx++) bins[cursor[ty * s->tiles_x + tx]++] = &tt->tri[i];
    }
}

/* Passes 3 and 4 in one parallel region (threads wait at its barriers, not
 * at a fork per pass): bin offsets, the scatter per chunk, then the tiles. */
static long bin_and_fill(const Setup *s, RasterScratch *sc, int nchunks, DepthBuffer *db, bool *ok, long *overflow)
{
    ThreadTris *tt = sc->chunk;
    int ntiles = s->tiles_x * s->tiles_y;
    long total = 0; /* bin entries, counted during set-up */
    for (int k = 0; k < nchunks; k++) total += tt[k].entries;
    int *bin_start = block_reserve(&sc->bin_start, sizeof(int) * (size_t)(ntiles + 1));
    int *cursor = block_reserve(&sc->cursor, sizeof(int) * (size_t)ntiles * (size_t)nchunks);
    long *block_sum = block_reserve(&sc->block_sum, sizeof(long) * (size_t)omp_get_max_threads());
    const SnapTri **bins = total < (long)1 << 31 ? block_reserve(&sc->bins, sizeof *bins * (size_t)total) : NULL;
    *ok = bin_start && cursor && block_sum && bins;
    if (!*ok) return 0;
    long written = 0, refused = 0;
#pragma omp parallel reduction(+ : written, refused)
    {
        bin_offsets(tt, nchunks, ntiles, bin_start, cursor, block_sum);
#pragma omp barrier
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < nchunks; k++) bin_chunk(s, &tt[k], cursor + (size_t)k * ntiles, bins);
        /* Row of tiles k is thread k mod N's: the same core every render,
         * balanced on any scene, and each map row's stretch of a tile row
         * written by one core (alternate tiles of a row on alternate cores
         * took 2.8-3.7x as long to store an empty map, bench/README.md,
         * step 10). */
#pragma omp for schedule(static, s->tiles_x)
        for (int tile = 0; tile < ntiles; tile++) written += fill_tile(s, tile, bins, bin_start, db, &refused);
    }
    *overflow = refused;
    return written;
}

static bool check_inputs(const RasterMesh *meshes, int num_meshes, const RasterView *view, const RasterOptions *opt,
                         const DepthBuffer *db, Error *err)
{
    bool counting = opt->test == RASTER_COUNT_LESS || opt->test == RASTER_COUNT_GREATER;
    if ((!counting && !db->depth) || db->width < 1 || db->height < 1)
        return error_set(err, "raster: depth buffer not initialised");
    if (counting && (!opt->count || !opt->count_ref))
        return error_set(err, "raster: a counting test needs counters and reference values per texel");
    if (opt->triangle_ids && !db->triangle) return error_set(err, "raster: triangle ids asked for but not allocated");
    if (!(opt->peel_epsilon >= 0.0f) || isinf(opt->peel_epsilon))
        return error_set(err, "raster: peel_epsilon %g outside [0, inf)", (double)opt->peel_epsilon);
    if (opt->depth_bits != 0 && opt->depth_bits != 16 && opt->depth_bits != 24)
        return error_set(err, "raster: depth_bits %d is not one of 0 (float32), 16, 24", opt->depth_bits);
    if (view->mapping == RASTER_PARABOLOID && !(view->depth_far > view->depth_near))
        return error_set(err, "raster: paraboloid depth range [%g, %g] is empty", view->depth_near, view->depth_far);
    long total = 0;
    for (int m = 0; m < num_meshes; m++) total += meshes[m].num_triangles;
    if (total >= INT32_MAX) return error_set(err, "raster: %ld triangles exceed the id range", total);
    return true;
}

/* The scratch sized for this render: vertex arrays per mesh, and per chunk
 * room for the whole chunk up front (most triangles survive, and growing
 * copies them all) and zeroed tile counts. */
static bool scratch_prepare(RasterScratch *sc, const RasterMesh *meshes, int num_meshes, const Setup *s, int nchunks,
                            long chunk, Vertices *cv)
{
    size_t nv = 0;
    for (int m = 0; m < num_meshes; m++) nv += (size_t)meshes[m].num_vertices;
    RVertex *v = block_reserve(&sc->vertices, sizeof *v * nv);
    size_t ntiles = (size_t)s->tiles_x * (size_t)s->tiles_y;
    int *counts = block_reserve(&sc->tile_counts, sizeof(int) * ntiles * (size_t)nchunks);
    if (!v || !counts) return false;
    const RasterMeshExtra *extra = s->opt->extra;
    for (int m = 0; m < num_meshes; v += meshes[m].num_vertices, m++)
        cv[m] = (Vertices){v, &meshes[m], extra ? extra[m].weights : NULL};
    if (nchunks > sc->num_chunks) {
        ThreadTris *n = realloc(sc->chunk, sizeof *n * (size_t)nchunks);
        if (!n) return false;
        memset(n + sc->num_chunks, 0, sizeof *n * (size_t)(nchunks - sc->num_chunks));
        sc->chunk = n;
        sc->num_chunks = nchunks;
    }
    memset(counts, 0, sizeof(int) * ntiles * (size_t)nchunks);
    int cap = (int)(chunk < INT32_MAX / 2 ? chunk + 16 : INT32_MAX / 2);
    for (int k = 0; k < nchunks; k++) {
        ThreadTris *t = &sc->chunk[k];
        if (t->cap < cap) {
            free(t->tri);
            free(t->box);
            t->tri = malloc(sizeof *t->tri * (size_t)cap);
            t->box = malloc(sizeof *t->box * (size_t)cap);
            t->cap = t->tri && t->box ? cap : 0;
            if (!t->cap) return false;
        }
        *t = (ThreadTris){t->tri, t->box, 0, t->cap, counts + (size_t)k * ntiles, 0, 0, 0};
    }
    return true;
}

bool raster_depth(const RasterMesh *meshes, int num_meshes, const RasterView *view, const RasterOptions *opt,
                  DepthBuffer *db, RasterStats *stats, Error *err)
{
    if (!check_inputs(meshes, num_meshes, view, opt, db, err)) return false;
    Setup s = {view, opt, value_mode(view, opt), db->width, db->height, (db->width + TILE - 1) / TILE,
               (db->height + TILE - 1) / TILE, (size_t)db->width * (size_t)db->height * sizeof(float) > RASTER_STREAM_MIN_BYTES};
    long total = 0;
    for (int m = 0; m < num_meshes; m++) total += meshes[m].num_triangles;
    /* More chunks than threads: set-up takes them in contiguous blocks (a
     * static schedule, see transform_vertices), binning dynamically; chunk
     * order, not thread order, fixes each tile's triangle order. */
    int nthreads = omp_get_max_threads();
    long by_size = total / CHUNK_TRIANGLES + 1;
    int nchunks = (int)(by_size < 4L * nthreads ? by_size : 4L * nthreads);
    long chunk = (total + nchunks - 1) / nchunks;
    if (!db->scratch) db->scratch = calloc(1, sizeof *db->scratch);
    Vertices *cv = calloc((size_t)(num_meshes > 0 ? num_meshes : 1), sizeof *cv);
    bool ok = db->scratch && cv && scratch_prepare(db->scratch, meshes, num_meshes, &s, nchunks, chunk, cv);
    ThreadTris *tt = ok ? db->scratch->chunk : NULL;
    for (int m = 0; ok && m < num_meshes; m++) transform_vertices(&s, &cv[m]);
    if (ok) {
        int failed = 0;
#pragma omp parallel for schedule(static) reduction(+ : failed)
        for (int k = 0; k < nchunks; k++) failed += !setup_chunk(&s, meshes, num_meshes, cv, k * chunk,
                                                              (k + 1) * chunk < total ? (k + 1) * chunk : total, &tt[k]);
        ok = failed == 0;
    }
    long overflow = 0;
    long written = ok ? bin_and_fill(&s, db->scratch, nchunks, db, &ok, &overflow) : 0;
    RasterStats st = {total, 0, 0, 0, written};
    for (int k = 0; ok && k < nchunks; k++) {
        st.triangles_culled += tt[k].culled;
        st.triangles_clipped += tt[k].clipped;
        st.triangles_drawn += tt[k].count;
    }
    free(cv);
    if (stats) *stats = st;
    work_raster((uint64_t)st.triangles_in, (uint64_t)st.texels_written); /* counters.h */
    if (!ok) return error_set(err, "raster: out of memory (%ld triangles into %dx%d)", total, db->width, db->height);
    if (overflow)
        return error_set(err, "raster: %ld counter updates refused: the count would leave int32 [%d, %d]", overflow,
                         INT32_MIN, INT32_MAX);
    return true;
}
