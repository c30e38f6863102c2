/* essm.c -- `essm`: exponential soft shadow maps (Shen, Feng & Yang,
 * "Exponential Soft Shadow Mapping", EGSR 2013 / CGF 32(4)): PCSS whose
 * blocker search and filter are both ESM lookups (course §4.2.4, its sign
 * erratum), read over windows of any size from one summed-area table of
 * exponential maps (course §5.2.2.2), so a receiver costs two lookups at any
 * light size. The map holds e(u) = e^(c (u - 1)) and e^(-c u) at normalised
 * depth u (WARP_EXP of prefilter.h, evsm's moment map with c+ = c- = c;
 * its squares are stored but not read). At the receiver's u = d:
 *   1. search window (filtsoft.h): the ESM lit fraction
 *        q = E e(z) / e(d) = E e^(c (z - d))           (course Eq. 4.7, erratum)
 *      (the blockers' terms e^(c (z - d)) -> 0, the receiver's own texels 1);
 *      the blockers' mean of e^(-c z) from E e^(-c z) = q e^(-c d) +
 *      (1 - q) E_b e^(-c z), the lit texels taken at the receiver's depth
 *      (Yang et al. 2010's estimate, VSSM §4, filtsoft_blocker_mean, on the
 *      negative exponential), and z_avg = -ln(E_b e^(-c z)) / c, the blockers'
 *      exponential mean (by Jensen's inequality at most their mean depth,
 *      exact for one depth) [derived: the paper's text was not available to
 *      this lab; its abstract states an "extended exponential shadow mapping
 *      theory" for the blocker estimate, its formulas are not checked here];
 *   2. the filter window from z_avg (course §5.2.2 step 2);
 *   3. ESM over it: min(1, E e(z) / e(d)).
 * plane_normalise [OWN] divides both windows' E e(z) by the receiver plane's
 * own box mean of e(u) over that window in place of e(d) (log_receiver_mean):
 * a floor tilted to the light puts texels deeper than d in the window, whose
 * terms e^(c (z - d)) > 1 (course §4.2.4's failure, "invalidating the
 * summation") read lit where the umbra is (contact.lua: umbra leak 0.658 ->
 * 0.391, test_essm_moment_soft.c).
 * For one planar occluder parallel to the receiver the search window holds
 * the occluder's depth and the receiver's: q = 1 - f + f e^(-c gap) and
 * z_avg the occluder's depth up to e^(-c gap) terms, so the result is the
 * exhaustive PCSS box up to ESM's contact term e^(-c gap).
 * Float limits: the warp is scaled to at most 1, so nothing overflows; the
 * exponent's range ends at 80, inside ESM's fp32 bound c u < 88.7 (esm.c,
 * catalogue §4.2.4 [OWN] overflow), so e^(-c) and e(d) >= e^-80 stay normal
 * floats and the quotient by e(d) never divides by 0. A SAT's rounding,
 * about eps times the face's sum of e(u) (prefilter.h), swamps e(d) where
 * c (1 - d) > ln(1 / (eps N)) (f64, 1024^2: about 22): receivers that deep
 * in a face's depth range need a smaller c (or precision=f64 at least). */
#include <stdlib.h>
#include "core/nanmath.h"
#include "techniques/filtsoft.h"

enum { P_MAX_RADIUS = SMAP_NUM_DEPTH_BIAS_PARAMS, P_PRECISION, P_EXPONENT, P_LIT_EPS, P_PLANE };

#define ESSM_MAX_EXPONENT 80 /* esm's fp32 bound, c u < 88.7, with e^-c a normal float */

static const ParamDesc essm_params[] = {
    /* perspective faces (softmap.h), one cascade: a prefiltered table per face */
    SMAP_MAP_PARAMS_UPTO(MAP_PROJ_CUBE, 1, SPLIT_EXPLICIT),
    SMAP_DEPTH_BIAS_PARAMS, /* one reference depth against a prefiltered window */
    FILTSOFT_MAX_RADIUS_PARAM(31),
    FILTSOFT_PRECISION_PARAM,
    {"exponent", PARAM_FLOAT, 20, 0.1, ESSM_MAX_EXPONENT, "1 / normalised depth",
     "c of exp(c z) for both windows (course §4.2.4: 80); larger sharpens contacts (a gap g leaks e^(-c g)) but "
     "a summed-area table's rounding swamps receivers with c (1 - u) above about 22 (f64); at most 80, inside "
     "fp32's 88.7",
     NULL},
    FILTSOFT_LIT_THRESHOLD_PARAM("blocked fraction 1 - q"),
    {"plane_normalise", PARAM_BOOL, 1, 0, 1, "",
     "divide each window's mean of exp(c z) by the receiver plane's own mean over that window instead of "
     "exp(c d) [OWN]: a receiver tilted to the light, whose deeper texels give ESM terms above 1 (course §4.2.4's "
     "failure), then reads lit where nothing blocks; off is the plain ESM quotient",
     NULL},
};
FILTER_CHECK_TABLE(essm_params);

static const char *const essm_resources[] = {"shadow_map", "minmax_pyramid", "view_samples", "moments", "sat", NULL};

typedef struct EssmState {
    FiltSoft fs;
    const Prefiltered *sat; /* e^(c (u - 1)), e^(2 c (u - 1)), -e^(-c u), e^(-2 c u) */
    double c, lit_eps;
    bool plane;
} EssmState;

static bool essm_prepare(const TechContext *ctx, void **state, Error *err)
{
    const double *p = ctx->params;
    EssmState *st = calloc(1, sizeof *st);
    if (!st) return error_set(err, "out of memory");
    st->c = p[P_EXPONENT];
    st->lit_eps = p[P_LIT_EPS];
    st->plane = p[P_PLANE] != 0.0;
    MomentSpec spec = {.warp = WARP_EXP, .order = 4, .c_pos = st->c, .c_neg = st->c, .f64 = (int)p[P_PRECISION] == 0};
    if (!filtsoft_init(&st->fs, ctx, p[P_MAX_RADIUS], false, "essm", err) ||
        !(st->sat = filtsoft_sat(ctx, &st->fs, spec, err))) {
        free(st);
        return false;
    }
    /* the receiver's plane (smap_receiver) for plane_normalise; no texel is compared one by one */
    st->fs.bias.receiver_plane = st->plane;
    *state = st;
    return true;
}

/* ln(sinh(x) / x), without overflow: the log of the box mean of e^(x v) over v in [-1, 1]. */
static double log_sinhc(double x)
{
    double a = fabs(x);
    return a < 1e-4 ? a * a / 6.0 : a + log1p(-exp(-2.0 * a)) - log(2.0 * a);
}

/* The receiver plane's normalised depth at texel offset (ds, dt) (the plane
 * of smap_receiver in the stored metric, 1/depth for linear perspective). */
static double plane_unit(const EssmState *st, const SmapReceiver *r, double ds, double dt)
{
    double g = r->g0 + r->gs * ds + r->gt * dt;
    return prefilter_depth_unit(st->fs.sm.map, r->mc.face, r->reciprocal ? 1.0 / g : g);
}

/* ln of the window mean of e^(k c (u' - o)) over the receiver's own texels
 * u' (k = 1, o = 1: the stored positive warp; k = -1, o = 0: the negative).
 * Plain ESM (course Eq. 4.7, erratum) takes them all at the reference d:
 * k c (d - o). With plane_normalise [OWN], u' = d + a x + b y on the
 * receiver's plane (x, y in texels, a, b its slopes there), whose box mean
 * over the half-widths (hx, hy) factors: k c (d - o) + ln sinhc(c a hx) +
 * ln sinhc(c b hy) (sinhc even, so for both signs); so a window holding only
 * the receiver reads 1, and a receiver facing the light (a = b = 0) is
 * plain ESM. */
static double log_receiver_mean(const EssmState *st, const SmapReceiver *r, double u, FsWindow w, double k, double o)
{
    double plain = k * st->c * (u - o);
    if (!st->plane || !r->plane) return plain;
    double u0 = plane_unit(st, r, 0.0, 0.0), a = plane_unit(st, r, 1.0, 0.0) - u0, b = plane_unit(st, r, 0.0, 1.0) - u0;
    return plain + log_sinhc(st->c * a * w.hx) + log_sinhc(st->c * b * w.hy);
}

/* The ESM lit fraction over window w from its mean m0 of e^(c (z - 1)); unclamped, NaN kept. */
static double esm_lit(const EssmState *st, const SmapReceiver *r, double m0, double u, FsWindow w)
{
    return m0 / exp(log_receiver_mean(st, r, u, w, 1.0, 1.0));
}

/* Step 1: the blockers' exponential mean depth (normalised); false: lit. */
static bool essm_blocker(const EssmState *st, const SmapReceiver *r, const double *m, double u, FsWindow w,
                         double *z_avg)
{
    double q = nan_min(1.0, esm_lit(st, r, m[0], u, w)), e_occ;
    double lit_term = exp(log_receiver_mean(st, r, u, w, -1.0, 0.0)); /* the lit texels' mean of e^(-c z) */
    if (!filtsoft_blocker_mean(-m[2], q, lit_term, st->lit_eps, &e_occ)) return false;
    /* e_occ <= 0 is rounding (E e^(-c z) below the lit texels' share): blockers at the receiver (a NaN passes on) */
    double z = e_occ > 0.0 ? -log(e_occ) / st->c : e_occ <= 0.0 ? u : e_occ;
    *z_avg = nan_clamp(z, 0.0, u);
    return true;
}

static double essm_visibility(const EssmState *st, const SmapReceiver *r)
{
    FsWindow ws;
    double z_min; /* the search window's nearest depth, linear */
    if (!filtsoft_search(&st->fs, r, &ws, &z_min)) return 1.0;
    double u = filtsoft_unit(&st->fs, r), m[3], z_avg;
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, ws.hx, ws.hy, 3, m)) return NAN; /* a NaN window */
    if (!essm_blocker(st, r, m, u, ws, &z_avg)) return 1.0;
    FsWindow wf = filtsoft_filter_window(&st->fs, r, filtsoft_linear(&st->fs, r->mc.face, z_avg), z_min);
    if (!pf_fetch_box(st->sat, r->mc.face, r->mc.s, r->mc.t, wf.hx, wf.hy, 1, m)) return NAN;
    return esm_lit(st, r, m[0], u, wf);
}

static void essm_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const EssmState *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        SmapReceiver r;
        double v = 1.0;
        if (smap_receiver(st->fs.sm.map, &st->fs.bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &r))
            v = essm_visibility(st, &r);
        tech_store(ctx, out, begin, s, (float)filtsoft_unit_clamp(v));
    }
}

const Technique tech_essm = {
    .name = "essm",
    .family = "soft",
    .source = "Shen, Feng & Yang 2013 (exponential soft shadow mapping); course §4.2.4 (ESM), §5.2.2.2 (SAT); "
              "blocker mean of Yang et al. 2010 §4 on exp(-c z) [derived]",
    .summary = "PCSS from one summed-area table of exp(c z) and exp(-c z): the blocked fraction by ESM and the "
               "blockers' exponential mean depth over the search window, then ESM over the penumbra window",
    .params = essm_params,
    .num_params = (int)(sizeof essm_params / sizeof essm_params[0]),
    .resources = essm_resources,
    .rgb = false,
    .lights = LIGHT_BIT(LIGHT_SPHERE) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_RECT),
    .main_param = "exponent",
    .prepare = essm_prepare,
    .evaluate = essm_evaluate,
    .release = free,
};
