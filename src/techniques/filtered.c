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
