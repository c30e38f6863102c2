/* soft_shadow_volume.c -- the wedge family of course §5.3.2: `soft_shadow_volume`
 * (Assarsson & Akenine-Möller 2003) and `penumbra_wedge` (Akenine-Möller &
 * Assarsson 2002), on the hard volume's machinery (resources/geometry/silhouette.h,
 * techniques/shadow_volume.h).
 *
 * Both start from the silhouette edges of one point c of the light (the
 * centre, or each patch's centre when the light is split) and from the hard
 * shadow volume's count w(c) at each view sample p: the number of volumes p
 * is in, i.e. the winding number about c of the casters' silhouette loops
 * projected from p onto the light's plane. The winding number about any
 * other light point x is w(c) plus the signed crossings of the segment c -> x
 * by projected silhouette edges, so the covered area of the light K is
 *
 *     A = w(c) |K| + sum_e sign_e count_e |R_e|,   R_e = {x in K : c->x crosses e}
 *
 * (Green's theorem over the light, course §5.3.2: each edge's term is local
 * to its wedge, the set of p whose projected edge meets K; the hard volume
 * fixes the integration constant). R_e is K cut by the cone from c through
 * the edge's endpoints and by the edge's line; its area is exact for a
 * rectangle (polygon clipping) and for a disk (polygon-circle area by signed
 * triangle-circle sectors). Visibility is 1 - A / |K| clamped to [0, 1]:
 * where the casters' projections overlap, A counts the overlap twice, the
 * additive fusion that over-darkens (course Figs. 1.7 and 5.19); the
 * unclamped A / |K| is the aux channel `coverage`.
 *
 * `penumbra_wedge` differs in the edge term only (2002): the edge is taken as
 * its infinite line and the light as a linear ramp across it, so the term is
 * |K| max(0, 1/2 - d / 2e) (d: the distance from c to the projected line, e:
 * the light's half extent across it), counted in the wedge whose edge holds
 * the foot of the perpendicular from c (the wedge's side planes). Silhouette
 * corners and edges shorter than the penumbra are where it departs from the
 * exact term.
 *
 * Lights: a rectangle and a disk in their own plane; a sphere as the disk
 * through its centre facing p. A split sphere's patch centres are fixed
 * points (each has its own volume) on the disk facing the scene's centre,
 * projected from p onto the plane facing p (domain_at). Splitting into 2x2 or 3x3 patches (Assarsson et al. 2003) gives
 * each patch its own centre silhouette, which shortens the edges' reach and
 * the popping when a centre silhouette changes.
 *
 * Wedges from the camera (Assarsson & Akenine-Möller 2003: each wedge is
 * rasterised and only the pixels inside it run the coverage): a sample p
 * needs edge a-b only if some segment from a point y of the light's region
 * Y to p crosses the edge (p = y + t (q - y), q on the edge, t >= 1), so the
 * wedge lies in conv(a, b) + cone(a - x_i, b - x_i) over the corners x_i of
 * a box holding Y. That polyhedron's stand-in (camera_count_stand_in: its
 * projected hull at its nearest depth) is drawn from the camera into
 * per-sample lists (camera_count_lists), and each sample sums the terms of
 * its listed edges, in edge order, after the same per-sample bounding cone
 * (edge_may_meet) as an all-edges loop, so the sum is the all-edges loop's
 * bit for bit. A wedge reaching the camera's near plane is cut by the plane
 * at NEAR_CUT times the near distance first (cut_at_near), so only the
 * samples its cut part covers get it; the few samples nearer than that
 * plane sum every edge; a wedge whose cut part is unbounded along the plane
 * (its directions on both sides of it) is still evaluated at every sample.
 * Measured at 160x120 on the
 * bunny (test_soft_volumes, load 4, 2 threads): frame 0.30 s against 0.83 s
 * for the all-edges loop, evaluation 0.066 s against 0.72 s. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/mat4.h"
#include "core/nanmath.h"
#include "raster/camera_count.h"
#include "resources/geometry/silhouette.h"
#include "rt/view.h"
#include "techniques/shadow_volume.h"
#include "techniques/radial_area.h"
#include "techniques/soft_shadow_volume.h"
#include "techniques/technique.h"

enum { SSV_PATCHES, SSV_OFFSET };
enum { TERM_EXACT, TERM_LINEAR };
#define MAX_PER_SIDE 3

static const ParamDesc ssv_params[] = {
    {"patches", PARAM_INT, 1, 1, MAX_PER_SIDE, "per side",
     "the light split into patches x patches cells (1, 2x2 or 3x3), each with its own centre silhouette and hard "
     "volume (Assarsson et al. 2003's light splitting)",
     NULL},
    {"offset_scale", PARAM_FLOAT, 1.0, 0.0, 1e4, "x rt_ray_offset",
     "the hard volumes' test point: each sample moved toward the camera by this multiple of the engine's ray offset "
     "(shadow_volume's offset_scale)",
     NULL},
};

static const char *const ssv_resources[] = {"silhouette", NULL};
static const char *const ssv_aux[] = {"coverage", NULL};

/* One patch: its centre (world), its cell's offset from the light's centre in
 * the light's fixed frame, its silhouette and hard counts. */
typedef struct Patch {
    dvec3 centre;
    double u, v;        /* cell centre - light centre along the fixed frame's t and b (world units) */
    double area;        /* |K_i|: the cell, cut by the disk for round lights (world units^2) */
    const Silhouette *sil;
    int32_t *count;     /* w(centre) per view sample */
    CameraLists wedges; /* per view sample, the edges whose wedge stand-in covers it */
    int32_t *everywhere;/* edges whose wedge has no bounded stand-in even cut at the near plane, ascending */
    int num_everywhere;
    int num_cut;        /* wedges reaching the camera's near plane, cut there (cut_at_near) */
    double near_depth;  /* samples nearer than this along the view axis sum every edge (0: none) */
    bool all_edges;     /* no lists: every edge at every sample (ssv_set_all_edges) */
} Patch;

typedef struct SsvState {
    int term;           /* TERM_EXACT or TERM_LINEAR */
    bool round;         /* disk or sphere: cells are cut by the disk */
    bool facing;        /* sphere: the disk faces each sample */
    dvec3 c0, t0, b0, n0; /* the light's centre and fixed frame (n0 toward the scene) */
    double radius;      /* round lights (world units) */
    double hx, hy;      /* a cell's half sides (world units) */
    int num_patches;
    Patch patch[MAX_PER_SIDE * MAX_PER_SIDE];
    double area;        /* sum of the patches' areas */
    dvec3 corner[8];    /* a box holding the light's region Y of every patch (world) */
    int num_corners;    /* 4 for a flat light, 8 for a sphere */
    double trust;       /* the lists hold for samples at least this far from c0 (world units) */
} SsvState;

static bool all_edges_mode;
void ssv_set_all_edges(bool on) { all_edges_mode = on; }
static SsvNearStats near_stats;
SsvNearStats ssv_near_stats(void) { return near_stats; }

/* ---- 2D geometry in the light's plane (origin: the patch centre) ------------ */

/* Area of a counter-clockwise convex polygon, cut by the disk (centre o,
 * radius r) when round. */
static double poly_area(const P2 *poly, int n, bool round, P2 o, double r)
{
    double a = 0.0;
    for (int i = 0; i < n; i++) {
        P2 p = poly[i], q = poly[(i + 1) % n];
        a += round ? tri_disk_area((P2){p.x - o.x, p.y - o.y}, (P2){q.x - o.x, q.y - o.y}, r) : 0.5 * cross2(p, q);
    }
    return a;
}

/* The rectangle of centre c and half sides hx, hy, counter-clockwise. */
static int rect_poly(P2 c, double hx, double hy, P2 *poly)
{
    poly[0] = (P2){c.x - hx, c.y - hy};
    poly[1] = (P2){c.x + hx, c.y - hy};
    poly[2] = (P2){c.x + hx, c.y + hy};
    poly[3] = (P2){c.x - hx, c.y + hy};
    return 4;
}

/* The light's part K of a patch seen from p: the cell (cut by the disk when
 * round) above p's tangent plane, the reference's domain (light.h: the
 * horizon is shading, not shadow). */
typedef struct Domain {
    P2 poly[POLY_MAX];
    int n;
    P2 cell;            /* the cell's centre */
    double hx, hy;      /* its half sides */
    P2 o;               /* the disk's centre */
    double r;           /* its radius */
    double scale;       /* lengths on this plane over those on the light's own (see domain_at) */
    double area;        /* |K| on this plane (world units^2) */
} Domain;

/* Exact term (2003): |R_e|, K beyond the projected edge a -> b inside the
 * cone from the origin through a and b; s = sign of cross(a, b), the side
 * of the edge the origin is on. */
static double term_exact(const SsvState *st, const Domain *k, P2 a, P2 b, double s)
{
    P2 poly[POLY_MAX], u = {b.x - a.x, b.y - a.y};
    memcpy(poly, k->poly, sizeof poly);
    int n = k->n;
    n = clip_half_plane(poly, n, -s * a.y, s * a.x, 0.0);  /* s cross(a, x) >= 0 */
    n = clip_half_plane(poly, n, s * b.y, -s * b.x, 0.0);  /* s cross(x, b) >= 0 */
    n = clip_half_plane(poly, n, s * u.y, -s * u.x, s * cross2(u, a)); /* s cross(u, x - a) <= 0: beyond */
    return n >= 3 ? poly_area(poly, n, st->round, k->o, k->r) : 0.0;
}

/* Linear term (2002): the light as a ramp across the edge's infinite line,
 * counted where the foot of the perpendicular from the origin lies on the
 * edge (half-open, so a shared vertex's foot counts once). */
static double term_linear(const SsvState *st, const Domain *k, P2 a, P2 b)
{
    P2 o = k->o;
    P2 u = {b.x - a.x, b.y - a.y};
    double uu = u.x * u.x + u.y * u.y;
    if (!(uu > 0.0)) return 0.0;
    double foot = -(a.x * u.x + a.y * u.y) / uu;
    if (foot < 0.0 || foot >= 1.0) return 0.0;
    double len = sqrt(uu), nx = -u.y / len, ny = u.x / len, d = fabs(cross2(a, b)) / len;
    /* the light's half extent across the line, from the origin */
    double e = k->hx * fabs(nx) + k->hy * fabs(ny) + fabs(k->cell.x * nx + k->cell.y * ny);
    if (st->round) {
        double disk = k->r + fabs(o.x * nx + o.y * ny);
        e = disk < e ? disk : e;
    }
    if (!(e > 0.0)) return 0.0;
    return k->area * nan_clamp(0.5 - d / (2.0 * e), 0.0, 0.5);
}

/* ---- one sample --------------------------------------------------------------- */

typedef struct Frame { dvec3 t, b, n; } Frame;

static void basis(dvec3 n, dvec3 *t, dvec3 *b)
{
    dvec3 axis = fabs(n.x) < 0.6 ? d3(1, 0, 0) : d3(0, 1, 0);
    *t = d3_normalize_or(d3_cross(axis, n), d3(0, 0, 1));
    *b = d3_cross(n, *t);
}

/* The light's frame at p: (t, b, n) right-handed, n toward p. */
static Frame frame_at(const SsvState *st, dvec3 p)
{
    Frame f = {st->t0, st->b0, st->n0};
    if (st->facing) { /* t: the fixed frame's, turned into the facing plane */
        f.n = d3_normalize_or(d3_sub(p, st->c0), st->n0);
        f.t = d3_normalize_or(d3_madd(st->t0, f.n, -d3_dot(st->t0, f.n)), d3(0, 0, 0));
        if (d3_dot(f.t, f.t) == 0.0) basis(f.n, &f.t, &f.b);
        f.b = d3_cross(f.n, f.t);
    } else if (d3_dot(d3_sub(p, st->c0), st->n0) < 0.0) {
        f.n = d3_scale(st->n0, -1.0);
        f.b = d3_scale(st->b0, -1.0);
    }
    return f;
}

/* Wedge culling: false when edge a-b (midpoint m, half length hl) lies
 * outside the cone from p around the light's bounding sphere (c, rb), so
 * its projection misses the light. */
static bool edge_may_meet(dvec3 p, dvec3 c, double rb, dvec3 a, dvec3 b)
{
    dvec3 axis = d3_sub(c, p), m = d3_scale(d3_add(a, b), 0.5);
    double L = d3_len(axis), hl = 0.5 * d3_len(d3_sub(b, a));
    if (!(L > rb)) return true;
    dvec3 q = d3_sub(m, p);
    double along = d3_dot(q, axis) / L, sin_t = rb / L, cos_t = sqrt(1.0 - sin_t * sin_t);
    if (along + hl < 0.0 || along - hl > L + rb) return false;
    double radial = d3_len(d3_madd(q, axis, -along / L));
    return radial <= (along + hl) * (sin_t / cos_t) + hl / cos_t;
}

/* K for patch pa at p (normal n_p, geometric), on the plane through the
 * patch's centre c_i parallel to the light's (through c0, normal f.n): the
 * light's cell and disk projected from p onto it, which scales them about p
 * by s = h_i / h_0 (the heights of p above the two planes; s = 1 but for a
 * sphere's patches, whose fixed centres lie off the plane facing p), cut by
 * p's tangent plane n_p . (c_i + x t + y b - p) >= 0 when `cut`. */
static void domain_at(const SsvState *st, const Patch *pa, dvec3 p, dvec3 n_p, const Frame *f, bool cut, Domain *k)
{
    double h0 = d3_dot(d3_sub(p, st->c0), f->n), hi = d3_dot(d3_sub(p, pa->centre), f->n);
    double s = h0 > 0.0 && hi > 0.0 ? hi / h0 : 1.0, side = d3_dot(f->b, st->b0) < 0.0 ? -1.0 : 1.0;
    dvec3 g = d3_add(d3_scale(d3_sub(st->c0, p), s), d3_sub(p, pa->centre)); /* c0 projected, from c_i */
    k->o = (P2){d3_dot(g, f->t), d3_dot(g, f->b)};
    k->cell = (P2){k->o.x + s * pa->u, k->o.y + s * side * pa->v};
    k->hx = s * st->hx;
    k->hy = s * st->hy;
    k->r = s * st->radius;
    k->scale = s;
    k->n = rect_poly(k->cell, k->hx, k->hy, k->poly);
    if (cut)
        k->n = clip_half_plane(k->poly, k->n, d3_dot(n_p, f->t), d3_dot(n_p, f->b), d3_dot(n_p, d3_sub(pa->centre, p)));
    k->area = k->n >= 3 ? poly_area(k->poly, k->n, st->round, k->o, k->r) : 0.0;
}

/* The edges a sample sums, ascending: its wedge list merged with the
 * patch's `everywhere` edges, or every edge. */
typedef struct EdgeCursor {
    const int32_t *list, *every;
    long n_list, n_every, i_list, i_every;
    int all, next_all; /* all > 0: edges 0 .. all-1 */
} EdgeCursor;

static EdgeCursor edge_cursor(const Patch *pa, int s, float depth_view, bool all)
{
    if (all || pa->all_edges || depth_view < pa->near_depth) return (EdgeCursor){.all = pa->sil->num_edges};
    const CameraLists *l = &pa->wedges;
    return (EdgeCursor){.list = l->item + l->start[s], .n_list = l->start[s + 1] - l->start[s],
                        .every = pa->everywhere, .n_every = pa->num_everywhere};
}

static int next_edge(EdgeCursor *c)
{
    if (c->all) return c->next_all < c->all ? c->next_all++ : -1;
    bool from_list = c->i_list < c->n_list, from_every = c->i_every < c->n_every;
    if (from_list && from_every) from_list = c->list[c->i_list] < c->every[c->i_every];
    return from_list ? c->list[c->i_list++] : from_every ? c->every[c->i_every++] : -1;
}

/* A patch's covered area of K at p: w |K| plus its silhouette edges' terms
 * (the edges `edges` yields). */
static double patch_covered(const SsvState *st, const Patch *pa, int32_t w, dvec3 p, const Frame *f, const Domain *k,
                            EdgeCursor edges)
{
    dvec3 c = pa->centre;
    double hp = d3_dot(d3_sub(p, c), f->n);
    if (!(hp > 0.0)) return w != 0 ? k->area : 0.0; /* p on the light's plane: the centre decides */
    double rb = sqrt(k->cell.x * k->cell.x + k->cell.y * k->cell.y) + sqrt(k->hx * k->hx + k->hy * k->hy), hmax = hp * (1.0 - 1e-6), a_cov = (double)w * k->area;
    for (int i = next_edge(&edges); i >= 0; i = next_edge(&edges)) {
        const SilEdge *e = &pa->sil->edges[i];
        dvec3 a = d3_from(e->a), b = d3_from(e->b);
        if (!edge_may_meet(p, c, rb, a, b)) continue;
        /* the part of the edge between the light's plane and p's parallel plane */
        double ha = d3_dot(d3_sub(a, c), f->n), hb = d3_dot(d3_sub(b, c), f->n), t0 = 0.0, t1 = 1.0;
        if (ha < 0.0 && hb < 0.0) continue;
        if (ha > hmax && hb > hmax) continue;
        if (ha != hb) {
            double ta = (0.0 - ha) / (hb - ha), tm = (hmax - ha) / (hb - ha);
            double lo = ta < tm ? ta : tm, hi = ta < tm ? tm : ta;
            t0 = lo > t0 ? lo : t0;
            t1 = hi < t1 ? hi : t1;
            if (!(t1 > t0)) continue;
        }
        P2 q2[2];
        for (int j = 0; j < 2; j++) {
            double t = j ? t1 : t0, h = ha + (hb - ha) * t;
            dvec3 q = d3_madd(a, d3_sub(b, a), t);
            /* central projection from p onto the plane h = 0 (course §5.3.2) */
            dvec3 x = d3_madd(d3_sub(p, c), d3_sub(q, p), hp / (hp - h));
            q2[j] = (P2){d3_dot(x, f->t), d3_dot(x, f->b)};
        }
        double cr = cross2(q2[0], q2[1]);
        if (cr == 0.0) continue; /* the edge projects through the centre: its wedge is a plane */
        double s = cr > 0.0 ? 1.0 : -1.0;
        double term = st->term == TERM_EXACT ? term_exact(st, k, q2[0], q2[1], s) : term_linear(st, k, q2[0], q2[1]);
        /* the silhouette's loops run clockwise in (t, b) seen from p: crossing
         * c -> x over an edge with c on its right enters a loop */
        a_cov += (double)e->count * s * term;
    }
    return a_cov;
}

/* The covered fraction of the light's part above p's tangent plane, each
 * patch's areas taken back to the light's own plane (over s^2); a part too
 * thin to have area leaves the whole light (its visible fraction tends to
 * that of its highest point, as the reference's one ray). */
static double covered_fraction(const SsvState *st, const ViewSamples *vs, int s)
{
    dvec3 p = d3_from(vs->p_world[s]), n_p = d3_from(vs->n_geom_world[s]);
    Frame f = frame_at(st, p);
    Domain k[MAX_PER_SIDE * MAX_PER_SIDE];
    double area = 0.0, covered = 0.0;
    for (int cut = 1; cut >= 0 && !(area > 1e-9 * st->area); cut--) {
        area = 0.0;
        for (int i = 0; i < st->num_patches; i++) {
            domain_at(st, &st->patch[i], p, n_p, &f, cut, &k[i]);
            area += k[i].area / (k[i].scale * k[i].scale);
        }
    }
    bool all = !(d3_len(d3_sub(p, st->c0)) >= st->trust);
    for (int i = 0; i < st->num_patches; i++)
        if (k[i].area > 0.0)
            covered += patch_covered(st, &st->patch[i], st->patch[i].count[s], p, &f, &k[i],
                                     edge_cursor(&st->patch[i], s, vs->depth_view[s], all)) /
                       (k[i].scale * k[i].scale);
    return covered / area; /* area > 0: light_shape refuses a light without one */
}

static void ssv_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SsvState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        double cov = covered_fraction(st, ctx->vs, s);
        tech_store(ctx, out, begin, s, (float)(1.0 - nan_clamp(cov, 0.0, 1.0)));
        if (ctx->aux) ctx->aux[s] = (float)cov;
    }
}

/* ---- preparation ---------------------------------------------------------------- */

static void ssv_release(void *state)
{
    SsvState *st = state;
    if (!st) return;
    for (int i = 0; i < st->num_patches; i++) {
        free(st->patch[i].count);
        camera_lists_free(&st->patch[i].wedges);
        free(st->patch[i].everywhere);
    }
    free(st);
}

/* The box holding the region Y the wedges are built from (see the header):
 * the light's rectangle (a disk's square) for a flat light, where every
 * patch's K lies. For a sphere, K is the disk facing p through c0 (radius
 * r) projected from p onto the plane through the patch's centre c_i, which
 * scales it about p by s = h_i / h_0 <= 1 + r / h_0 (domain_at), so with
 * patches |y - c0| <= r + s r <= 3 r for samples at h_0 = |p - c0| >= r
 * (the cube of half side 3 r; inside the light sphere every edge is summed),
 * and Y is the disk itself with one patch (s = 1: the cube of half side r).
 * The linear term (2002) needs no crossing inside K: it counts where the
 * foot x_f of the perpendicular from c_i lies on the projected edge and
 * |x_f - c_i| = d < e, e at most the cell's half diagonal (a flat light:
 * within ex + ey of c0, the square of that half side) or, for a sphere,
 * r + |o| <= 2 r about c_i (within 3 r of c0; r with one patch). */
static void light_bound(SsvState *st, int per_side, double ex, double ey)
{
    double ez = st->facing ? st->radius * (per_side > 1 ? 3.0 : 1.0) : 0.0;
    if (st->facing) ex = ey = ez;
    else if (st->term == TERM_LINEAR) ex = ey = ex + ey;
    st->trust = st->facing && per_side > 1 ? st->radius : 0.0;
    st->num_corners = st->facing ? 8 : 4;
    for (int i = 0; i < st->num_corners; i++)
        st->corner[i] = d3_madd(d3_madd(d3_madd(st->c0, st->t0, i & 1 ? ex : -ex), st->b0, i & 2 ? ey : -ey), st->n0,
                                i & 4 ? ez : -ez);
}

/* The light's centre, fixed frame and cells. */
static void light_shape(const TechContext *ctx, int per_side, SsvState *st)
{
    const Light *l = ctx->light;
    st->c0 = d3_from(l->position);
    st->round = l->kind != LIGHT_RECT;
    st->facing = l->kind == LIGHT_SPHERE;
    if (l->kind == LIGHT_SPHERE) {
        const Scene *sc = ctx->scene;
        dvec3 mid = d3_scale(d3_add(d3_from(sc->bounds_min), d3_from(sc->bounds_max)), 0.5);
        st->n0 = d3_normalize_or(d3_sub(mid, st->c0), d3(0, -1, 0));
        basis(st->n0, &st->t0, &st->b0);
    } else {
        st->n0 = d3_from(l->direction);
        st->b0 = l->kind == LIGHT_RECT ? d3_from(l->up) : d3(0, 0, 0);
        if (l->kind == LIGHT_RECT) st->t0 = d3_cross(st->b0, st->n0); /* light.c's rect_right */
        else basis(st->n0, &st->t0, &st->b0);
    }
    st->radius = l->radius;
    double ex = st->round ? l->radius : 0.5 * l->width, ey = st->round ? l->radius : 0.5 * l->height;
    st->hx = ex / per_side;
    st->hy = ey / per_side;
    st->num_patches = per_side * per_side;
    st->area = 0.0;
    for (int j = 0; j < per_side; j++)
        for (int i = 0; i < per_side; i++) {
            Patch *pa = &st->patch[j * per_side + i];
            pa->u = -ex + (2 * i + 1) * st->hx;
            pa->v = -ey + (2 * j + 1) * st->hy;
            pa->centre = d3_madd(d3_madd(st->c0, st->t0, pa->u), st->b0, pa->v);
            P2 poly[POLY_MAX];
            int n = rect_poly((P2){pa->u, pa->v}, st->hx, st->hy, poly);
            pa->area = poly_area(poly, n, st->round, (P2){0.0, 0.0}, st->radius);
            st->area += pa->area;
        }
    light_bound(st, per_side, ex, ey);
}

/* ---- wedges cut at the camera's near plane ---------------------------------------- */

#define WEDGE_GEN_MAX (2 + 2 * 8) /* a wedge's generators: its 2 ends, each extruded from 8 corners */
#define NEAR_CUT (1.0 + 1e-3)     /* the cut plane's depth over the near distance: camera_count_stand_in
                                   * takes points past near (1 + 1e-6) / (1 - 1e-4) */


/* The wedge conv(points) + cone(directions) (gen: points w = 1, directions
 * w = 0, world) cut to the view depths d >= z_c: its generators at or past
 * the plane, and the plane's points where a segment or ray between one
 * past it and one before it crosses it, these replaced by their bounding
 * rectangle in the plane (the cut polyhedron's vertices lie on its edges,
 * each between two generators, and every such crossing lies in it, so the
 * hull of the result holds the cut wedge). Returns the generators (0: the
 * wedge lies before the plane), or -1 when the cut is unbounded along the
 * plane: a direction along it, or directions on both sides. */
static int cut_at_near(const double (*gen)[4], int m, const Camera *cam, dvec3 fwd, dvec3 right, dvec3 up,
                       double (*out)[4])
{
    dvec3 eye = d3_from(cam->position);
    double z_c = NEAR_CUT * cam->near_dist, l[WEDGE_GEN_MAX];
    bool ahead = false, behind = false;
    for (int i = 0; i < m; i++) {
        dvec3 q = d3(gen[i][0], gen[i][1], gen[i][2]);
        l[i] = gen[i][3] != 0.0 ? d3_dot(d3_sub(q, eye), fwd) - z_c : d3_dot(q, fwd);
        if (gen[i][3] != 0.0) continue;
        if (fabs(l[i]) <= 1e-9 * d3_len(q)) return -1;
        ahead |= l[i] > 0.0;
        behind |= l[i] < 0.0;
    }
    if (ahead && behind) return -1;
    int n = 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int i = 0; i < m; i++) {
        if (l[i] >= 0.0) memcpy(out[n++], gen[i], sizeof out[0]);
        if (gen[i][3] == 0.0) continue;
        dvec3 p = d3(gen[i][0], gen[i][1], gen[i][2]);
        for (int j = 0; j < m; j++) { /* p's segment or ray toward j, crossing the plane */
            if (j == i || (l[i] >= 0.0) == (l[j] >= 0.0) || (gen[j][3] != 0.0 && j < i)) continue;
            dvec3 q = d3(gen[j][0], gen[j][1], gen[j][2]);
            dvec3 x = gen[j][3] != 0.0 ? d3_madd(p, d3_sub(q, p), l[i] / (l[i] - l[j])) : d3_madd(p, q, -l[i] / l[j]);
            double c[2] = {d3_dot(d3_sub(x, eye), right), d3_dot(d3_sub(x, eye), up)};
            for (int k = 0; k < 2; k++) {
                lo[k] = fmin(lo[k], c[k]);
                hi[k] = fmax(hi[k], c[k]);
            }
        }
    }
    if (!(lo[0] <= hi[0])) return n;
    for (int k = 0; k < 4; k++) {
        dvec3 x = d3_madd(d3_madd(d3_madd(eye, fwd, z_c), right, k & 1 ? hi[0] : lo[0]), up, k & 2 ? hi[1] : lo[1]);
        out[n][0] = x.x, out[n][1] = x.y, out[n][2] = x.z, out[n++][3] = 1.0;
    }
    return n;
}

/* Lit candidates that sum a wedge reaching the near plane, as pa's lists
 * and rules give them (near_stats' `after`). */
static long near_pairs(const TechContext *ctx, const Patch *pa, const bool *cut)
{
    long pairs = 0;
    for (int s = 0; s < ctx->vs->count; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        if (ctx->vs->depth_view[s] < pa->near_depth) {
            pairs += pa->num_cut + pa->num_everywhere;
            continue;
        }
        pairs += pa->num_everywhere;
        for (long i = pa->wedges.start[s]; i < pa->wedges.start[s + 1]; i++) pairs += cut[pa->wedges.item[i]];
    }
    return pairs;
}

/* Patch pa's wedge lists: each silhouette edge's stand-in drawn from the
 * camera (its wedge cut at the near plane where it reaches it), or the edge
 * in `everywhere` when it has none. */
static bool patch_wedges(const TechContext *ctx, const SsvState *st, CameraCount *cc, Patch *pa, Error *err)
{
    int ne = pa->sil->num_edges;
    vec3 *verts = malloc(sizeof *verts * (size_t)CAMERA_POLY_MAX * (size_t)(ne ? ne : 1));
    int *first = malloc(sizeof *first * (size_t)(ne + 1));
    pa->everywhere = malloc(sizeof *pa->everywhere * (size_t)(ne ? ne : 1));
    if (!verts || !first || !pa->everywhere) {
        free(verts);
        free(first);
        return error_set(err, "out of memory for %d wedges", ne);
    }
    bool *cut = calloc((size_t)ne + 1, sizeof *cut);
    if (!cut) {
        free(verts);
        free(first);
        return error_set(err, "out of memory for %d wedges", ne);
    }
    const Camera *cam = &ctx->scene->camera;
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, ctx->vs->width, ctx->vs->height, &f, &r, &u, &tx, &ty);
    first[0] = 0;
    for (int i = 0; i < ne; i++) {
        dvec3 end[2] = {d3_from(pa->sil->edges[i].a), d3_from(pa->sil->edges[i].b)};
        double gen[2 + 2 * 8][4];
        int m = 0;
        for (int j = 0; j < 2; j++) {
            gen[m][0] = end[j].x, gen[m][1] = end[j].y, gen[m][2] = end[j].z, gen[m++][3] = 1.0;
            for (int c = 0; c < st->num_corners; c++) {
                dvec3 d = d3_sub(end[j], st->corner[c]); /* the extrusion away from the light's corner */
                gen[m][0] = d.x, gen[m][1] = d.y, gen[m][2] = d.z, gen[m++][3] = 0.0;
            }
        }
        int n = 0;
        if (!camera_count_stand_in(cc, cam, (const double(*)[4])gen, m, verts + first[i], &n)) {
            double in[WEDGE_GEN_MAX + 4][4];
            int mc = cut_at_near((const double(*)[4])gen, m, cam, d3_from(f), d3_from(r), d3_from(u), in);
            n = 0;
            cut[i] = mc >= 0 && (mc == 0 || camera_count_stand_in(cc, cam, (const double(*)[4])in, mc, verts + first[i], &n));
            if (cut[i]) pa->num_cut++;
            else {
                pa->everywhere[pa->num_everywhere++] = i;
                n = 0;
            }
        }
        first[i + 1] = first[i] + n;
    }
    pa->near_depth = pa->num_cut > 0 ? NEAR_CUT * cam->near_dist * (1.0 + 1e-3) : 0.0;
    RasterStats fill;
    bool ok = camera_count_lists(cc, verts, first, ne, COUNT_NEARER, &pa->wedges, &fill, err);
    if (ok) {
        long lit = 0;
        for (int s = 0; s < ctx->vs->count; s++) lit += ctx->cls[s] == SAMPLE_LIT_CANDIDATE;
        near_stats.reaching += pa->num_cut + pa->num_everywhere;
        near_stats.cut += pa->num_cut;
        near_stats.before += lit * (pa->num_cut + pa->num_everywhere);
        near_stats.after += near_pairs(ctx, pa, cut);
    }
    free(cut);
    free(verts);
    free(first);
    return ok;
}

/* Whether the mesh's triangles with area lie in one plane: their corners
 * within 1e-6 of the mesh's extent of the plane of its largest triangle
 * (zero-area triangles cast nothing and are skipped, as by silhouette.h). */
static bool mesh_is_flat(const Mesh *m)
{
    dvec3 n = d3(0, 0, 0), o = d3(0, 0, 0), lo = d3(INFINITY, INFINITY, INFINITY), hi = d3(-INFINITY, -INFINITY, -INFINITY);
    double best = 0.0;
    for (int t = 0; t < m->num_triangles; t++) {
        const uint32_t *ix = &m->indices[3 * t];
        dvec3 a = d3_from(m->positions[ix[0]]), b = d3_from(m->positions[ix[1]]), c = d3_from(m->positions[ix[2]]);
        dvec3 x = d3_cross(d3_sub(b, a), d3_sub(c, a));
        if (d3_dot(x, x) > best) best = d3_dot(x, x), n = x, o = a;
        for (int k = 0; k < 3; k++) {
            dvec3 p = d3_from(m->positions[ix[k]]);
            lo = d3(p.x < lo.x ? p.x : lo.x, p.y < lo.y ? p.y : lo.y, p.z < lo.z ? p.z : lo.z);
            hi = d3(p.x > hi.x ? p.x : hi.x, p.y > hi.y ? p.y : hi.y, p.z > hi.z ? p.z : hi.z);
        }
    }
    if (!(best > 0.0)) return true; /* no area: casts nothing */
    n = d3_scale(n, 1.0 / sqrt(best));
    double tol = 1e-6 * d3_len(d3_sub(hi, lo));
    for (int t = 0; t < m->num_triangles; t++) {
        const uint32_t *ix = &m->indices[3 * t];
        dvec3 a = d3_from(m->positions[ix[0]]), b = d3_from(m->positions[ix[1]]), c = d3_from(m->positions[ix[2]]);
        dvec3 x = d3_cross(d3_sub(b, a), d3_sub(c, a));
        if (d3_dot(x, x) == 0.0) continue;
        for (int k = 0; k < 3; k++) /* NaN: not flat */
            if (!(fabs(d3_dot(d3_sub(d3_from(m->positions[ix[k]]), o), n)) <= tol)) return false;
    }
    return true;
}

/* Open meshes (issue 14): the coverage integrates the hard volume's count,
 * which counts every layer a ray crosses. Closed objects and shells count
 * once (their dark side, SIL_SHELLS_DARK_SIDE); an object that took
 * Bergeron's rule (a triangle weighted +1, counted from its front) counts
 * once only if flat (a quad, a disk: one layer), and is refused otherwise:
 * a ray through two of its layers would count twice (measured on a box
 * without one face: penumbra MAE 0.17 against 0.012 for a square). */
static bool check_layers(const Scene *scene, const Silhouette *sil, Error *err)
{
    for (int i = 0; i < sil->num_objects; i++) {
        const SilObject *so = &sil->objects[i];
        bool bergeron = false;
        for (int t = 0; t < so->triangles && !bergeron; t++) bergeron = so->weight[t] > 0;
        const Object *o = &scene->objects[so->object];
        if (so->closed || !bergeron || mesh_is_flat(&o->mesh)) continue;
        return error_set(err,
                         "caster '%s' is neither closed (%ld open, %ld non-manifold, %ld misoriented of %ld edges), "
                         "a shell (open edges under 1/%d, no other defect) nor flat: the wedges would count a ray "
                         "through two of its layers twice (Bergeron's rule); close it or use shadow_volume",
                         o->name, so->open_edges, so->nonmanifold_edges, so->misoriented_edges, so->edges,
                         SIL_SHELL_OPEN);
    }
    return true;
}

static bool ssv_prepare_term(const TechContext *ctx, void **state, int term, Error *err)
{
    const char *name = term == TERM_EXACT ? "soft_shadow_volume" : "penumbra_wedge";
    int per_side = (int)ctx->params[SSV_PATCHES];
    SsvState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "%s: out of memory", name);
    st->term = term;
    light_shape(ctx, per_side, st);
    if (!(st->area > 0.0)) {
        free(st);
        return error_set(err, "%s: light %d has no area (radius, width or height 0)", name, ctx->light_index + 1);
    }
    CameraCount cc = {0};
    if (!all_edges_mode) near_stats = (SsvNearStats){0};
    if (!all_edges_mode && !camera_count_init(&cc, &ctx->scene->camera, ctx->vs, ctx->vs->depth_view, err)) {
        free(st);
        return false;
    }
    for (int i = 0; i < st->num_patches; i++) {
        Patch *pa = &st->patch[i];
        pa->all_edges = all_edges_mode;
        double L[4] = {pa->centre.x, pa->centre.y, pa->centre.z, 1.0};
        char desc[160];
        snprintf(desc, sizeof desc, "casters, patch %d of %d of light %d", i + 1, st->num_patches, ctx->light_index + 1);
        RasterStats fill;
        /* shells counted once: the coverage integrates the counts (silhouette.h) */
        pa->sil = res_silhouette_point(ctx->rm, ctx->scene, L, SIL_SHELLS_DARK_SIDE, desc, err);
        pa->count = malloc(sizeof *pa->count * (size_t)(ctx->vs->count + 1));
        if (!pa->count) error_set(err, "%s: out of memory for %d counts", name, ctx->vs->count);
        if (!pa->sil || !check_layers(ctx->scene, pa->sil, err) || !pa->count ||
            !shadow_volume_zfail_counts(ctx, pa->sil, ctx->params[SSV_OFFSET], pa->count, &fill, err) ||
            (!all_edges_mode && !patch_wedges(ctx, st, &cc, pa, err))) {
            st->num_patches = i + 1;
            ssv_release(st);
            camera_count_free(&cc);
            return false;
        }
    }
    camera_count_free(&cc);
    *state = st;
    return true;
}

static bool ssv_prepare(const TechContext *ctx, void **state, Error *err)
{
    return ssv_prepare_term(ctx, state, TERM_EXACT, err);
}

static bool wedge_prepare(const TechContext *ctx, void **state, Error *err)
{
    return ssv_prepare_term(ctx, state, TERM_LINEAR, err);
}

#define AREA_LIGHTS (LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK))

const Technique tech_soft_shadow_volume = {
    .name = "soft_shadow_volume",
    .family = "geometry",
    .source = "course §5.3.2 (Assarsson & Akenine-Möller 2003; light splitting Assarsson et al. 2003)",
    .summary = "soft shadow volumes: the hard volume's count at the light's centre plus each wedge's exact coverage "
               "of the light by its projected silhouette edge (Green's theorem); overlapping casters add",
    .params = ssv_params,
    .num_params = (int)(sizeof ssv_params / sizeof ssv_params[0]),
    .resources = ssv_resources,
    .rgb = false,
    .lights = AREA_LIGHTS,
    .main_param = "patches",
    .prepare = ssv_prepare,
    .evaluate = ssv_evaluate,
    .release = ssv_release,
    .aux = ssv_aux,
};

const Technique tech_penumbra_wedge = {
    .name = "penumbra_wedge",
    .family = "geometry",
    .source = "course §5.3.2 (Akenine-Möller & Assarsson 2002)",
    .summary = "penumbra wedges: the hard volume at the light's centre plus, inside each silhouette edge's wedge, "
               "a linear ramp across the edge's line; overlapping casters add",
    .params = ssv_params,
    .num_params = (int)(sizeof ssv_params / sizeof ssv_params[0]),
    .resources = ssv_resources,
    .rgb = false,
    .lights = AREA_LIGHTS,
    .main_param = "patches",
    .prepare = wedge_prepare,
    .evaluate = ssv_evaluate,
    .release = ssv_release,
    .aux = ssv_aux,
};
