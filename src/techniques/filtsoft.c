/* filtsoft.c -- PCSS's windows and the prefiltered maps the constant-time
 * soft shadows read (filtsoft.h; course §5.2.2, §5.2.2.2). */
#include "techniques/filtsoft.h"
#include "core/nanmath.h"

bool filtsoft_init(FiltSoft *fs, const TechContext *ctx, double max_radius, bool receiver_plane, const char *tech,
                   Error *err)
{
    ShadowMapSpec spec = smap_spec(ctx->params);
    const ShadowMap *map = res_shadow_map(ctx->rm, ctx->scene, ctx->light_index, &spec, err);
    if (!map || !softmap_init(&fs->sm, ctx->rm, map, ctx->light, tech, err)) return false;
    fs->bias = receiver_plane ? smap_bias(ctx->params, ctx->scene) : smap_depth_bias(ctx->params, ctx->scene);
    fs->max_radius = max_radius;
    return true;
}

/* Tangent half-widths -> texels, clamped to [FILTSOFT_MIN_HALF, max_radius]
 * by comparisons, so a NaN width (a NaN depth upstream) stays NaN: the SAT
 * then refuses the window and the technique returns NaN, counted as
 * non-finite, never a value that hides it. */
static double clamp_half(double h, double max_radius)
{
    return h < FILTSOFT_MIN_HALF ? FILTSOFT_MIN_HALF : h > max_radius ? max_radius : h;
}

static FsWindow window(const FiltSoft *fs, const SoftFace *f, double k)
{
    FsWindow w = {clamp_half(f->light.half_x * k / f->dx, fs->max_radius),
                  clamp_half(f->light.half_y * k / f->dy, fs->max_radius)};
    return w;
}

static bool may_block(const FiltSoft *fs, const SmapReceiver *r, FsWindow w, double *z_min_linear)
{
    return softmap_may_block(&fs->sm, r, (int)floor(r->mc.s - w.hx), (int)floor(r->mc.t - w.hy),
                             (int)floor(r->mc.s + w.hx), (int)floor(r->mc.t + w.hy), z_min_linear);
}

bool filtsoft_search(const FiltSoft *fs, const SmapReceiver *r, FsWindow *w, double *z_min)
{
    const SoftFace *f = &fs->sm.face[r->mc.face];
    double z_p = r->mc.depth_linear, z_cut = f->near_world;
    for (int pass = 0; pass < 3; pass++) {
        *w = window(fs, f, (z_p - z_cut) / (z_p * z_cut)); /* course §5.2.2 step 1, per unit of light half-extent */
        if (pass == 2) break;
        double z;
        if (!may_block(fs, r, *w, &z)) return false;
        z_cut = nan_max(z_cut, z);
        if (isnan(z_cut)) { /* a NaN depth in reach: the window is unknown */
            *w = (FsWindow){NAN, NAN};
            break;
        }
    }
    *z_min = z_cut;
    return true;
}

FsWindow filtsoft_filter_window(const FiltSoft *fs, const SmapReceiver *r, double z_avg, double z_min)
{
    const SoftFace *f = &fs->sm.face[r->mc.face];
    double z_p = r->mc.depth_linear, z_lo = z_min > f->near_world ? z_min : f->near_world;
    /* d_blocker -> 0 (course §5.2.2.1, [OWN] degenerate inputs): blockers lie beyond the near plane and no
     * nearer than the window's nearest texel; a moment estimate below it (Chebyshev's bound over a window
     * whose receiver spans depths, [OWN]) would otherwise take the widest window there */
    z_avg = z_avg < z_lo ? z_lo : z_avg > z_p ? z_p : z_avg;
    return window(fs, f, (z_p - z_avg) / (z_avg * z_p)); /* course §5.2.2 step 2 */
}

double filtsoft_unit(const FiltSoft *fs, const SmapReceiver *r)
{
    return prefilter_depth_unit(fs->sm.map, r->mc.face, r->ref);
}

double filtsoft_linear(const FiltSoft *fs, int face, double u)
{
    const ShadowMap *m = fs->sm.map;
    const RasterView *rv = &m->view.face[face].raster;
    /* prefilter_depth_unit's inverse: linear maps store near + u (far - near), ndc maps u itself */
    double stored = m->spec.depth == RASTER_DEPTH_LINEAR ? rv->depth_near + u * (rv->depth_far - rv->depth_near) : u;
    return smap_linear_depth(m, face, stored);
}

const Prefiltered *filtsoft_sat(const TechContext *ctx, const FiltSoft *fs, MomentSpec spec, Error *err)
{
    const MomentMap *mm = res_moment_map(ctx->rm, fs->sm.map, &spec, err);
    return mm ? res_prefiltered(ctx->rm, mm, PREFILTER_SAT, 1, err) : NULL;
}

bool filtsoft_blocker_mean(double mean_all, double lit, double d, double eps, double *z_occ)
{
    double blocked = 1.0 - lit;
    if (blocked < eps) return false; /* a NaN passes on into z_occ */
    *z_occ = (mean_all - lit * d) / blocked;
    return true;
}

void filtsoft_fourier_coefficients(int terms, double damping, double *coef)
{
    for (int k = 1; k <= terms; k++) {
        double x = (double)k / terms;
        coef[k - 1] = 2.0 * exp(-damping * x * x) / (M_PI * (2 * k - 1)); /* c_k = pi (2k - 1) */
    }
}

double filtsoft_fourier_step(const double *coef, int terms, const double *m, double mean_w, double d)
{
    double at_d[PREFILTER_MAX_CHANNELS], sum = 0.5 * mean_w;
    fourier_basis(d, terms, at_d);
    for (int k = 0; k < terms; k++) sum += coef[k] * (at_d[2 * k + 1] * m[2 * k] - at_d[2 * k] * m[2 * k + 1]);
    return sum;
}
