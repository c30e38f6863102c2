/* aliasing_report.c -- files and printout of a sampling-error analysis
 * (aliasing_report.h). */
#include "lab/aliasing_report.h"
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "core/fsutil.h"
#include "core/json.h"
#include "io/exr.h"
#include "io/image_file.h"
#include "resources/standard.h"

#define NUM_FILES 7

void aliasing_color(double m, float rgb[3])
{
    static const double stops[][4] = {/* log10 m, r, g, b */
                                      {-1.0, 0.05, 0.15, 0.60}, {0.0, 0.10, 0.75, 0.15}, {1.0 / 3, 0.95, 0.90, 0.10},
                                      {2.0 / 3, 0.90, 0.10, 0.05}, {1.0, 0.35, 0.00, 0.00}};
    double t = log10(fmax(m, 1e-300));
    int k = 0;
    while (k < 3 && t > stops[k + 1][0]) k++;
    double a = fmin(fmax((t - stops[k][0]) / (stops[k + 1][0] - stops[k][0]), 0.0), 1.0);
    for (int c = 0; c < 3; c++) rgb[c] = (float)(stops[k][c + 1] + a * (stops[k + 1][c + 1] - stops[k][c + 1]));
}

/* Distinct colours for cascade indices 1.. (0: not measured, grey). */
static void cascade_color(int face, float rgb[3])
{
    static const float pal[8][3] = {{0.85f, 0.20f, 0.15f}, {0.20f, 0.65f, 0.25f}, {0.20f, 0.35f, 0.85f},
                                    {0.90f, 0.75f, 0.15f}, {0.65f, 0.25f, 0.75f}, {0.15f, 0.75f, 0.80f},
                                    {0.95f, 0.50f, 0.15f}, {0.55f, 0.55f, 0.55f}};
    if (face < 0) {
        rgb[0] = rgb[1] = rgb[2] = 0.25f;
        return;
    }
    float k = 1.0f - 0.35f * (float)((face / 8) % 2); /* past 8, the palette again, darker */
    for (int c = 0; c < 3; c++) rgb[c] = pal[face % 8][c] * k;
}

static bool write_exr(const AliasingReport *r, const char *path, Error *err)
{
    const AliasingMap *a = r->samples;
    size_t n = (size_t)a->width * a->height;
    float *buf = malloc(n * 4 * sizeof *buf);
    if (!buf) return error_set(err, "out of memory writing %s", path);
    for (size_t s = 0; s < n; s++) {
        bool ok = a->face[s] >= 0;
        buf[s] = ok ? fmaxf(a->m_s[s], a->m_t[s]) : NAN;
        buf[n + s] = ok ? fmaxf(a->m_s[s], a->m_t[s]) / fmaxf(a->proj[s], 1e-12f) : NAN;
        buf[2 * n + s] = (float)(a->face[s] + 1);
    }
    ExrChannel ch[] = {{"m", buf, 1}, {"m_s", a->m_s, 1}, {"m_t", a->m_t, 1}, {"proj", a->proj, 1},
                       {"persp", buf + n, 1}, {"cascade", buf + 2 * n, 1}};
    ExrAttr at[] = {{"shadowlab.technique", r->technique}, {"shadowlab.params", r->params_text},
                    {"shadowlab.scene", r->scene->name},
                    {"shadowlab.channels", "m = max(m_s, m_t): pixels per texel (> 1 undersampled); m_s, m_t per map "
                                           "axis; proj = cos(alpha)/cos(beta); persp = m / proj; cascade 1-based "
                                           "(0: not measured); NaN where not measured"}};
    bool ok = exr_write(path, a->width, a->height, ch, 6, at, 4, err);
    free(buf);
    return ok;
}

static bool write_pngs(const AliasingReport *r, const char *path_m, const char *path_c, Error *err)
{
    const AliasingMap *a = r->samples;
    Image im = {0}, ic = {0};
    if (!image_init(&im, a->width, a->height, 3, err) || !image_init(&ic, a->width, a->height, 3, err)) {
        image_free(&im);
        return false;
    }
    for (int s = 0; s < a->width * a->height; s++) {
        float *pm = im.data + (size_t)s * 3, *pc = ic.data + (size_t)s * 3;
        if (a->face[s] >= 0) aliasing_color(fmax(a->m_s[s], a->m_t[s]), pm);
        else pm[0] = pm[1] = pm[2] = 0.0f;
        cascade_color(a->face[s], pc);
    }
    bool ok = image_write_ldr(path_m, &im, false, err) && image_write_ldr(path_c, &ic, false, err);
    image_free(&im);
    image_free(&ic);
    return ok;
}

static bool write_hist(const AliasingSummary *s, const char *path, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    fprintf(af.fp, "m_lo,m_hi,count\n");
    for (int b = 0; b < ALIASING_HIST_BINS; b++)
        fprintf(af.fp, "%.6g,%.6g,%ld\n", b == 0 ? 0.0 : aliasing_hist_edge(b),
                b == ALIASING_HIST_BINS - 1 ? INFINITY : aliasing_hist_edge(b + 1), s->hist[b]);
    return atomic_commit(&af, err);
}

static bool write_depth(const AliasingSummary *s, const char *path, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    fprintf(af.fp, "z_lo,z_hi,count,m_s_mean,m_t_mean,m_s_max,m_t_max,persp_s_mean,persp_t_mean\n");
    double r = s->depth_hi / s->depth_lo;
    for (int k = 0; k < ALIASING_DEPTH_BINS; k++)
        fprintf(af.fp, "%.6g,%.6g,%ld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                s->depth_lo * pow(r, (double)k / ALIASING_DEPTH_BINS),
                s->depth_lo * pow(r, (double)(k + 1) / ALIASING_DEPTH_BINS), s->depth_count[k], s->depth_m_s[k],
                s->depth_m_t[k], s->depth_m_s_max[k], s->depth_m_t_max[k], s->depth_persp_s[k], s->depth_persp_t[k]);
    return atomic_commit(&af, err);
}

static bool write_axis(const AliasingReport *r, const char *path, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    AliasingView av = aliasing_view(&r->scene->camera);
    fprintf(af.fp, "z,cascade,m_s,m_t,e_x,e_y\n");
    for (int i = 0; i < r->num_axis; i++) {
        const AliasingPoint *p = &r->axis[i];
        double ex = NAN, ey = NAN;
        if (p->face >= 0) aliasing_normalised(&av, r->map->res, p, &ex, &ey);
        fprintf(af.fp, "%.6g,%d,%.6g,%.6g,%.6g,%.6g\n", p->depth, p->face + 1, p->face >= 0 ? p->m_s : NAN,
                p->face >= 0 ? p->m_t : NAN, ex, ey);
    }
    return atomic_commit(&af, err);
}

static void json_summary(JsonWriter *w, const char *key, const AliasingSummary *s)
{
    json_object_begin(w, key);
    json_int(w, "measured", s->measured);
    json_int(w, "undersampled", s->undersampled);
    json_number(w, "undersampled_share", s->measured ? (double)s->undersampled / s->measured : 0.0);
    json_int(w, "singular", s->singular);
    json_number(w, "m_max", s->m_max);
    json_number(w, "m_mean", s->m_mean);
    json_number(w, "m_s_max", s->m_s_max);
    json_number(w, "m_t_max", s->m_t_max);
    json_number(w, "m_s_mean", s->m_s_mean);
    json_number(w, "m_t_mean", s->m_t_mean);
    json_number(w, aliasing_storage_name(s), s->storage);
    json_array_begin(w, "faces");
    for (int f = 0; f < s->num_faces && f < LIGHTVIEW_MAX_FACES; f++) {
        json_object_begin(w, NULL);
        json_int(w, "measured", s->face_count[f]);
        json_number(w, "m_s_max", s->face_m_s_max[f]);
        json_number(w, "m_t_max", s->face_m_t_max[f]);
        json_object_end(w);
    }
    json_array_end(w);
    json_object_end(w);
}

static bool write_json(const AliasingReport *r, const char *path, Error *err)
{
    AtomicFile af;
    if (!atomic_open(&af, path, err)) return false;
    JsonWriter w;
    json_init(&w, af.fp);
    json_object_begin(&w, NULL);
    json_string(&w, "scene", r->scene->name);
    json_string(&w, "technique", r->technique);
    json_string(&w, "params", r->params_text);
    json_int(&w, "map_size", r->map->res);
    json_int(&w, "faces", r->map->num_faces);
    json_string(&w, "projection", map_projection_name(r->map->view.projection));
    json_array_begin(&w, "splits");
    for (int i = 0; r->map->view.num_cascades > 1 && i <= r->map->view.num_cascades; i++)
        json_number(&w, NULL, r->map->view.split[i]);
    json_array_end(&w);
    json_int(&w, "screen_width", r->scene->camera.width);
    json_int(&w, "screen_height", r->scene->camera.height);
    json_number(&w, "seconds", r->seconds);
    json_summary(&w, "samples", &r->samples->sum);
    if (r->frustum) json_summary(&w, "frustum", r->frustum);
    json_object_end(&w);
    json_finish(&w);
    return atomic_commit(&af, err);
}

bool aliasing_report_write(const AliasingReport *r, const char *dir, const char *stem, bool png, Error *err)
{
    if (!mkdir_p(dir, err)) return false;
    static const char *const suffix[NUM_FILES] = {".exr",       ".png",     "-cascade.png", "-hist.csv",
                                                  "-depth.csv", "-axis.csv", ".json"};
    char path[NUM_FILES][1200];
    for (int k = 0; k < NUM_FILES; k++) snprintf(path[k], sizeof path[k], "%s/%s%s", dir, stem, suffix[k]);
    const AliasingSummary *s = &r->samples->sum;
    bool ok = write_exr(r, path[0], err) && (!png || write_pngs(r, path[1], path[2], err)) &&
              write_hist(s, path[3], err) && write_depth(s, path[4], err) && write_axis(r, path[5], err) &&
              write_json(r, path[6], err);
    if (!ok)
        for (int k = 0; k < NUM_FILES; k++) unlink(path[k]);
    return ok;
}

static void print_summary(FILE *fp, const char *what, const AliasingSummary *s)
{
    fprintf(fp, "%-9s %8ld measured, %5.1f%% undersampled (m > 1), %ld edge-on to the light; m max %.4g mean %.4g; "
                "m_s max %.4g mean %.4g; m_t max %.4g mean %.4g; %s %.4g\n",
            what, s->measured, s->measured ? 100.0 * s->undersampled / s->measured : 0.0, s->singular, s->m_max,
            s->m_mean, s->m_s_max, s->m_s_mean, s->m_t_max, s->m_t_mean,
            s->perspective_only ? "storage factor" : "total-aliasing storage", s->storage);
}

void aliasing_report_print(const AliasingReport *r, FILE *fp)
{
    fprintf(fp, "%s on %s: %d^2 x%d %s map (%s)\n", r->technique, r->scene->name, r->map->res, r->map->num_faces,
            map_projection_name(r->map->view.projection), r->params_text);
    print_summary(fp, "samples", &r->samples->sum);
    if (r->frustum) print_summary(fp, "frustum", r->frustum);
}
