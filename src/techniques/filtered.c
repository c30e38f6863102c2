/* filtered.c -- the resource chain, lookup and Chebyshev bound shared by the
 * prefiltered shadow-map techniques (filtered.h; course ch.4). */
#include "techniques/filtered.h"

const char *const filter_prefilter_names[] = {PREFILTER_NAMES, NULL};
const char *const filter_lookup_names[] = {"nearest", "bilinear", NULL};
const char *const filter_precision_names[] = {"f64", "f32", NULL};
const char *const filter_resources[] = {"shadow_map", "view_samples", "moments", "box_blur", "sat", NULL};

bool filtered_acquire(const TechContext *ctx, MomentSpec spec, FilteredMaps *fm, Error *err)
{
    const double *p = ctx->params;
    ShadowMapSpec map_spec = smap_spec(p);
    fm->map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &map_spec, err);
    if (!fm->map) return false;
    spec.f64 = (int)p[FILTER_P_PRECISION] == 0;
    const MomentMap *mm = res_moment_map(ctx->rm, fm->map, &spec, err);
    if (!mm) return false;
    fm->K = (int)p[FILTER_P_K];
    fm->bilinear = (int)p[FILTER_P_LOOKUP] == FILTER_LOOKUP_BILINEAR;
    fm->pf = res_prefiltered(ctx->rm, mm, (PrefilterKind)(int)p[FILTER_P_PREFILTER], fm->K, err);
    fm->bias = smap_depth_bias(p, ctx->scene);
    fm->bias.filter_radius = 0.5 * (fm->K - 1); /* as pcf's: the same slope bias for the same window */
    return fm->pf != NULL;
}

bool filtered_lookup(const FilteredMaps *fm, const TechContext *ctx, int s, FilteredSample *fs)
{
    if (!smap_receiver(fm->map, &fm->bias, ctx->vs->p_world[s], ctx->vs->n_geom_world[s], &fs->r)) return false;
    fs->u = prefilter_depth_unit(fm->map, fs->r.mc.face, fs->r.ref);
    fs->fp = pf_footprint(fs->r.mc.s, fs->r.mc.t, fm->K, fm->bilinear);
    fs->reliable = pf_fetch(fm->pf, fs->r.mc.face, &fs->fp, fs->m);
    return true;
}

double chebyshev_upper(double mean, double m2, double d, double min_variance)
{
    if (isnan(mean) || isnan(m2) || isnan(d)) return NAN; /* an unknown moment: no bound */
    if (!(d > mean)) return 1.0;
    double var = fmax(m2 - mean * mean, min_variance), t = d - mean, den = var + t * t;
    return den > 0.0 ? var / den : 1.0; /* den = 0: var = 0 and (d - mean)^2 underflowed, d == mean in effect */
}

double evsm_positive_bound(const double *m, double u, double c_pos, double min_variance)
{
    double w = exp(c_pos * (u - 1.0)), slope = c_pos * w;
    return chebyshev_upper(m[0], m[1], w, min_variance * slope * slope);
}

double evsm_negative_bound(const double *m, double u, double c_neg, double min_variance)
{
    double w = exp(-c_neg * u), slope = c_neg * w;
    return chebyshev_upper(m[2], m[3], -w, min_variance * slope * slope);
}

double bleed_reduce(double p, double amount)
{
    if (!(amount > 0.0)) return p;
    double x = (p - amount) / (1.0 - amount);
    x = x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
    return x * x * (3.0 - 2.0 * x);
}

/* ---- Hamburger four-moment reconstruction (filtered.h) ---- */

#define MSM_PIVOT_MIN 1e-12

/* The biased moments b and the roots z2 <= z3 of Algorithm 2's quadratic
 * (Cholesky of the Hankel matrix; the roots without cancellation). */
static void msm_support(const double *b_in, double zf, double alpha, double *b, double *z2, double *z3)
{
    static const double b_bias[4] = {0.0, 0.63, 0.0, 0.63};
    for (int k = 0; k < 4; k++) b[k] = (1.0 - alpha) * b_in[k] + alpha * b_bias[k];
    double l21 = b[0], l31 = b[1];
    double l22 = sqrt(fmax(b[1] - l21 * l21, MSM_PIVOT_MIN));
    double l32 = (b[2] - l21 * l31) / l22;
    double l33 = sqrt(fmax(b[3] - l31 * l31 - l32 * l32, MSM_PIVOT_MIN));
    double y2 = (zf - l21) / l22, y3 = (zf * zf - l31 - l32 * y2) / l33;
    double c3 = y3 / l33, c2 = (y2 - l32 * c3) / l22, c1 = 1.0 - l21 * c2 - l31 * c3;
    /* q = -(c2 + sign(c2) sqrt(disc)) / 2, x = q / c3 and c1 / q */
    double r = sqrt(fmax(c2 * c2 - 4.0 * c1 * c3, 0.0)), q = -0.5 * (c2 + copysign(r, c2));
    *z2 = q / c3;
    *z3 = c1 / q;
    if (*z2 > *z3) { double t = *z2; *z2 = *z3; *z3 = t; }
}

/* The weight at za of the distribution on {za, zb, zc} with mean b[0] and
 * second moment b[1] (Peters & Klein 2015, Algorithm 2's quotients). */
static double msm_weight(const double *b, double za, double zb, double zc)
{
    return (zb * zc - b[0] * (zb + zc) + b[1]) / ((za - zb) * (za - zc));
}

static bool msm_nan(const double *b, double zf) { return isnan(b[0] + b[1] + b[2] + b[3] + zf); }

double msm_lit(const double *b_in, double zf, double alpha)
{
    /* A NaN moment would vanish in the pivots' clamps (fmax(NaN, eps) = eps). */
    if (msm_nan(b_in, zf)) return NAN;
    double b[4], z2, z3;
    msm_support(b_in, zf, alpha, b, &z2, &z3);
    double G = zf <= z2 ? 0.0 : zf <= z3 ? msm_weight(b, z2, zf, z3) : 1.0 - msm_weight(b, zf, z2, z3);
    /* A degenerate quadratic (c3 or q = 0) leaves no usable roots: fall
     * back on Chebyshev's bound from the same (biased) first two moments. */
    if (!isfinite(G)) return chebyshev_upper(b[0], b[1], zf, 0.0);
    return 1.0 - (G < 0.0 ? 0.0 : G > 1.0 ? 1.0 : G);
}

bool msm_blockers(const double *b_in, double zf, double alpha, double *blocked, double *z_mean)
{
    if (msm_nan(b_in, zf)) {
        *blocked = *z_mean = NAN;
        return true;
    }
    double b[4], z2, z3;
    msm_support(b_in, zf, alpha, b, &z2, &z3);
    double w2 = zf > z2 ? msm_weight(b, z2, zf, z3) : 0.0, w3 = zf > z3 ? msm_weight(b, z3, zf, z2) : 0.0;
    *blocked = w2 + w3;
    if (!isfinite(*blocked) || !isfinite(w2 * z2 + w3 * z3)) return false;
    *z_mean = (w2 * z2 + w3 * z3) / *blocked; /* G = 0: NaN, the caller's "lit" */
    return true;
}
