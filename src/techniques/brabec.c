/* brabec.c -- `brabec`: single-sample soft shadows on depth maps (Brabec &
 * Seidel 2002; course §5.2.1; seed 003 §2, which describes it as Parker's
 * algorithm, seed 002, carried over to depth maps). One depth map and
 * object-id map from the light's centre; for a receiver p:
 *   - lit by the hard test: search the map radially for the nearest blocked
 *     texel; its distance d to the hard shadow's edge and its depth z_b place p
 *     in that blocker's outer penumbra;
 *   - shadowed: search for the nearest unblocked texel; d and the depth z_b of
 *     p's own blocker place p in the inner penumbra.
 * The placement [OWN: the papers available here give no formula]: a straight
 * edge of a blocker at z_b casts a penumbra of half-width
 *     w = a (z_p - z_b) / (z_p z_b)            (tangent units, a = light radius),
 * centred on the hard edge (the same similar triangles as PCSS's window,
 * course §5.2.2; a rect light counts as the disk of its area), so with
 * tau = 1/2 + d / (2 w) outside and 1/2 - d / (2 w) inside, visibility is
 * Parker's Bernstein interpolant 3 tau^2 - 2 tau^3 (seed 002 §3) or tau.
 * The search stops at the first texel found, at the
 * widest penumbra any blocker beyond the near plane can cast, or at the
 * search radius (course §5.2.1's failure: occluders beyond it are ignored).
 * Blockers of the receiver's own object count (self_shadow, on by default):
 * the paper's object ids (seed 003 §2: "the algorithm allows no
 * self-shadowing") kept a surface from shadowing itself without a bias; the
 * receiver-plane bias does that here, and the ids lose every shadow an
 * object casts on itself (the bunny's umbra leaked 0.44, the teapot's 0.11;
 * issue 13). */
#include <stdlib.h>
#include "core/nanmath.h"
#include "techniques/softmap.h"

enum { FALLOFF_SMOOTH, FALLOFF_LINEAR };
static const char *const falloff_names[] = {"smoothstep", "linear", NULL};

enum { P_SEARCH = SMAP_NUM_PARAMS, P_FALLOFF, P_SELF_SHADOW };

#define BRABEC_MAX_SEARCH 64

static const ParamDesc brabec_params[] = {
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, LIGHTVIEW_MAX_CASCADES, SPLIT_EXPLICIT),
    SMAP_BIAS_PARAMS_PLANE(1),
    {"search_radius", PARAM_INT, 32, 1, BRABEC_MAX_SEARCH, "texels",
     "radius of the neighbourhood searched for the nearest blocked (or unblocked) texel", NULL},
    {"falloff", PARAM_ENUM, FALLOFF_SMOOTH, 0, 1, "",
     "visibility across the penumbra: smoothstep (Parker's 3 tau^2 - 2 tau^3, seed 002 §3) or linear",
     falloff_names},
    {"self_shadow", PARAM_BOOL, 1, 0, 1, "",
     "let an object's own texels block it (off in the paper, seed 003 §2: blockers must carry another object id, "
     "which loses every shadow an object casts on itself; the receiver-plane bias keeps surfaces from shadowing "
     "themselves)",
     NULL},
};

static const char *const brabec_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", NULL};

/* A texel offset of the search, nearest first. */
typedef struct Offset { int16_t di, dj; float dist; } Offset;

typedef struct BrabecState {
    SoftMap sm;
    SmapBias bias;
    int falloff;
    bool self_shadow;
    int32_t *object_of_triangle; /* the map's triangle ids -> scene object, or NULL */
    Offset *offsets;             /* within search_radius texels, sorted by tangent distance */
    int num_offsets;
    double search_tangent;       /* the search radius in tangent units */
} BrabecState;

static void brabec_release(void *state)
{
    BrabecState *st = state;
    if (!st) return;
    free(st->object_of_triangle);
    free(st->offsets);
    free(st);
}

static int by_distance(const void *a, const void *b)
{
    float x = ((const Offset *)a)->dist, y = ((const Offset *)b)->dist;
    return (x > y) - (x < y);
}

/* The search order: every offset within the radius, nearest first (the
 * tangent distance, so rectangular texels are searched radially too). */
static bool make_offsets(BrabecState *st, int radius, Error *err)
{
    const SoftFace *f = &st->sm.face[0]; /* every face of a map has the same texel size */
    int side = 2 * radius + 1;
    st->offsets = malloc(sizeof *st->offsets * (size_t)side * (size_t)side);
    if (!st->offsets) return error_set(err, "out of memory");
    st->search_tangent = radius * fmin(f->dx, f->dy);
    st->num_offsets = 0;
    for (int dj = -radius; dj <= radius; dj++)
        for (int di = -radius; di <= radius; di++) {
            double d = hypot(di * f->dx, dj * f->dy);
            if (d <= st->search_tangent) st->offsets[st->num_offsets++] = (Offset){(int16_t)di, (int16_t)dj, (float)d};
        }
    qsort(st->offsets, (size_t)st->num_offsets, sizeof *st->offsets, by_distance);
    return true;
}

/* The map's triangle ids count the caster objects' triangles in scene order. */
static bool make_object_table(BrabecState *st, const Scene *scene, Error *err)
{
    int total = 0;
    for (int k = 0; k < scene->num_objects; k++)
        if (scene->objects[k].caster) total += scene->objects[k].mesh.num_triangles;
    st->object_of_triangle = malloc(sizeof *st->object_of_triangle * (size_t)(total > 0 ? total : 1));
    if (!st->object_of_triangle) return error_set(err, "out of memory");
    int t = 0;
    for (int k = 0; k < scene->num_objects; k++)
        for (int i = 0; scene->objects[k].caster && i < scene->objects[k].mesh.num_triangles; i++)
            st->object_of_triangle[t++] = k;
    return true;
}

static bool brabec_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    BrabecState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->self_shadow = p[P_SELF_SHADOW] != 0.0;
    ShadowMapSpec spec = smap_spec(p);
    spec.triangle_ids = !st->self_shadow;
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    bool ok = map && softmap_init(&st->sm, ctx->rm, map, ctx->light, "brabec", err) &&
              make_offsets(st, (int)p[P_SEARCH], err) &&
              (st->self_shadow || make_object_table(st, ctx->scene, err));
    if (!ok) {
        brabec_release(st);
        return false;
    }
    st->bias = smap_bias(p, ctx->scene);
    st->falloff = (int)p[P_FALLOFF];
    *state = st;
    return true;
}

/* Does texel (i, j) block the receiver (of scene object `object`)? */
static bool blocked(const BrabecState *st, const SmapReceiver *r, int object, int i, int j)
{
    const ShadowMap *m = st->sm.map;
    if (!(smap_ref_at(r, i, j) > shadowmap_texel(m, r->mc.face, i, j))) return false;
    if (st->self_shadow) return true;
    i = i < 0 ? 0 : i >= m->res ? m->res - 1 : i; /* clamped to the edge, as shadowmap_texel reads */
    j = j < 0 ? 0 : j >= m->res ? m->res - 1 : j;
    int32_t tri = m->triangle[((size_t)r->mc.face * (size_t)m->res + (size_t)j) * (size_t)m->res + (size_t)i];
    return tri >= 0 && st->object_of_triangle[tri] != object;
}

/* Half-width of the penumbra a blocker at depth z_b casts at depth z_p (tangent units). */
static double half_width(double a, double z_p, double z_b) { return a * (z_p - z_b) / (z_p * z_b); }

/* The nearest texel whose blocked state is `want`, its centre within
 * `limit` (tangent units) of p's own texel's; its distance from p to the
 * texels' shared edge (half a texel before its centre) in *edge, the texel
 * in *i, *j. A NaN depth met first makes *edge NaN (the answer is unknown). */
static bool nearest(const BrabecState *st, const SmapReceiver *r, int object, bool want, double limit, double *edge,
                    int *i, int *j)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    int i0, j0;
    smap_texel(r, &i0, &j0);
    double half_texel = 0.5 * fmin(f->dx, f->dy);
    for (int k = 0; k < st->num_offsets && st->offsets[k].dist <= limit; k++) {
        int ii = i0 + st->offsets[k].di, jj = j0 + st->offsets[k].dj;
        if (isnan(shadowmap_texel(st->sm.map, r->mc.face, ii, jj))) { /* unknown before any answer: NaN */
            *edge = NAN;
            return true;
        }
        if (blocked(st, r, object, ii, jj) != want) continue;
        *edge = fmax(0.0, hypot(softmap_di(r, ii) * f->dx, softmap_dj(r, jj) * f->dy) - half_texel);
        *i = ii;
        *j = jj;
        return true;
    }
    return false;
}

static double falloff(int kind, double tau)
{
    tau = fmin(fmax(tau, 0.0), 1.0);
    return kind == FALLOFF_SMOOTH ? tau * tau * (3.0 - 2.0 * tau) : tau;
}

/* Texel centres within w + slack of p's own texel's hold every texel whose
 * edge lies within w of p: half a texel to the edge, and p is up to a half
 * diagonal from its texel's centre. */
static double search_slack(const SoftFace *f) { return 0.5 * fmin(f->dx, f->dy) + 0.71 * fmax(f->dx, f->dy); }

/* How far a lit receiver's blocker can be (tangent units, texel centres):
 * the widest penumbra a blocker beyond the near plane casts, narrowed twice
 * through the nearest depth the pyramid finds within it (course §5.2.3.4's
 * search area through z_min); false when nothing in reach can block. */
static bool outer_limit(const BrabecState *st, const SmapReceiver *r, double a, double *limit)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    double z_p = r->mc.depth_linear, z_near = f->near_world, slack = search_slack(f);
    int i, j;
    smap_texel(r, &i, &j);
    for (int pass = 0; pass < 3; pass++) {
        *limit = fmin(half_width(a, z_p, z_near), st->search_tangent) + slack;
        int ri = (int)ceil(*limit / f->dx), rj = (int)ceil(*limit / f->dy); /* the offsets nearest() may visit */
        double z_min;
        if (!softmap_may_block(&st->sm, r, i - ri, j - rj, i + ri, j + rj, &z_min)) return false;
        z_near = nan_max(z_near, z_min); /* NaN in reach: a NaN limit, so a NaN visibility */
    }
    return true;
}

/* The texel one step from (i, j) toward (i0, j0), along the larger offset
 * (both where they tie): the blocked side of the edge the search found. */
static void edge_blocker(int i, int j, int i0, int j0, int *ei, int *ej)
{
    int di = i0 - i, dj = j0 - j, adi = abs(di), adj = abs(dj);
    *ei = i + (adi >= adj ? (di > 0) - (di < 0) : 0);
    *ej = j + (adj >= adi ? (dj > 0) - (dj < 0) : 0);
}

static float visibility(const BrabecState *st, const SmapReceiver *r, int object)
{
    const SoftFace *f = &st->sm.face[r->mc.face];
    double a = f->light.radius_world, z_p = r->mc.depth_linear, z_n = f->near_world, edge;
    int i, j;
    smap_texel(r, &i, &j);
    if (isnan(shadowmap_texel(st->sm.map, r->mc.face, i, j))) return NAN; /* the receiver's own texel: unknown */
    if (!blocked(st, r, object, i, j)) { /* outer penumbra: the nearest blocker */
        double limit;
        if (!outer_limit(st, r, a, &limit)) return 1.0f;
        if (isnan(limit)) return NAN;
        if (!nearest(st, r, object, true, limit, &edge, &i, &j)) return 1.0f;
        if (isnan(edge)) return NAN;
        double w = half_width(a, z_p, nan_max(softmap_depth(&st->sm, r->mc.face, i, j), z_n));
        return w > 0.0 ? (float)falloff(st->falloff, 0.5 + edge / (2.0 * w)) : 1.0f;
    }
    /* inner penumbra: the nearest unblocked texel is the place; the blocker at
     * that edge, the blocked texel next to it on p's side, sets the width */
    double w = half_width(a, z_p, nan_max(softmap_depth(&st->sm, r->mc.face, i, j), z_n));
    double limit = fmin(w, st->search_tangent) + search_slack(f);
    int i0 = i, j0 = j;
    if (!(w > 0.0) || !nearest(st, r, object, false, limit, &edge, &i, &j)) return 0.0f;
    if (isnan(edge)) return NAN;
    int ei, ej;
    edge_blocker(i, j, i0, j0, &ei, &ej);
    double w_edge = half_width(a, z_p, nan_max(softmap_depth(&st->sm, r->mc.face, ei, ej), z_n));
    return w_edge > 0.0 ? (float)falloff(st->falloff, 0.5 - edge / (2.0 * w_edge)) : 0.0f;
}

static void brabec_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const BrabecState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        float v = 1.0f;
        if (smap_receiver(st->sm.map, &st->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = visibility(st, &r, ctx->vs->object[s]);
        tech_store(ctx, out, begin, s, v);
    }
}

const Technique tech_brabec = {
    .name = "brabec",
    .family = "soft",
    .source = "course §5.2.1 (Brabec & Seidel 2002), seed 003 §2; penumbra shape from seed 002 §3",
    .summary = "radial search of the depth map for the nearest blocked (or unblocked) texel; its distance and "
               "depth place the receiver in an outer (or inner) penumbra",
    .params = brabec_params,
    .num_params = (int)(sizeof brabec_params / sizeof brabec_params[0]),
    .resources = brabec_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "search_radius",
    .prepare = brabec_prepare,
    .evaluate = brabec_evaluate,
    .release = brabec_release,
};
