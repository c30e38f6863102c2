/* test_param_effect.c -- no parameter that does nothing (issue 13 §1): for
 * every technique and every parameter, two values inside its range, with the
 * parameter's declared condition (tech_param_when) made to hold, give
 * different outputs (visibility or aux channels, bit for bit) on at least one
 * scene of a small fixed set whose light the technique handles:
 * sphere-on-plane (sphere light), contact (rect), textured-light (textured
 * rect: light-colour parameters) and terrain (directional sun over a 1.5 km
 * view: cascades, splits and warps). "Output" is what a run records: the
 * visibility, the aux channels and the resource kinds it acquired (a SAT
 * for a box blur). Images of 48 x 36 samples and maps of 128^2 texels keep
 * the whole registry to seconds, on one thread (48 x 36 samples leave
 * nothing to share, and idle OpenMP workers spin: 1.7 s of CPU instead of
 * 14 s on a loaded machine). The values tried are the default, then the
 * range's ends, midpoint and small steps, or every enum choice; a value the
 * technique refuses (a projection the soft maps cannot use) is skipped. */
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "filtered_fixtures.h"
#include "lab/compare.h"
#include "techniques/smap.h"
#include "test.h"

#define EFFECT_W 48
#define EFFECT_H 36
#define EFFECT_MAP_SIZE 128
#define EFFECT_MAX_TRIES 12

static const char *const effect_scenes[] = {"scenes/sphere-on-plane.lua", "scenes/contact.lua",
                                            "scenes/textured-light.lua", "scenes/terrain.lua"};
#define EFFECT_NUM_SCENES ((int)(sizeof effect_scenes / sizeof effect_scenes[0]))

/* Settings under which a parameter's effect shows that are no condition of
 * it (it acts without them, only less visibly on 48 x 36 samples): depth
 * precision shows without slope bias, or in pcss's fractional box weights; later explicit splits need the
 * earlier ones given (split_1 = 2, split_2 = 3 world units: inside the views);
 * which cascade a point reads shows at more cascade borders. */
static const struct { const char *param, *settings; } probes[] = {
    {"depth", "depth_bits=u16 slope_bias=0"},
    {"depth_bits", "slope_bias=0"},
    {"depth_bits", "sampling=exhaustive"},
    {"depth_bits", "depth=ndc"}, /* backprojection, occlusion_textures: linear depth's quantisation is absorbed */
    /* layered_attenuation: depth precision shows once epsilon nears the depth step */
    {"depth", "depth_bits=u16 epsilon=0.001"},
    {"depth_bits", "epsilon=0.001"},
    {"stabilize", "projection=perspective"}, /* light_sampling: auto gives its point samples cube maps */
    {"extrusion", "distance=0.5"}, /* shadow_volume: the default finite length outreaches every shadow */
    {"split_2", "split_1=2"},
    {"split_3", "split_1=2 split_2=3"},
    {"cascade_select", "cascades=8"},
    {"cascade_blend", "cascades=8"},
    {"blend", "budget=4"}, /* mssm, ysm: at 128^2 their narrow search areas fit budget 32 at level 0 */
};

/* The test's base values: the defaults, a small map, k's condition (when
 * `enable`), then the settings ("name=value ..."; NULL: none); false if
 * one does not apply. */
static bool base_values(const Technique *t, int k, bool enable, const char *settings, double *v)
{
    tech_params_default(t, v);
    if (smap_has_map_params(t)) v[SMAP_P_MAP_SIZE] = EFFECT_MAP_SIZE;
    if (enable) tech_param_enable(t, k, v);
    char buf[256], *save = NULL;
    Error err;
    snprintf(buf, sizeof buf, "%s", settings ? settings : "");
    for (char *a = strtok_r(buf, " ", &save); a; a = strtok_r(NULL, " ", &save))
        if (!tech_param_parse(t, a, v, &err)) return false;
    return true;
}

/* Values to try for parameter k: `base` first, then every enum choice, or
 * the range's ends, midpoint and two small steps above the minimum. */
static int try_values(const ParamDesc *p, double base, double *out)
{
    double tries[EFFECT_MAX_TRIES];
    int n = 0, m = 0;
    if (p->type == PARAM_ENUM || p->type == PARAM_BOOL) {
        for (double v = p->min; v <= p->max && n < EFFECT_MAX_TRIES; v++) tries[n++] = v;
    } else {
        double span = p->max - p->min, mid = p->min + 0.5 * span;
        double steps[] = {p->min, p->max, mid, p->min + 1e-3 * span, p->min + 1e-6 * span, p->min + 1e-7 * span,
                          p->min + 5e-9 * span, p->min + 4e-9 * span};
        for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++)
            tries[n++] = p->type == PARAM_INT ? floor(steps[i]) : steps[i];
    }
    out[m++] = base;
    for (int i = 0; i < n; i++)
        if (tries[i] != base) out[m++] = tries[i];
    return m;
}

static bool same_image(const Image *a, const Image *b)
{
    size_t na = (size_t)a->width * a->height * a->channels, nb = (size_t)b->width * b->height * b->channels;
    return na == nb && (na == 0 || memcmp(a->data, b->data, na * sizeof *a->data) == 0);
}

static int kind_count(const RenderResult *r, const char *kind)
{
    int n = 0;
    for (int i = 0; i < r->num_tech_resources; i++) n += strcmp(r->tech_resources[i].kind, kind) == 0;
    return n;
}

/* The resource kinds a render acquired, as a multiset (a box blur or a SAT,
 * a min-max pyramid or an N-buffer: what the record lists; a reused
 * resource lists its dependencies in another order than a built one). */
static bool same_resources(const RenderResult *a, const RenderResult *b)
{
    if (a->num_tech_resources != b->num_tech_resources) return false;
    for (int i = 0; i < a->num_tech_resources; i++)
        if (kind_count(a, a->tech_resources[i].kind) != kind_count(b, a->tech_resources[i].kind)) return false;
    return true;
}

static bool same_output(const RenderResult *a, const RenderResult *b)
{
    return same_image(&a->visibility, &b->visibility) && same_image(&a->aux, &b->aux) && same_resources(a, b);
}

static bool render(Lab *lab, const Technique *t, const double *v, RenderResult *out)
{
    Error err;
    RenderRequest rq = {.tech = t, .params = v, .light_index = 0, .repeat = 1};
    return lab_render(lab, &rq, out, &err);
}

/* The render at the plain base (defaults, small map), once per technique
 * and lab: most parameters are tried from it. */
typedef struct BaseRender {
    const Technique *t;
    Lab *lab;
    bool ok;
    RenderResult r;
} BaseRender;
#define EFFECT_MAX_BASES 128
static BaseRender bases[EFFECT_MAX_BASES];
static int num_bases;

static const RenderResult *base_render(Lab *lab, const Technique *t, const double *v)
{
    for (int i = 0; i < num_bases; i++)
        if (bases[i].t == t && bases[i].lab == lab) return bases[i].ok ? &bases[i].r : NULL;
    if (num_bases == EFFECT_MAX_BASES) return NULL;
    BaseRender *b = &bases[num_bases++];
    *b = (BaseRender){.t = t, .lab = lab};
    b->ok = render(lab, t, v, &b->r);
    return b->ok ? &b->r : NULL;
}

static void free_bases(void)
{
    for (int i = 0; i < num_bases; i++)
        if (bases[i].ok) render_result_free(&bases[i].r);
    num_bases = 0;
}

/* Do two values of parameter k that render give different outputs on this
 * lab? With `enable` false, only values under which k's condition fails. */
static bool acts_on(Lab *lab, const Technique *t, int k, bool enable, const char *settings)
{
    double base[TECH_MAX_PARAMS], plain[TECH_MAX_PARAMS], values[EFFECT_MAX_TRIES + 1];
    if (!base_values(t, k, enable, settings, base)) return false;
    tech_params_default(t, plain);
    if (smap_has_map_params(t)) plain[SMAP_P_MAP_SIZE] = EFFECT_MAP_SIZE;
    bool is_plain = memcmp(base, plain, sizeof(double) * (size_t)t->num_params) == 0;
    int n = try_values(&t->params[k], base[k], values);
    RenderResult own;
    const RenderResult *first = NULL;
    bool differs = false;
    for (int i = 0; i < n && !differs; i++) {
        double v[TECH_MAX_PARAMS];
        memcpy(v, base, sizeof v);
        v[k] = values[i];
        if (!enable && tech_param_acts(t, k, v)) continue; /* a value that meets its own condition (split_scheme=faces) */
        if (!first && i == 0 && is_plain) {
            first = base_render(lab, t, v);
            continue;
        }
        RenderResult r;
        if (!render(lab, t, v, first ? &r : &own)) continue; /* a value the technique refuses */
        if (!first) {
            first = &own;
            continue;
        }
        differs = !same_output(first, &r);
        render_result_free(&r);
    }
    if (first == &own) render_result_free(&own);
    return differs;
}

/* Does parameter k act on this lab, at the base or under one of its probes? */
static bool acts_probed(Lab *lab, const Technique *t, int k)
{
    if (acts_on(lab, t, k, true, NULL)) return true;
    for (size_t i = 0; i < sizeof probes / sizeof probes[0]; i++)
        if (strcmp(probes[i].param, t->params[k].name) == 0 && acts_on(lab, t, k, true, probes[i].settings)) return true;
    return false;
}

TEST(test_param_effect_every_parameter_changes_an_output)
{
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Lab *labs[EFFECT_NUM_SCENES];
    for (int i = 0; i < EFFECT_NUM_SCENES; i++) {
        labs[i] = filtered_open(effect_scenes[i], EFFECT_W, EFFECT_H);
        if (!labs[i]) {
            for (int j = 0; j < i; j++) lab_close(labs[j]);
            omp_set_num_threads(threads);
            CHECK_MSG(false, "cannot open %s", effect_scenes[i]);
        }
    }
    int idle = 0, checked = 0;
    for (int ti = 0; ti < tech_count(); ti++) {
        const Technique *t = tech_at(ti);
        for (int k = 0; k < t->num_params; k++) {
            if (!tech_param_offered(t, k)) continue; /* not the technique's (registry.h) */
            bool acts = false;
            for (int s = 0; s < EFFECT_NUM_SCENES && !acts; s++) {
                const Light *light = &lab_scene(labs[s])->lights[0];
                if (!(t->lights & LIGHT_BIT(light->kind))) continue;
                acts = acts_probed(labs[s], t, k);
            }
            checked++;
            if (!acts) {
                const char *when = tech_param_when(t, k);
                idle++;
                printf("    no effect: %s.%s%s%s\n", t->name, t->params[k].name, when ? " when " : "", when ? when : "");
            }
        }
    }
    free_bases();
    for (int i = 0; i < EFFECT_NUM_SCENES; i++) lab_close(labs[i]);
    omp_set_num_threads(threads);
    printf("    %d parameters of %d techniques checked\n", checked, tech_count());
    CHECK_MSG(idle == 0, "%d of %d parameters changed no output on any scene", idle, checked);
}

/* A setting "name=value" of one other parameter under which parameter k's
 * condition fails (pcss's sampling=exhaustive for blocker_taps); false if
 * no single change does. */
static bool disabling_setting(const Technique *t, int k, const double *base, char *out, size_t n)
{
    for (int j = 0; j < t->num_params; j++) {
        const ParamDesc *p = &t->params[j];
        double tries[EFFECT_MAX_TRIES + 1];
        int m = j == k ? 0 : try_values(p, base[j], tries);
        for (int i = 1; i < m; i++) {
            double v[TECH_MAX_PARAMS];
            memcpy(v, base, sizeof v);
            v[j] = tries[i];
            if (tech_param_acts(t, k, v)) continue;
            char text[64];
            tech_param_format(p, tries[i], text, sizeof text);
            snprintf(out, n, "%s=%s", p->name, text);
            return true;
        }
    }
    return false;
}

/* The converse, which the configuration key relies on: where its condition
 * does not hold (at the defaults, or one change away from them), a
 * parameter changes no output on any of the scenes, so a condition is never
 * narrower than where it acts. */
TEST(test_param_effect_outside_its_condition_a_parameter_changes_nothing)
{
    int threads = omp_get_max_threads(), wrong = 0, checked = 0;
    omp_set_num_threads(1);
    for (int s = 0; s < EFFECT_NUM_SCENES; s++) {
        Lab *lab = filtered_open(effect_scenes[s], EFFECT_W, EFFECT_H);
        for (int ti = 0; lab && ti < tech_count(); ti++) {
            const Technique *t = tech_at(ti);
            if (!(t->lights & LIGHT_BIT(lab_scene(lab)->lights[0].kind))) continue;
            double v[TECH_MAX_PARAMS];
            base_values(t, 0, false, NULL, v);
            for (int k = 0; k < t->num_params; k++) {
                char setting[128] = "";
                if (!tech_param_offered(t, k) || !tech_param_when(t, k)) continue;
                if (tech_param_acts(t, k, v) && !disabling_setting(t, k, v, setting, sizeof setting)) continue;
                checked++;
                if (acts_on(lab, t, k, false, setting[0] ? setting : NULL)) {
                    wrong++;
                    printf("    acts outside its condition: %s.%s (when %s; %s) on %s\n", t->name, t->params[k].name,
                           tech_param_when(t, k), setting[0] ? setting : "defaults", effect_scenes[s]);
                }
            }
        }
        free_bases();
        if (lab) lab_close(lab);
    }
    omp_set_num_threads(threads);
    printf("    %d (technique, parameter, scene) triples outside their condition checked\n", checked);
    CHECK_MSG(wrong == 0, "%d parameters change outputs where their condition says they do not act", wrong);
}

/* The configuration key leaves out a parameter whose condition does not
 * hold (sweeps record no duplicate rows) and keeps it where it does. */
TEST(test_param_effect_key_omits_parameters_that_do_not_act)
{
    Error err;
    Lab *lab = filtered_open("scenes/sphere-on-plane.lua", EFFECT_W, EFFECT_H);
    CHECK(lab);
    const Technique *t = tech_find("pcss", &err);
    double a[TECH_MAX_PARAMS], b[TECH_MAX_PARAMS];
    bool ok = filtered_params(t, "sampling=exhaustive blocker_taps=4", a) &&
              filtered_params(t, "sampling=exhaustive blocker_taps=64", b);
    bool same_exhaustive = ok && lab_config_key(lab, t, a, 0) == lab_config_key(lab, t, b, 0);
    ok = ok && filtered_params(t, "sampling=poisson blocker_taps=4", a) &&
         filtered_params(t, "sampling=poisson blocker_taps=64", b);
    bool differ_poisson = ok && lab_config_key(lab, t, a, 0) != lab_config_key(lab, t, b, 0);
    lab_close(lab);
    CHECK(ok);
    CHECK_MSG(same_exhaustive, "blocker_taps does not act with sampling=exhaustive, yet changes the key");
    CHECK_MSG(differ_poisson, "blocker_taps acts with sampling=poisson, yet leaves the key unchanged");
}
