/* penumbra_deep_map.c -- `penumbra_deep_map`: penumbra deep shadow maps
 * (St-Amour, Paquette & Poulin 2005, "Soft shadows from extended light
 * sources with penumbra deep shadow maps", Graphics Interface 2005; course
 * §5.2.4, its second paragraph). The N light samples' hard maps (multimap.h:
 * the same points and map resources as `light_sampling`) are merged into one
 * structure on the grid of the light centre's map: per texel, the
 * visibility along the texel's centre ray as a function of depth,
 *
 *   V(z) = 1/N sum_k V_k(x(z)),  V_k = sample k's own depth test at x(z),
 *
 * x(z) the ray's point at linear depth z of the centre's face (course Eq.
 * 1.4 by N-sample quadrature, as `light_sampling`, so V converges to it as
 * the centre's texels shrink). V is a step function: V_k changes only at the
 * visibility events, where the ray's image in sample k's map (its epipolar
 * segment) enters another texel or passes that texel's stored depth. The
 * build marches each segment at most half a texel of map k at a time
 * (perspective-correct steps, so they are even in texels) and bisects each
 * change of verdict down to PDM_REFINE halvings [derived]; only the ray's
 * part inside the scene's bounds is marched, and a span whose verdict a
 * tile's depth bounds fix is jumped (skip_to). Unlike a deep
 * shadow map's transmittance (Lokovic & Veach 2000) V need not fall
 * monotonically: past a caster smaller than the light a sample's segment
 * clears the caster again and V rises [derived], so the functions are kept
 * general, not monotone.
 *
 * Each texel's step function is compressed to a piecewise-linear one within
 * `error` (max |deviation| in visibility), by Lokovic & Veach's greedy
 * segment growth (Deep shadow maps, SIGGRAPH 2000, their compression of a
 * visibility function; that St-Amour et al. compress the same way is the
 * course's summary, §5.2.4: the two papers' texts were not at hand here, so
 * no section is cited [derived where it differs]): from a fixed origin, the interval of slopes that keeps the
 * segment within error of every step end is narrowed until it empties;
 * steps taller than 2 error become a jump (two vertices at one depth);
 * where a segment ends is chosen for the long runs receivers read (compress,
 * end_value: not Lokovic & Veach's middle slope). So a
 * staircase of equal steps 1/N compresses to one segment when error >=
 * 1/(2N) [derived: a line through its mid-risers is within 1/(2N) of every
 * step], and error = 0 keeps every event. A texel needing more than
 * max_vertices is compressed again with the tolerance doubled until it fits
 * (counted: the resource log's note), up to 1/2: then the constant 1/2.
 *
 * Lookup: the receiver's four nearest texels, weighted bilinearly (or its
 * texel alone: nearest, which converges to `light_sampling` as the texels
 * shrink; bilinear's penumbra RMSE was 0.41x nearest's at 256^2), each
 * function evaluated at the receiver's plane depth on that texel's ray
 * when receiver_plane is on (course §4.1.2 box: otherwise a texel's ray
 * meets the receiver up to a texel's slope away and the functions drop to
 * 0 there), less the shared bias, with the shared set-up (smap_receivers).
 * At the build each sample's depth test takes the slope-scaled bias of its
 * own map (verdict_at), as light_sampling's tests do: the centre face's
 * bias cannot stand in for theirs.
 * Like `layered_attenuation`, V counts all N samples, also those below the
 * receiver's tangent plane (the function is the ray's, not the surface's):
 * it agrees with `light_sampling` off the terminator. The course's cost
 * (§5.2.4): "rendering is real-time, but the build is interactive rates at
 * best": the build reads about 2 N (segment length in texels) texels per
 * texel of the centre's map. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "techniques/multimap.h"

/* Bisections of a verdict change on the segment: its depth to 2^-12 of a
 * half-texel step of map k. */
#define PDM_REFINE 12
/* Texels a side of the tiles whose depth bounds let a march skip a span
 * whose verdict cannot change (sample_events). */
#define PDM_TILE 8
#define PDM_MAX_VERTICES 1024
/* A flat run this many times longer than the interval after the break it
 * meets is a knee (compress): it ends flat rather than tilt toward a drop. */
#define PDM_KNEE 4.0

enum { P_SAMPLES = SMAP_NUM_PARAMS, P_PATTERN, P_ERROR, P_MAX_VERTICES, P_FILTER };
enum { FILTER_NEAREST, FILTER_BILINEAR };
static const char *const pdm_filter_names[] = {"nearest", "bilinear", NULL};

static const ParamDesc pdm_params[] = {
    /* cube faces at most, one cascade: the functions live on the centre map's grid */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    LS_SAMPLE_PARAMS,
    {"error", PARAM_FLOAT, 0.05, 0, 0.5, "visibility",
     "compression bound: each texel's piecewise-linear function stays within this of its step function at every "
     "depth (Lokovic & Veach 2000); 0 keeps every event; a staircase of N steps becomes one segment from 1/(2N)",
     NULL},
    {"max_vertices", PARAM_INT, 32, 2, PDM_MAX_VERTICES, "vertices",
     "vertex cap per texel: a function needing more is compressed again with the bound doubled until it fits, "
     "up to 1/2 (then the constant 1/2; counted in the resource log); memory is at most faces x map_size^2 x "
     "(8 max_vertices + 5) bytes, refused above 2 GiB",
     NULL},
    {"filter", PARAM_ENUM, FILTER_BILINEAR, 0, 1, "",
     "lookup: the receiver's texel's function (nearest), or the four nearest texels' functions, each at the "
     "receiver's depth on its own ray, weighted bilinearly",
     pdm_filter_names},
};

static const char *const pdm_resources[] = {"shadow_map", "penumbra_deep_map", "view_samples", NULL};
static const char *const pdm_aux[] = {"vertices", NULL};

/* ---- the step function of one texel's ray --------------------------------- */

/* A change of one sample's verdict at depth z: +1 lit, -1 shadowed. */
typedef struct Event {
    float z;
    int delta;
} Event;

/* Per-thread scratch of the build. */
typedef struct Scratch {
    Event *event;
    int count, cap;
    float *zb, *c;      /* the step function: breaks zb[0..m+1], values c[0..m] */
    DeepVertex *out;    /* its compression */
} Scratch;

/* Room for `cap` events and the step function and compression they make. */
static bool scratch_grow(Scratch *s, int cap)
{
    Event *e = realloc(s->event, (size_t)cap * sizeof *e);
    if (e) s->event = e;
    float *zb = realloc(s->zb, (size_t)(cap + 2) * sizeof *zb);
    if (zb) s->zb = zb;
    float *c = realloc(s->c, (size_t)(cap + 1) * sizeof *c);
    if (c) s->c = c;
    DeepVertex *o = realloc(s->out, (size_t)(2 * cap + 2) * sizeof *o); /* compress: at most 2 per break + 2 */
    if (o) s->out = o;
    if (!e || !zb || !c || !o) return false;
    s->cap = cap;
    return true;
}

static bool push_event(Scratch *s, float z, int delta)
{
    if (s->count == s->cap && !scratch_grow(s, 2 * s->cap)) return false;
    s->event[s->count++] = (Event){z, delta};
    return true;
}

/* The stored depth's change across one texel at (i, j) of a face: per
 * axis the smaller of the two one-sided differences (on a plane both are
 * its slope; at a silhouette one side jumps, the other does not), the larger
 * of the axes; 0 where neither side is finite [derived]. */
static double texel_slope(const ShadowMap *m, int face, int i, int j, float z)
{
    double slope = 0.0;
    for (int axis = 0; axis < 2; axis++) {
        float lo = axis ? shadowmap_texel(m, face, i, j - 1) : shadowmap_texel(m, face, i - 1, j);
        float hi = axis ? shadowmap_texel(m, face, i, j + 1) : shadowmap_texel(m, face, i + 1, j);
        double d = fmin(fabs((double)z - lo), fabs((double)hi - z)); /* fmin: one NaN side leaves the other */
        if (isfinite(d)) slope = d > slope ? d : slope;
    }
    return slope;
}

/* Sample k's depth test (course §2.1, in the map's stored metric) of the
 * located point mc: 1 lit, 0 shadowed, NaN unknown; lit off the map. A
 * point behind the stored depth by less than slope_bias times the map's own
 * depth change across the texel (at most slope_max texel widths) is lit: the slope-scaled bias of course
 * §2.1.2 in each sample's map, as light_sampling's tests have it (the
 * receiver's, applied at lookup, is the centre face's: on sphere-on-plane's
 * ground the centre's -y face has slope 0 where samples' -z faces graze). */
static float verdict_at(const ShadowMap *m, const MapCoord *mc, const SmapBias *bias)
{
    if (!mc->inside) return 1.0f;
    int i = (int)mc->s, j = (int)mc->t;
    i = i < m->res ? i : m->res - 1; /* s < res, but rounding may reach it */
    j = j < m->res ? j : m->res - 1;
    double ref = m->spec.depth == RASTER_DEPTH_NDC ? mc->z_ndc : mc->depth_linear;
    float z = shadowmap_texel(m, mc->face, i, j);
    float v = smap_test(ref, z);
    if (v == 0.0f && bias->slope > 0.0) { /* clamped at slope_max texel widths, as smap.c's */
        double most = bias->slope_max_texels * lightview_texel_world(&m->view, mc);
        if (m->spec.depth == RASTER_DEPTH_NDC) most *= lightview_ndc_per_world(&m->view, mc);
        v = smap_test(ref, z + fmin(bias->slope * texel_slope(m, mc->face, i, j, z), most));
    }
    return v;
}

/* A segment a + u (b - a) of world space seen through one face of sample
 * k's map: on a plain (ortho, perspective or cube) face its clip
 * coordinates and linear depth are affine in u, so a point is located as
 * lightview_locate_on does, without the matrices; `fast` false when the
 * segment spans faces (located per point). */
typedef struct Seg {
    const ShadowMap *map;
    const SmapBias *bias; /* the depth tests' slope bias (verdict_at) */
    dvec3 a, ab;
    bool fast;
    int face;
    dvec4 c0, dc; /* clip coordinates at u = 0, their change to u = 1 */
    double d0, dd; /* linear depth likewise */
} Seg;

static Seg seg_make(const ShadowMap *m, const SmapBias *bias, dvec3 a, dvec3 b, int face_a, int face_b)
{
    Seg g = {.map = m, .bias = bias, .a = a, .ab = d3_sub(b, a), .fast = face_a == face_b, .face = face_a};
    const MapFace *f = &m->view.face[face_a];
    const double *row = f->raster.depth_row;
    dvec4 ca = m4_apply(&f->raster.clip_from_world, a), cb = m4_apply(&f->raster.clip_from_world, b);
    g.c0 = ca;
    g.dc = (dvec4){cb.x - ca.x, cb.y - ca.y, cb.z - ca.z, cb.w - ca.w};
    g.d0 = row[0] * a.x + row[1] * a.y + row[2] * a.z + row[3];
    g.dd = row[0] * g.ab.x + row[1] * g.ab.y + row[2] * g.ab.z;
    return g;
}

/* The verdict at u: lightview_locate_on's arithmetic (lightview_lookup.c)
 * on the segment's face, or lightview_locate. */
static float seg_verdict(const Seg *g, double u)
{
    const ShadowMap *m = g->map;
    if (!g->fast) {
        MapCoord mc = lightview_locate(&m->view, d3_madd(g->a, g->ab, u));
        return verdict_at(m, &mc, g->bias);
    }
    double w = g->c0.w + u * g->dc.w;
    MapCoord mc = {.face = g->face, .depth_linear = g->d0 + u * g->dd};
    if (w > 0.0) {
        mc.s = ((g->c0.x + u * g->dc.x) / w + 1.0) * 0.5 * m->res;
        mc.t = ((g->c0.y + u * g->dc.y) / w + 1.0) * 0.5 * m->res;
        mc.z_ndc = (g->c0.z + u * g->dc.z) / w;
        mc.inside = mc.s >= 0.0 && mc.s < m->res && mc.t >= 0.0 && mc.t < m->res && mc.z_ndc >= 0.0 &&
                    mc.z_ndc <= 1.0;
    }
    return verdict_at(m, &mc, g->bias);
}

/* One sample's map and what bounds its march. */
typedef struct SampleMap {
    const ShadowMap *map;
    dvec3 point;       /* the sample, world */
    double lit_within; /* points nearer the sample than this see it (the map's nearest stored depth) */
    int tiles;         /* tiles a side of each face, PDM_TILE texels each */
    float *tile_min, *tile_max; /* stored depth's bounds per tile (NaN in it: -inf, +inf), faces x tiles^2 */
} SampleMap;

/* The ray's parameter u in [0, 1] (a + u (b - a)) at screen parameter lam of
 * the segment's image: perspective-correct interpolation with depths wa, wb
 * (1 for ortho faces), so even steps in lam are even in texels. */
static double ray_u(double lam, double wa, double wb)
{
    double den = (1.0 - lam) * wb + lam * wa;
    return den > 0.0 ? lam * wa / den : lam;
}

/* Where the segment a-b leaves the ball of radius r about c (0: it starts
 * outside; 1: it never leaves). */
static double leave_ball(dvec3 a, dvec3 b, dvec3 c, double r)
{
    dvec3 d = d3_sub(b, a), f = d3_sub(a, c);
    double A = d3_dot(d, d), B = d3_dot(f, d), C = d3_dot(f, f) - r * r;
    if (!(C < 0.0) || !(A > 0.0)) return 0.0;
    double u = (-B + sqrt(B * B - A * C)) / A; /* the far root: C < 0, so real */
    return u < 1.0 ? u : 1.0;
}

/* The stored metric of the point at u of a `fast` segment (the face's). */
static double seg_ref(const Seg *g, double u)
{
    if (g->map->spec.depth == RASTER_DEPTH_LINEAR) return g->d0 + u * g->dd;
    return (g->c0.z + u * g->dc.z) / (g->c0.w + u * g->dc.w);
}

/* How far (screen parameter lam, perspective-correct as ray_u) a march at
 * lam with verdict v may jump: to where its image leaves the current tile,
 * when the verdict cannot change before (the point's stored metric, monotone
 * along the segment, stays below the tile's nearest depth: lit; or above its
 * farthest, every texel a caster: shadowed); else lam itself. Screen
 * coordinates are linear in lam on a face (sa, sb: the ends' (s, t)). */
static double skip_to(const Seg *g, const SampleMap *s, double lam, double wa, double wb, const double sa[2],
                      const double sb[2], float v)
{
    double at[2], exit = 1.0;
    for (int k = 0; k < 2; k++) {
        at[k] = sa[k] + lam * (sb[k] - sa[k]);
        if (!(at[k] >= 0.0 && at[k] < g->map->res)) return lam;
        double d = sb[k] - sa[k], edge = (floor(at[k] / PDM_TILE) + (d > 0.0)) * PDM_TILE;
        if (d != 0.0) exit = fmin(exit, (edge - sa[k]) / d);
    }
    exit = lam + (exit - lam) * (1.0 - 1e-9); /* inside the tile */
    if (!(exit > lam)) return lam;
    int n = s->tiles;
    size_t t = ((size_t)g->face * n + (size_t)(at[1] / PDM_TILE)) * n + (size_t)(at[0] / PDM_TILE);
    double r0 = seg_ref(g, ray_u(lam, wa, wb)), r1 = seg_ref(g, ray_u(exit, wa, wb));
    if (v == 1.0f && fmax(r0, r1) < s->tile_min[t]) return exit; /* fmax: r0, r1 finite on a face in front */
    if (v == 0.0f && fmin(r0, r1) > s->tile_max[t]) return exit;
    return lam;
}

/* Steps of the segment's image in texels: from the face's clip coordinates
 * when it lies on one face in front of the eye, else (across cube faces)
 * the angle it spans, a cube face having at most res texels per radian. */
static double seg_texels(const Seg *g, dvec3 point)
{
    double wa = g->c0.w, wb = g->c0.w + g->dc.w, res = g->map->res;
    if (g->fast && wa > 0.0 && wb > 0.0)
        return 0.5 * res * hypot((g->c0.x + g->dc.x) / wb - g->c0.x / wa, (g->c0.y + g->dc.y) / wb - g->c0.y / wa);
    dvec3 da = d3_sub(g->a, point), db = d3_add(da, g->ab);
    double la = d3_len(da), lb = d3_len(db);
    return la > 0.0 && lb > 0.0 ? acos(fmax(-1.0, fmin(1.0, d3_dot(da, db) / (la * lb)))) * res : res;
}

/* The events of sample `s` on the segment a-b (depths za..zb along the
 * centre's axis); false when a verdict is NaN (the texel is unknown). The
 * steps are perspective-correct on a face (depths wa, wb: even in texels),
 * else along the chord of directions from the sample. */
static bool sample_events(const SampleMap *s, const SmapBias *bias, dvec3 a, dvec3 b, double za, double zb,
                          Scratch *sc, int *lit0, bool *oom)
{
    double u0 = leave_ball(a, b, s->point, s->lit_within);
    dvec3 a0 = d3_madd(a, d3_sub(b, a), u0);
    const LightView *lv = &s->map->view;
    Seg g = seg_make(s->map, bias, a0, b, lightview_locate(lv, a0).face, lightview_locate(lv, b).face);
    double wa = 1.0, wb = 1.0;
    if (!g.fast || lv->face[g.face].perspective) {
        bool clip = g.fast && g.c0.w > 0.0 && g.c0.w + g.dc.w > 0.0;
        wa = clip ? g.c0.w : d3_len(d3_sub(a0, s->point));
        wb = clip ? g.c0.w + g.dc.w : d3_len(d3_sub(b, s->point));
    }
    int steps = (int)fmin(ceil(2.0 * seg_texels(&g, s->point)), 8.0 * s->map->res) + 1;
    float prev = seg_verdict(&g, 0.0);
    if (isnan(prev)) return false;
    *lit0 += u0 > 0.0 ? 1 : (int)prev; /* inside the ball it is lit */
    if (u0 > 0.0 && prev == 0.0f && !push_event(sc, (float)(za + u0 * (zb - za)), -1)) return *oom = true;
    /* the ends' screen coordinates, for skip_to: a face in front of the eye at both */
    bool tiled = g.fast && g.c0.w > 0.0 && g.c0.w + g.dc.w > 0.0;
    double sa[2] = {0.0, 0.0}, sb[2] = {0.0, 0.0};
    if (tiled) {
        double w1 = g.c0.w + g.dc.w, half = 0.5 * s->map->res;
        sa[0] = (g.c0.x / g.c0.w + 1.0) * half, sa[1] = (g.c0.y / g.c0.w + 1.0) * half;
        sb[0] = ((g.c0.x + g.dc.x) / w1 + 1.0) * half, sb[1] = ((g.c0.y + g.dc.y) / w1 + 1.0) * half;
    }
    double lam_prev = 0.0;
    for (int q = 1; q <= steps; q++) {
        if (tiled) { /* jump the steps whose verdict cannot change */
            int to = (int)floor(skip_to(&g, s, lam_prev, wa, wb, sa, sb, prev) * steps);
            if (to > q) q = to, lam_prev = (double)to / steps;
            if (q > steps) break;
        }
        double lam = (double)q / steps;
        float v = seg_verdict(&g, ray_u(lam, wa, wb));
        if (isnan(v)) return false;
        if (v != prev) { /* bisect [lam_prev, lam] for the change */
            double lo = lam_prev, hi = lam;
            for (int r = 0; r < PDM_REFINE; r++) {
                double mid = 0.5 * (lo + hi);
                float vm = seg_verdict(&g, ray_u(mid, wa, wb));
                if (isnan(vm)) return false;
                if (vm == prev) lo = mid;
                else hi = mid;
            }
            double u = u0 + (1.0 - u0) * ray_u(hi, wa, wb);
            if (!push_event(sc, (float)(za + u * (zb - za)), v > prev ? 1 : -1)) return *oom = true;
            prev = v;
        }
        lam_prev = lam;
    }
    return true;
}

static int event_cmp(const void *pa, const void *pb)
{
    const Event *a = pa, *b = pb;
    return (a->z > b->z) - (a->z < b->z);
}

/* The step function from the events: breaks zb[1..m] strictly inside
 * (zb[0], zb[m+1]) = (za, zf), value c[i] / n on [zb[i], zb[i+1]); events at
 * one depth merge, and breaks where nothing changes go. Returns m. */
static int step_function(Scratch *s, int lit0, int n, float za, float zf)
{
    qsort(s->event, (size_t)s->count, sizeof *s->event, event_cmp);
    int m = 0, lit = lit0;
    s->zb[0] = za;
    s->c[0] = (float)lit0 / (float)n;
    for (int e = 0; e < s->count;) {
        float z = s->event[e].z;
        int change = 0;
        for (; e < s->count && s->event[e].z == z; e++) change += s->event[e].delta;
        lit += change;
        if (!(z > za && z < zf)) { /* at the ends (rounding): the value from there on */
            if (z <= za) s->c[0] = (float)lit / (float)n;
            continue;
        }
        if (change == 0) continue;
        m++;
        s->zb[m] = z;
        s->c[m] = (float)lit / (float)n;
    }
    s->zb[m + 1] = zf;
    return m;
}

/* Break i's window [lo, hi]: within eps of value c, inside [0, 1]. */
static void window(double c, double eps, double *lo, double *hi)
{
    *lo = c - eps > 0.0 ? c - eps : 0.0;
    *hi = c + eps < 1.0 ? c + eps : 1.0;
}

/* Interval i's length [zb[i], zb[i + 1]). */
static double span(const float *zb, int i) { return (double)zb[i + 1] - zb[i]; }

/* The value a segment from (zb[a], ya) ends with at break i, its slope in
 * [lo, hi]: the one nearest `target`. */
static double end_value(const float *zb, int i, int a, double ya, double lo, double hi, double target)
{
    double dz = (double)zb[i] - zb[a];
    double slope = (target - ya) / dz;
    slope = slope < lo ? lo : slope > hi ? hi : slope;
    return ya + slope * dz;
}

/* Lokovic & Veach's greedy compression (Deep shadow maps, 2000) of the step
 * function (zb, c, m) within eps into `out`; returns the vertex count. A
 * segment from (zb[a], ya) may end at break i when some slope keeps it
 * within eps of c[i - 1] there, and pass through i when also of c[i] (the
 * deviation of a line from a constant is largest at an interval's ends, so
 * the ends bound it everywhere); [lo, hi] is the slopes that pass every
 * break so far. Where no slope passes, the segment ends at i, as near
 * c[i - 1] as its slopes allow, and jumps to c[i]; where break i is out of
 * reach, it ends at i - 1, as near the value of the longer interval beside
 * i - 1 as they allow, and the next one starts there. Receivers read on the
 * long runs: in front of their surface's drop (the N maps disagree on the
 * surface's depth by about a texel's slope, so the drop is a short
 * staircase) or behind a caster (the umbra) [derived: with the middle
 * slope, as Lokovic & Veach choose, the lit ground of sphere-on-plane read
 * 0.9 error too dark]. So a long flat run meeting short intervals (a knee:
 * the top of a drop) ends flat there rather than tilt toward the drop. */
static int compress(const float *zb, const float *c, int m, double eps, DeepVertex *out)
{
    int k = 0, a = 0;
    double ya = c[0], lo = -INFINITY, hi = INFINITY;
    out[k++] = (DeepVertex){zb[0], (float)ya};
    for (int i = 1; i <= m + 1;) {
        double dz = (double)zb[i] - zb[a]; /* > 0: the breaks increase strictly */
        double wlo, whi;
        window(c[i - 1], eps, &wlo, &whi);
        double elo = fmax(lo, (wlo - ya) / dz), ehi = fmin(hi, (whi - ya) / dz);
        if (elo > ehi) { /* out of reach: end at i - 1 (i - 1 > a, so lo and hi are finite) */
            ya = end_value(zb, i - 1, a, ya, lo, hi, span(zb, i - 1) > span(zb, i - 2) ? c[i - 1] : c[i - 2]);
            a = i - 1;
            out[k++] = (DeepVertex){zb[a], (float)ya};
            lo = -INFINITY, hi = INFINITY;
            continue;
        }
        double plo = 1.0, phi = 0.0; /* the slopes passing break i: none at the end */
        if (i <= m) {
            window(c[i], eps, &wlo, &whi);
            plo = fmax(elo, (wlo - ya) / dz), phi = fmin(ehi, (whi - ya) / dz);
        }
        bool knee = i <= m && elo <= 0.0 && ehi >= 0.0 && !(plo <= 0.0 && phi >= 0.0) &&
                    dz > PDM_KNEE * span(zb, i);
        if (plo <= phi && !knee) {
            lo = plo, hi = phi, i++;
            continue;
        }
        double y = end_value(zb, i, a, ya, elo, ehi, c[i - 1]); /* before a jump: the run's own value */
        out[k++] = (DeepVertex){zb[i], (float)y};
        if (i <= m && (float)y != c[i]) out[k++] = (DeepVertex){zb[i], c[i]}; /* the jump */
        a = i, ya = c[i <= m ? i : m], lo = -INFINITY, hi = INFINITY;
        if (i <= m && (float)y == c[i]) ya = y;
        i++;
    }
    return k;
}

/* ---- the resource ----------------------------------------------------------- */

typedef struct DeepArgs {
    const ShadowMap *centre;
    dvec3 box_min, box_max; /* the scene's bounds, a little enlarged: receivers lie inside */
    const SampleMap *sample;
    int n, max_vertices;
    double error;
    SmapBias bias; /* its slope and slope_max act in each sample's depth tests */
} DeepArgs;

/* The part [*u0, *u1] of the segment a + u (b - a), u in [0, 1], inside the
 * box (the slab method); false when it misses. */
static bool clip_to_box(dvec3 a, dvec3 b, dvec3 lo, dvec3 hi, double *u0, double *u1)
{
    const double o[3] = {a.x, a.y, a.z}, d[3] = {b.x - a.x, b.y - a.y, b.z - a.z};
    const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    *u0 = 0.0, *u1 = 1.0;
    for (int k = 0; k < 3; k++) {
        if (d[k] == 0.0) {
            if (o[k] < l[k] || o[k] > h[k]) return false;
            continue;
        }
        double ta = (l[k] - o[k]) / d[k], tb = (h[k] - o[k]) / d[k];
        *u0 = fmax(*u0, fmin(ta, tb));
        *u1 = fmin(*u1, fmax(ta, tb));
    }
    return *u0 < *u1;
}

/* One texel's function into sc->out over the part of its centre ray inside
 * the scene's bounds (held constant beyond); returns the vertex count, 0
 * unknown (a NaN verdict), -1 out of memory. */
static int texel_function(const DeepArgs *d, int face, int i, int j, Scratch *sc, long *events, bool *capped)
{
    const LightView *v = &d->centre->view;
    const RasterView *rv = &v->face[face].raster;
    dvec3 a, b;
    double u0, u1;
    *capped = false;
    if (!mm_texel_point(v, face, i + 0.5, j + 0.5, rv->depth_near, &a) ||
        !mm_texel_point(v, face, i + 0.5, j + 0.5, rv->depth_far, &b))
        return 0;
    if (!clip_to_box(a, b, d->box_min, d->box_max, &u0, &u1)) { /* nothing to shadow or be shadowed: lit */
        sc->out[0] = (DeepVertex){(float)rv->depth_near, 1.0f};
        return 1;
    }
    double za = rv->depth_near + u0 * (rv->depth_far - rv->depth_near);
    double zb = rv->depth_near + u1 * (rv->depth_far - rv->depth_near);
    dvec3 ca = d3_madd(a, d3_sub(b, a), u0), cb = d3_madd(a, d3_sub(b, a), u1);
    sc->count = 0;
    int lit0 = 0;
    bool oom = false;
    for (int k = 0; k < d->n; k++) {
        if (!sample_events(&d->sample[k], &d->bias, ca, cb, za, zb, sc, &lit0, &oom)) return 0;
        if (oom) return -1;
    }
    int m = step_function(sc, lit0, d->n, (float)za, (float)zb);
    *events += m;
    double eps = d->error;
    int k = compress(sc->zb, sc->c, m, eps, sc->out);
    while (k > d->max_vertices && eps < 0.5) {
        *capped = true;
        eps = fmin(0.5, fmax(2.0 * eps, 0.25 / d->n));
        k = compress(sc->zb, sc->c, m, eps, sc->out);
    }
    if (k > d->max_vertices) { /* the segments start at c[0]: still too many; 1/2 is within 1/2 of any V */
        sc->out[0] = (DeepVertex){(float)za, 0.5f};
        sc->out[1] = (DeepVertex){(float)zb, 0.5f};
        k = 2;
    }
    return k;
}

static size_t deep_bytes(const void *res)
{
    const DeepMap *d = res;
    return d->texels * (sizeof *d->first + sizeof *d->unknown) + sizeof *d->first +
           (size_t)d->first[d->texels] * sizeof *d->vertex;
}

static void deep_destroy(void *res)
{
    DeepMap *d = res;
    if (!d) return;
    free(d->first);
    free(d->vertex);
    free(d->unknown);
    free(d);
}

static const ResourceKind kind_deep_map = {"penumbra_deep_map", deep_bytes, deep_destroy, RES_FRAME};

/* Rows are built in bands of BAND_ROWS in parallel and each band appended
 * to the map's one vertex array in row order (the map is the same for any
 * thread count), so the vertices are held twice for one band, not for the
 * whole map: with every row kept until the end the build's peak was 1.40x
 * the resource's bytes (bench/README.md, step 11). */
#define BAND_ROWS 64

/* One built row's vertices, until its band is appended. */
typedef struct Row {
    DeepVertex *vertex;
    uint32_t count;
} Row;

/* Row r of the map into *out, from the thread's scratch and row buffer buf
 * (room for a row at the cap); texel t's vertex count into d->first[t + 1]
 * (build_deep_map sums them into offsets). false when out of memory. */
static bool build_row(const DeepArgs *a, DeepMap *d, int r, Scratch *sc, DeepVertex *buf, Row *out, long *events,
                      long *capped)
{
    int res = d->res, f = r / res, j = r % res;
    uint32_t used = 0;
    for (int i = 0; i < res; i++) {
        bool cap;
        size_t t = ((size_t)f * res + j) * res + i;
        int k = texel_function(a, f, i, j, sc, events, &cap);
        if (k < 0) return false;
        d->first[t + 1] = (uint32_t)k;
        if (k == 0) {
            d->unknown[t] = 1;
            continue;
        }
        *capped += cap;
        memcpy(buf + used, sc->out, (size_t)k * sizeof *buf);
        used += (uint32_t)k;
    }
    out->count = used;
    out->vertex = malloc((used ? used : 1) * sizeof *buf);
    if (out->vertex) memcpy(out->vertex, buf, used * sizeof *buf);
    return out->vertex != NULL;
}

/* Append a band's n rows to d->vertex (*total used of *cap, grown by
 * doubling), freeing them; false when out of memory (they are freed too). */
static bool append_band(DeepMap *d, Row *band, int n, size_t *total, size_t *cap)
{
    size_t need = *total;
    for (int k = 0; k < n; k++) need += band[k].count;
    bool ok = true;
    if (need > *cap) {
        size_t grown = *cap > 0 ? *cap : 1024;
        while (grown < need) grown *= 2;
        DeepVertex *v = realloc(d->vertex, grown * sizeof *v);
        if (v) d->vertex = v, *cap = grown;
        ok = v != NULL;
    }
    for (int k = 0; k < n; k++) {
        if (ok && band[k].vertex) memcpy(d->vertex + *total, band[k].vertex, band[k].count * sizeof *d->vertex);
        if (ok) *total += band[k].count;
        ok = ok && band[k].vertex;
        free(band[k].vertex);
        band[k] = (Row){NULL, 0};
    }
    return ok;
}

/* Every row, band by band; *total the vertices appended. */
static bool build_rows(const DeepArgs *a, DeepMap *d, size_t *total)
{
    int rows = d->num_faces * d->res;
    long events = 0, capped = 0;
    size_t cap = 0;
    bool ok = true, appended = true;
    Row band[BAND_ROWS] = {{NULL, 0}};
    *total = 0;
#pragma omp parallel reduction(+ : events, capped) reduction(&& : ok)
    {
        Scratch sc = {0};
        bool grown = scratch_grow(&sc, 256);
        DeepVertex *buf = malloc((size_t)d->res * (size_t)a->max_vertices * sizeof *buf);
        ok = grown && buf;
        for (int r0 = 0; r0 < rows; r0 += BAND_ROWS) {
            int n = rows - r0 < BAND_ROWS ? rows - r0 : BAND_ROWS;
#pragma omp for schedule(dynamic, 1)
            for (int r = r0; r < r0 + n; r++) ok = ok && build_row(a, d, r, &sc, buf, &band[r - r0], &events, &capped);
#pragma omp single
            appended = append_band(d, band, n, total, &cap) && appended;
        }
        free(buf);
        free(sc.event), free(sc.zb), free(sc.c), free(sc.out);
    }
    d->events = events;
    d->capped = capped;
    return ok && appended;
}

static void *build_deep_map(const void *args, Error *err)
{
    const DeepArgs *a = args;
    const ShadowMap *c = a->centre;
    DeepMap *d = calloc(1, sizeof *d);
    size_t texels = (size_t)c->num_faces * (size_t)c->res * (size_t)c->res, total = 0;
    if (d) *d = (DeepMap){a->n, a->error, a->max_vertices, c->res, c->num_faces, texels, NULL, NULL, NULL, 0, 0};
    bool ok = d && (d->first = malloc((texels + 1) * sizeof *d->first)) && (d->unknown = calloc(texels, 1)) &&
              build_rows(a, d, &total);
    if (ok) {
        d->first[0] = 0; /* the counts build_row left in first[t + 1], summed into offsets */
        for (size_t t = 0; t < texels; t++) d->first[t + 1] += d->first[t];
        DeepVertex *v = realloc(d->vertex, (total ? total : 1) * sizeof *v); /* the doubling's slack back */
        if (v) d->vertex = v;
        return d;
    }
    if (d) deep_destroy(d);
    error_set(err, "out of memory building the penumbra deep shadow map (%zu texels)", texels);
    return NULL;
}

/* The bound checked before any map is drawn: every texel at the cap. */
static bool deep_check(size_t texels, int max_vertices, int res, Error *err)
{
    double bytes = (double)texels * (max_vertices * (double)sizeof(DeepVertex) + sizeof(uint32_t) + 1.0);
    if (bytes <= (double)SHADOWMAP_MAX_BYTES) return true;
    return error_set(err, "max_vertices = %d at map_size = %d take up to %.2f GiB, above the %.0f GiB limit: lower "
                          "max_vertices or map_size",
                     max_vertices, res, bytes / (1u << 30), (double)SHADOWMAP_MAX_BYTES / (1u << 30));
}

/* The nearest finite stored depth of a map as a distance from its light
 * (linear depth along a face's axis is at most the distance), or 0 when a
 * NaN texel must be marched to. */
static double nearest_stored(const ShadowMap *m)
{
    double best = INFINITY;
    for (int f = 0; f < m->num_faces; f++)
        for (int j = 0; j < m->res; j++) {
            const float *row = shadowmap_row(m, f, j, m->res);
            for (int i = 0; i < m->res; i++) {
                if (isnan(row[i])) return 0.0;
                best = fmin(best, smap_linear_depth(m, f, row[i]));
            }
        }
    return isfinite(best) ? best * (1.0 - 1e-6) : 0.0; /* the margin: locate's rounding */
}

/* The stored depth's bounds over each PDM_TILE^2 tile of each face (a tile
 * holding a NaN gets [-inf, +inf]: never skipped); false out of memory. */
static bool tile_bounds(SampleMap *s)
{
    const ShadowMap *m = s->map;
    int n = (m->res + PDM_TILE - 1) / PDM_TILE;
    size_t count = (size_t)m->num_faces * n * n;
    s->tiles = n;
    s->tile_min = malloc(count * sizeof *s->tile_min);
    s->tile_max = malloc(count * sizeof *s->tile_max);
    if (!s->tile_min || !s->tile_max) return false;
    for (size_t k = 0; k < count; k++) s->tile_min[k] = INFINITY, s->tile_max[k] = -INFINITY;
    for (int f = 0; f < m->num_faces; f++)
        for (int j = 0; j < m->res; j++) {
            const float *row = shadowmap_row(m, f, j, m->res);
            for (int i = 0; i < m->res; i++) {
                size_t k = ((size_t)f * n + j / PDM_TILE) * n + i / PDM_TILE;
                float lo = isnan(row[i]) ? -INFINITY : row[i], hi = isnan(row[i]) ? INFINITY : row[i];
                s->tile_min[k] = lo < s->tile_min[k] ? lo : s->tile_min[k];
                s->tile_max[k] = hi > s->tile_max[k] ? hi : s->tile_max[k];
            }
        }
    return true;
}

typedef struct PdmState {
    SmapBias bias;
    const ShadowMap *centre;
    const DeepMap *deep;
    bool bilinear;
} PdmState;

static const DeepMap *acquire_deep_map(const TechContext *ctx, DeepArgs *a, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, "penumbra deep map 1");
    hash_u64(&h, a->centre->key);
    for (int k = 0; k < a->n; k++) hash_u64(&h, a->sample[k].map->key);
    hash_f64(&h, a->error);
    hash_f64(&h, a->bias.slope);
    hash_f64(&h, a->bias.slope_max_texels);
    hash_f64(&h, a->max_vertices);
    uint64_t key = hash_final(&h);
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %d samples, %d^2 x %d faces, error %g, cap %d", ctx->light_index + 1, a->n,
             a->centre->res, a->centre->num_faces, a->error, a->max_vertices);
    const DeepMap *d = rm_acquire(ctx->rm, &kind_deep_map, key, desc, build_deep_map, a, err);
    if (!d) return NULL;
    char note[160];
    snprintf(note, sizeof note, "%ld events, %u vertices (%.2f per texel, %.1f MiB), %ld texels capped", d->events,
             d->first[d->texels], (double)d->first[d->texels] / (double)d->texels,
             (double)d->first[d->texels] * sizeof(DeepVertex) / (1u << 20), d->capped);
    rm_log_note(ctx->rm, kind_deep_map.name, key, note);
    return d;
}

static bool pdm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    PdmState *st = calloc(1, sizeof *st);
    const ShadowMap **map = calloc(LS_MAX_SAMPLES, sizeof *map);
    vec3 *point = calloc(LS_MAX_SAMPLES, sizeof *point);
    SampleMap *sample = calloc(LS_MAX_SAMPLES, sizeof *sample);
    if (!st || !map || !point || !sample) {
        free(st), free(map), free(point), free(sample);
        return error_set(err, "out of memory");
    }
    st->bias = smap_bias(p, ctx->scene);
    st->bilinear = (int)p[P_FILTER] == FILTER_BILINEAR;
    ShadowMapSpec spec = smap_spec(p);
    Light probe = {.kind = LIGHT_POINT, .position = ctx->light->position};
    size_t most_texels = shadowmap_bytes_for(&probe, &spec) / sizeof(float);
    dvec3 margin = d3_from(v3(1.0f, 1.0f, 1.0f));
    margin = d3_scale(margin, 1e-3 * scene_extent(ctx->scene));
    DeepArgs a = {.box_min = d3_sub(d3_from(ctx->scene->bounds_min), margin),
                  .box_max = d3_add(d3_from(ctx->scene->bounds_max), margin),
                  .sample = sample,
                  .n = (int)p[P_SAMPLES],
                  .max_vertices = (int)p[P_MAX_VERTICES],
                  .error = p[P_ERROR],
                  .bias = st->bias};
    bool ok = deep_check(most_texels, a.max_vertices, spec.res, err) &&
              ls_sample_maps(ctx, &spec, a.n, (int)p[P_PATTERN], point, map, err) &&
              (a.centre = ls_point_map(ctx, &spec, ctx->light->position, err));
    for (int k = 0; ok && k < a.n; k++) {
        sample[k] = (SampleMap){map[k], d3_from(point[k]), nearest_stored(map[k]), 0, NULL, NULL};
        if (!tile_bounds(&sample[k])) ok = error_set(err, "out of memory");
    }
    ok = ok && (st->deep = acquire_deep_map(ctx, &a, err));
    st->centre = a.centre;
    for (int k = 0; k < a.n; k++) free(sample[k].tile_min), free(sample[k].tile_max);
    free(map), free(point), free(sample);
    if (!ok) {
        free(st);
        return false;
    }
    *state = st;
    return true;
}

/* A texel's function at depth z (right-continuous at a step; held beyond
 * the ends), reading its vertices up to z. */
static float deep_value(const DeepMap *d, size_t t, double z)
{
    if (d->unknown[t] || isnan(z)) return NAN;
    const DeepVertex *v = d->vertex + d->first[t];
    int n = (int)(d->first[t + 1] - d->first[t]), k = 0;
    while (k < n && v[k].z <= z) k++;
    work_texels((uint64_t)(k < n ? k + 1 : n), sizeof *v); /* the vertices read (core/counters.h) */
    if (k == 0) return v[0].v;
    if (k == n) return v[n - 1].v;
    double w = (z - v[k - 1].z) / ((double)v[k].z - v[k - 1].z); /* v[k].z > z >= v[k - 1].z */
    return (float)(v[k - 1].v + w * ((double)v[k].v - v[k - 1].v));
}

/* Texel (i, j) of the receiver's face at the receiver's (plane) depth there,
 * linear along the face's axis. */
static float texel_at(const PdmState *st, const SmapReceiver *r, int i, int j)
{
    int res = st->deep->res;
    i = i < 0 ? 0 : i >= res ? res - 1 : i;
    j = j < 0 ? 0 : j >= res ? res - 1 : j;
    size_t t = ((size_t)r->mc.face * res + j) * res + i;
    return deep_value(st->deep, t, smap_linear_depth(st->centre, r->mc.face, smap_ref_at(r, i, j)));
}

static float pdm_visibility(const PdmState *st, const SmapReceiver *r, float *vertices)
{
    int i, j, res = st->deep->res;
    smap_texel(r, &i, &j);
    i = i < res ? i : res - 1;
    j = j < res ? j : res - 1;
    size_t t = ((size_t)r->mc.face * res + j) * res + i;
    *vertices = (float)(st->deep->first[t + 1] - st->deep->first[t]);
    if (!st->bilinear) return texel_at(st, r, i, j);
    double s = r->mc.s - 0.5, u = r->mc.t - 0.5, fs = s - floor(s), ft = u - floor(u);
    int i0 = (int)floor(s), j0 = (int)floor(u);
    double v0 = (1.0 - fs) * texel_at(st, r, i0, j0) + fs * texel_at(st, r, i0 + 1, j0);
    double v1 = (1.0 - fs) * texel_at(st, r, i0, j0 + 1) + fs * texel_at(st, r, i0 + 1, j0 + 1);
    return (float)((1.0 - ft) * v0 + ft * v1);
}

static void pdm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const PdmState *st = state;
    SmapReceiver r[SMAP_BATCH];
    bool inside[SMAP_BATCH];
    for (int s0 = begin; s0 < end; s0 += SMAP_BATCH) {
        int count = end - s0 < SMAP_BATCH ? end - s0 : SMAP_BATCH;
        smap_receivers(st->centre, &st->bias, ctx->vs->p_world + s0, ctx->vs->n_geom_world + s0, ctx->cls + s0,
                       count, r, inside);
        for (int q = 0; q < count; q++) {
            int s = s0 + q;
            if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
            float vertices = 0.0f;
            float v = inside[q] ? pdm_visibility(st, &r[q], &vertices) : 1.0f; /* off the map: lit, as light_sampling */
            tech_store(ctx, out, begin, s, v);
            if (ctx->aux) ctx->aux[s] = vertices;
        }
    }
}

const Technique tech_penumbra_deep_map = {
    .name = "penumbra_deep_map",
    .family = "soft",
    .source = "course §5.2.4 (St-Amour, Paquette & Poulin 2005, penumbra deep shadow maps; compression of Lokovic "
              "& Veach 2000)",
    .summary = "per texel of the light centre's map, the fraction of N light samples' hard maps that see each depth "
               "of its ray, marched through their texels and compressed to a piecewise-linear function within "
               "`error`; V = that function at the receiver's depth",
    .params = pdm_params,
    .num_params = (int)(sizeof pdm_params / sizeof pdm_params[0]),
    .resources = pdm_resources,
    .aux = pdm_aux,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "samples",
    .prepare = pdm_prepare,
    .evaluate = pdm_evaluate,
    .release = free,
};
