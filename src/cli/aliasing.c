/* aliasing.c -- `shadowlab aliasing SCENE [-t TECH] [-p K=V]...`: the
 * sampling-error analysis (course §3.1; resources/analysis/aliasing.h) of the shadow
 * map a technique renders with -- any projection, warp, fit or cascades of
 * the shared map parameters -- over the view samples, and Lloyd's storage
 * factor over the view frustum; writes lab/aliasing_report.h's files and prints
 * the summary. */
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "core/progress.h"
#include "core/timer.h"
#include "lab/aliasing_report.h"
#include "techniques/smap.h"

#define AXIS_POINTS 64 /* view depths of the axis profile, log spaced over near..far */

static const CliAccept aliasing_options[] = {
    {OPT_TECHNIQUE, "a shadow-map technique whose map is analysed (default aliasing)"},
    {OPT_PARAM, "its parameters (repeatable): map_size, projection, fit, warp_n, cascades, ..."},
    {OPT_SET, NULL},
    {OPT_LIGHT, NULL},
    {OPT_FRUSTUM, "also Lloyd's storage factor over the view frustum (perspective aliasing only): N x N rays,\n"
                  "edges included, x N depths in B, ends included, map changes bisected, then a climb to each\n"
                  "map's maxima (default 24, 0: off)"},
    {OPT_THREADS, NULL},
    {OPT_OUT, NULL},
    {OPT_NO_PNG, "skip the PNGs"},
    {OPT_END, NULL}};

static const CliCommand aliasing_cmd = {
    "aliasing", "SCENE [options]", true, aliasing_options,
    "writes DIR/aliasing.{exr,png,json}, aliasing-cascade.png, aliasing-hist.csv, aliasing-depth.csv,\n"
    "aliasing-axis.csv: m = pixels per texel step along the map's axes (> 1: undersampled), its histogram,\n"
    "its profile along view depth, the projection factor cos(alpha)/cos(beta), the samples' total-aliasing\n"
    "storage (projection aliasing included), Lloyd et al. 2006's storage factor over the frustum, and along\n"
    "the view axis the catalogue's normalised e_x, e_y (course Fig. 3.7)\n"};

/* "name=value" of the map parameters that differ from the defaults. */
static void params_text(const Technique *t, const double *p, char *out, size_t n)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < SMAP_NUM_PARAMS && used < n; i++) {
        if (p[i] == t->params[i].def && i > SMAP_P_FIT) continue;
        char v[64];
        tech_param_format(&t->params[i], p[i], v, sizeof v);
        used += (size_t)snprintf(out + used, n - used, "%s%s=%s", used ? " " : "", t->params[i].name, v);
    }
}

typedef struct AliasingJob {
    CliOptions o;
    const Technique *tech;
    double params[TECH_MAX_PARAMS];
} AliasingJob;

static bool setup(AliasingJob *j, Error *err)
{
    j->tech = tech_find(j->o.technique ? j->o.technique : "aliasing", err);
    if (!j->tech) return false;
    if (!smap_has_map_params(j->tech))
        return error_set(err, "%s renders no shadow map with the shared map parameters; the analysis measures the "
                              "map of sm, pcf, aliasing and the other map techniques (see shadowlab list)",
                         j->tech->name);
    tech_params_default(j->tech, j->params);
    for (int i = 0; i < j->o.num_params; i++)
        if (!tech_param_parse(j->tech, j->o.params[i], j->params, err)) return false;
    return true;
}

static bool analyse(AliasingJob *j, Lab *lab, Error *err)
{
    const Scene *sc = lab_scene(lab);
    int light;
    if (!lab_light_index(lab, j->o.light, &light, err)) return false;
    if (!tech_check_light(j->tech, &sc->lights[light], j->o.light, err)) return false;
    ResourceManager *rm = lab_resources(lab);
    ShadowMapSpec spec = smap_spec(j->params);
    const ShadowMap *map = res_shadow_map(rm, sc, light, &spec, err);
    double t0 = timer_now_s();
    const AliasingMap *an = map ? res_aliasing(rm, sc, light, map, err) : NULL;
    if (!an) return false;
    AliasingSummary fr;
    Progress stage;
    int n = j->o.frustum;
    progress_begin(&stage, "frustum", 0);
    if (n > 0) aliasing_frustum(&map->view, sc, &sc->lights[light], n, n, n, &fr);
    progress_end(&stage);
    AliasingPoint axis[AXIS_POINTS];
    AliasingView av = aliasing_view(&sc->camera);
    for (int i = 0; i < AXIS_POINTS; i++) {
        double z = sc->camera.near_dist * pow(sc->camera.far_dist / sc->camera.near_dist, (double)i / (AXIS_POINTS - 1));
        z *= 1.0 + 1e-9 * (i == 0) - 1e-9 * (i == AXIS_POINTS - 1); /* a hair inside the ends */
        if (!aliasing_on_axis(&map->view, &av, &sc->lights[light], z, &axis[i])) axis[i] = (AliasingPoint){.face = -1};
        axis[i].depth = z;
    }
    char text[1024], dir[1024];
    params_text(j->tech, j->params, text, sizeof text);
    AliasingReport rep = {sc, j->tech->name, text, map, an, j->o.frustum > 0 ? &fr : NULL, axis, AXIS_POINTS,
                          timer_now_s() - t0};
    if (j->o.out_dir) snprintf(dir, sizeof dir, "%s", j->o.out_dir);
    else snprintf(dir, sizeof dir, "reports/%s", sc->name);
    progress_begin(&stage, "outputs", 0);
    bool written = aliasing_report_write(&rep, dir, "aliasing", !j->o.no_png, err);
    progress_end(&stage);
    if (!written) return false;
    progress_clear();
    aliasing_report_print(&rep, stdout);
    printf("outputs: %s/aliasing{.exr,.json,.png,-cascade.png,-hist.csv,-depth.csv,-axis.csv}\n", dir);
    return true;
}

int cmd_aliasing(int argc, char **argv)
{
    AliasingJob j;
    memset(&j, 0, sizeof j);
    Error err;
    if (!cli_parse(&aliasing_cmd, argc, argv, &j.o, &err) || (!j.o.help && !setup(&j, &err))) {
        fprintf(stderr, "shadowlab aliasing: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (j.o.help) {
        cli_print_help(&aliasing_cmd, stdout);
        return EXIT_OK;
    }
    cli_apply_threads(&j.o);
    progress_set_heartbeat(true); /* this process never forks */
    char label[PROGRESS_LABEL_MAX];
    snprintf(label, sizeof label, "aliasing %s", j.tech->name);
    Progress prog; /* "aliasing pcf > shadow_map, 1.2 s" on a terminal, after a second */
    progress_begin(&prog, label, 0);
    Lab *lab = lab_open(j.o.scene, j.o.overrides, j.o.num_overrides, &err);
    bool ok = lab && analyse(&j, lab, &err);
    progress_end(&prog);
    if (!ok) fprintf(stderr, "shadowlab aliasing: %s\n", err.msg);
    lab_close(lab);
    return ok ? EXIT_OK : EXIT_RUNTIME;
}
