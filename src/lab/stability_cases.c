/* stability_cases.c -- the extreme cases of issue 7 as data: each one a scene
 * derived from a small base (a plane, a box and a ball under one light), the
 * light kinds it runs with, and its documented limit or expected refusal.
 * Scenes are Lua text so that every row can be reproduced with
 * `shadowlab compare` on the file the suite keeps (stability -o DIR). */
#include "lab/stability_cases.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "techniques/registry.h"

#define DEG (M_PI / 180.0)

static void set3(double *d, double x, double y, double z)
{
    d[0] = x;
    d[1] = y;
    d[2] = z;
}

void stab_objects_add(SceneSpec *s, const char *fmt, ...)
{
    size_t used = strlen(s->objects);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->objects + used, sizeof s->objects - used, fmt, ap);
    va_end(ap);
}

StabFile *stab_file_add(SceneSpec *s, const char *name)
{
    StabFile *f = &s->files[s->num_files++];
    memset(f, 0, sizeof *f);
    snprintf(f->name, sizeof f->name, "%s", name);
    return f;
}

static void file_printf(StabFile *f, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void file_printf(StabFile *f, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(f->data + f->size, sizeof f->data - f->size, fmt, ap);
    va_end(ap);
    if (k > 0) f->size = f->size + (size_t)k < sizeof f->data ? f->size + (size_t)k : sizeof f->data - 1;
}

static void file_bytes(StabFile *f, const void *p, size_t n)
{
    if (f->size + n > sizeof f->data) return;
    memcpy(f->data + f->size, p, n);
    f->size += n;
}

/* ---- the base scene ------------------------------------------------------ */

void stab_base_scene(SceneSpec *s, const StabSettings *st)
{
    memset(s, 0, sizeof *s);
    set3(s->cam_pos, 0, 3, 4);
    set3(s->cam_target, 0, 0.4, 0);
    set3(s->cam_up, 0, 1, 0);
    s->fov_deg = 45;
    s->near_d = 0.05;
    s->far_d = 50;
    s->width = st->width;
    s->height = st->height;
    set3(s->light_pos, 0.7, 4, 0.5); /* in no plane of the box's faces */
    set3(s->light_aim, 0, 0, 0);
    s->light_size = 0.3;
    stab_objects_add(s,
                     "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
                     "    { name = 'box', shape = 'box', size = {0.8, 0.8, 0.8}, translate = {0, 1, 0} },\n"
                     "    { name = 'ball', shape = 'sphere', radius = 0.3, segments = 24, translate = {1.1, 0.5, 0.6} },\n");
}

static void base_objects(SceneSpec *s, const char *text)
{
    s->objects[0] = '\0';
    stab_objects_add(s, "%s", text);
}

/* Text appended to a bounded buffer; numbers exactly (%.17g), NaN and
 * infinities as the Lua expressions 0/0 and 1/0. */
typedef struct Text { char *buf; size_t n, used; } Text;

static void tx(Text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void tx(Text *t, const char *fmt, ...)
{
    if (t->used >= t->n) return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(t->buf + t->used, t->n - t->used, fmt, ap);
    va_end(ap);
    t->used = k < 0 ? t->n : t->used + (size_t)k;
}

static void tx_num(Text *t, double v)
{
    if (isnan(v)) tx(t, "(0/0)");
    else if (isinf(v)) tx(t, v > 0 ? "(1/0)" : "(-1/0)");
    else tx(t, "%.17g", v);
}

static void tx_vec(Text *t, const double *v)
{
    tx(t, "{");
    for (int i = 0; i < 3; i++) {
        tx_num(t, v[i]);
        tx(t, i < 2 ? ", " : "}");
    }
}

static void tx_key_num(Text *t, const char *key, double v)
{
    tx(t, ", %s = ", key);
    tx_num(t, v);
}

static void tx_key_vec(Text *t, const char *key, const double *v)
{
    tx(t, ", %s = ", key);
    tx_vec(t, v);
}

static void light_text(const SceneSpec *s, LightKind k, Text *t)
{
    double d[3] = {s->light_aim[0] - s->light_pos[0], s->light_aim[1] - s->light_pos[1],
                   s->light_aim[2] - s->light_pos[2]};
    tx(t, "{ type = '%s'", light_kind_name(k));
    if (k != LIGHT_DIRECTIONAL) tx_key_vec(t, "position", s->light_pos);
    if (k != LIGHT_POINT && k != LIGHT_SPHERE) tx_key_vec(t, "direction", d);
    if (k == LIGHT_SPOT) tx(t, ", cone_angle = 60");
    if (k == LIGHT_SPHERE || k == LIGHT_DISK) tx_key_num(t, "radius", s->light_size);
    if (k == LIGHT_RECT || k == LIGHT_TEXTURED_RECT) {
        tx_key_num(t, "width", 2 * s->light_size);
        tx_key_num(t, "height", 2 * s->light_size);
    }
    if (k == LIGHT_TEXTURED_RECT) tx(t, ", image = 'stab-light.exr'");
    tx(t, " }");
}

bool stab_scene_text(const SceneSpec *s, LightKind kind, char *out, size_t n)
{
    Text t = {out, n, 0};
    tx(&t, "-- written by shadowlab stability; reproduce with: shadowlab compare THIS_FILE -t TECH\n"
           "return {\n  camera = { position = ");
    tx_vec(&t, s->cam_pos);
    tx_key_vec(&t, "target", s->cam_target);
    tx_key_vec(&t, "up", s->cam_up);
    tx(&t, ",\n            ");
    tx(&t, "fov = ");
    tx_num(&t, s->fov_deg);
    tx_key_num(&t, "near", s->near_d);
    tx_key_num(&t, "far", s->far_d);
    tx(&t, ", width = %d, height = %d },\n  lights = { ", s->width, s->height);
    if (s->light_extra[0]) tx(&t, "%s", s->light_extra);
    else light_text(s, kind, &t);
    tx(&t, " },\n  objects = {\n%s  },\n}\n", s->objects);
    return t.used < n;
}

/* ---- limits ---------------------------------------------------------------- */

void stab_quantity_names(unsigned q, char *out, size_t n)
{
    static const char *const names[STAB_Q_COUNT] = {"band RMSE", "band misclassified", "misclassified",
                                                    "umbra count", "umbra leak", "umbra lit", "back-facing count",
                                                    "geometry count", "terminator count"};
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < STAB_Q_COUNT && used < n; i++)
        if (q & (1u << i)) used += (size_t)snprintf(out + used, n - used, "%s%s", used ? " and " : "", names[i]);
}

/* Light size 1e-6: the reference equals `hard` there (unit test
 * test_reference_point_limit), so a soft technique must agree with the
 * point-light shadow where the shadow is: over the hard shadow's band
 * (StabMeasure) RMSE <= HARD_BAND_RMSE and at most HARD_BAND_MISCLASSIFIED
 * of its samples misclassified, and at most HARD_MISCLASSIFIED of all lit
 * candidates (a shadow drawn where neither has one). Over every lit
 * candidate instead (MAE), a fixed penumbra passed (issue 13: shadow_width,
 * MAE 0.0137 with RMSE 0.107). Measured at writing (128 x 96, default maps):
 * sm's own aliasing (1024 texels, nearest texel) band RMSE 0.183, 3.3%
 * misclassified; every soft technique at most 0.148 and 2.0%; shadow_width
 * 0.265 and 10.3%. */
#define HARD_BAND_RMSE 0.2
#define HARD_BAND_MISCLASSIFIED 0.05
#define HARD_MISCLASSIFIED 0.02

static unsigned limit_hard(const StabMeasure *m, char *why, size_t n)
{
    const ErrorStats *b = &m->band.region[REGION_ALL], *all = &m->all.region[REGION_ALL];
    snprintf(why, n, "over the hard shadow's band of %ld samples RMSE %.4f (limit %.2f), %.2f%% misclassified (limit %.0f%%); "
             "%.2f%% of all lit samples misclassified (limit %.0f%%)",
             b->count, b->rmse, HARD_BAND_RMSE, 100 * b->misclassified, 100 * HARD_BAND_MISCLASSIFIED,
             100 * all->misclassified, 100 * HARD_MISCLASSIFIED);
    return (b->rmse > HARD_BAND_RMSE ? STAB_Q_BAND_RMSE : 0) |
           (b->misclassified > HARD_BAND_MISCLASSIFIED ? STAB_Q_BAND_MISCLASSIFIED : 0) |
           (all->misclassified > HARD_MISCLASSIFIED ? STAB_Q_MISCLASSIFIED : 0);
}

/* Light below the receiver plane: the ground is unlit by shading (back-facing),
 * never a shadow to estimate; only the objects' sides may face the light. */
static unsigned limit_no_ground_candidates(const StabMeasure *m, char *why, size_t n)
{
    if (m->all.class_count[SAMPLE_BACKFACING] > 0) return 0;
    snprintf(why, n, "no back-facing samples: the ground under a light below it was not classified unlit");
    return STAB_Q_BACKFACING;
}

/* Light cut by the ground's plane: the ground sees part of it, so its
 * samples are scored as terminator (light.h's convention), never as
 * penumbra of the light's part below the plane. */
static unsigned limit_terminator_present(const StabMeasure *m, char *why, size_t n)
{
    if (m->all.region[REGION_TERMINATOR].count > 0) return 0;
    snprintf(why, n, "no terminator samples: the ground before a light its plane cuts was not flagged");
    return STAB_Q_TERMINATOR;
}

/* Light inside the closed box: every lit candidate (the ground, the ball;
 * the ball's band whose plane cuts the light is scored as terminator)
 * is in the reference's umbra, and the technique must say so: mean light
 * leaked over them at most UMBRA_LEAK_MAX, at most UMBRA_LIT_MAX of them
 * estimated lit (> 0.5). */
#define UMBRA_LEAK_MAX 0.02
#define UMBRA_LIT_MAX 0.01

static unsigned limit_all_umbra(const StabMeasure *m, char *why, size_t n)
{
    const ErrorStats *all = &m->all.region[REGION_ALL], *umbra = &m->all.region[REGION_UMBRA];
    long terminator = m->all.region[REGION_TERMINATOR].count; /* the ball's band whose plane cuts the light */
    if (all->count == 0 || umbra->count + terminator != all->count) {
        snprintf(why, n, "the reference has %ld of %ld lit candidates in umbra (%ld terminator): the light is not enclosed",
                 umbra->count, all->count, terminator);
        return STAB_Q_UMBRA_COUNT;
    }
    double lit = all->misclassified; /* the reference is 0 throughout: |e| > 0.5 is an estimate > 0.5 */
    snprintf(why, n, "light leaks out of the closed box: mean leak %.4f (limit %.2f), %.2f%% of umbra samples lit (limit %.0f%%)",
             all->leak_mean, UMBRA_LEAK_MAX, 100 * lit, 100 * UMBRA_LIT_MAX);
    return (all->leak_mean > UMBRA_LEAK_MAX ? STAB_Q_UMBRA_LEAK : 0) | (lit > UMBRA_LIT_MAX ? STAB_Q_UMBRA_LIT : 0);
}

/* No geometry in view: nothing is estimated and nothing may fail. */
static unsigned limit_all_background(const StabMeasure *m, char *why, size_t n)
{
    long non_bg = 0;
    for (int c = 1; c < SAMPLE_CLASS_COUNT; c++) non_bg += m->all.class_count[c];
    if (non_bg == 0) return 0;
    snprintf(why, n, "%ld samples hit geometry in a view of the empty sky", non_bg);
    return STAB_Q_GEOMETRY;
}

/* Why techniques miss a limit: each entry names its technique, light kinds
 * and the quantities it misses, with its source's reason; the figures at
 * writing (full sizes) are in the comments, the row's note has them as run. */
#define ONE_SIDED (LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK) | LIGHT_BIT(LIGHT_TEXTURED_RECT))
#define UMBRA_MISSED (STAB_Q_UMBRA_LEAK | STAB_Q_UMBRA_LIT)
#define ONE_SIDED_MAP                                                                                                \
    "a one-sided area light's map is one perspective face (course §2.1): receivers in its hemisphere outside that " \
    "frustum are outside the map, taken as lit"

/* Seed 003 §1 and §3 disregard the light's size and shape: one light sample,
 * and c_scale alone "adjusts the softness" (its default models one light),
 * so the penumbra does not shrink with the light. Measured: band RMSE 0.265,
 * 10.3% of the band misclassified (sphere; 0.261, 10.7% rect, disk,
 * textured_rect); 1.7% of all lit samples. */
static const KnownLimit tiny_light_known[] = {
    {"shadow_width", LIGHTS_AREA, STAB_Q_BAND_RMSE | STAB_Q_BAND_MISCLASSIFIED,
     "seed 003 §1, §3: one light sample, the light's size disregarded; c_scale alone sets the penumbra's width, "
     "so it stays that of the light its default models"},
    /* Measured (sphere, epsilon 0.1): band RMSE 0.220, 133 false shadows of 8435 samples; 0.076, 46 at 0.2. */
    {"layered_attenuation", LIGHT_BIT(LIGHT_SPHERE), STAB_Q_BAND_RMSE,
     "course §5.2.4 [OWN], Agrawala et al. 2000's tolerance: epsilon is stiff; the box's faces grazing to the "
     "light change depth by more than epsilon across an LDI texel, so their warped depths split into layers of "
     "partial counts and a receiver matches one of them (acne on those faces)"},
    {NULL, 0, 0, NULL},
};

/* Measured: shadow_width 0.075 and 8.1% (point, sphere); under one-sided
 * lights every map technique 0.216-0.228 and 21.6-22.5% lit (accumulation
 * 0.217, 21.7%: its footprint grid meets the limit under a sphere light,
 * mean leak 0.0006, where the lexel grid had leaked 0.99). */
static const KnownLimit inside_occluder_known[] = {
    {"accumulation", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"shadow_width", LIGHT_BIT(LIGHT_POINT) | LIGHT_BIT(LIGHT_SPHERE), UMBRA_MISSED, /* a spot's cone keeps widths small: it meets the limit */
     "seed 003 §3: I = 1 + c_bias - c_scale sw / sd darkens only where the width (capped at 1 / start_difference "
     "texels) is large against the shadow depth; receivers far behind an enclosing wall are only attenuated"},
    {"sm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"pcf", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"vsm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"lvsm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"evsm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"msm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"esm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"csm", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"brabec", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"pcss", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"adaptive_area", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_TEXTURED_RECT), UMBRA_MISSED, ONE_SIDED_MAP},
    {"shadow_width", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    {"aliasing", ONE_SIDED, UMBRA_MISSED, ONE_SIDED_MAP},
    /* backprojection 0.218 / 0.217 (rect / disk; sphere 0.0006); occlusion_textures (6 slices) 0.361 / 0.335, sphere 0.021 */
    {"backprojection", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    /* hsm 0.218 / 0.217, mssm and ysm 0.217 / 0.217 (rect / disk; sphere 0.0006 each): backprojection's map */
    {"hsm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"mssm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"ysm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"occlusion_textures", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"occlusion_textures", LIGHT_BIT(LIGHT_SPHERE), STAB_Q_UMBRA_LEAK,
     "course §5.2.5: the slices' box-filtered values are multiplied, not united; walls whose depths spread over "
     "several slices each cover part of every kernel, so the product stays above 0 (no umbra sample lit)"},
    {"pcss_prefiltered", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"cssm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"evssm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"vssm", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {"dpcf", LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK), UMBRA_MISSED, ONE_SIDED_MAP},
    {NULL, 0, 0, NULL},
};

const KnownLimit *stab_known_limit(const StabCase *c, const Technique *t, LightKind kind)
{
    for (const KnownLimit *k = c->known; t && k && k->reason; k++)
        if (k->technique && strcmp(k->technique, t->name) == 0 && (k->lights & LIGHT_BIT(kind))) return k;
    return NULL;
}

/* ---- light cases ------------------------------------------------------------ */

static void light_tiny(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->light_size = 1e-6;
}

static void light_huge(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->light_size = 100; /* the scene's extent is about 8.6: a sphere light this big contains it */
}

/* The box's top face is at y = 1.4: the light's centre on it (a sphere light
 * rests on it), area lights half inside the box. */
static void light_touching(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)st;
    set3(s->light_pos, 0, k == LIGHT_SPHERE ? 1.4 + s->light_size : 1.4, 0);
    set3(s->light_aim, 0.5, 0, 0.5);
}

static void light_inside_occluder(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->light_pos, 0, 1, 0);
    set3(s->light_aim, 0.3, 0, 0.2);
    s->light_size = 0.1;
}

/* Beside the box, below its top: inside the scene's bounding box. */
static void light_inside_bounds(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->light_pos, 1.6, 0.6, -0.2);
    set3(s->light_aim, -1, 0, 0);
    s->light_size = 0.1;
}

static void light_below(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->light_pos, 0.6, -2, 0.4);
    set3(s->light_aim, 0, 0, 0);
}

/* Centre 0.1 below the ground, a third of the light's size: the plane
 * y = 0 cuts it; an area light tilted up toward the box and the ball. */
static void light_straddling(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->light_pos, -1.6, -0.1, -0.6);
    set3(s->light_aim, 0, 0.4, 0);
}

/* 89.9 degrees from the ground's normal, 20 units from the centre. */
static void light_grazing(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    double th = 89.9 * DEG;
    set3(s->light_pos, 20 * sin(th), 20 * cos(th), 0);
    set3(s->light_aim, 0, 0, 0);
}

/* Camera from (0, 3, 4) to the origin: the view direction is (0, -3, -4)
 * exactly, in floats as in decimals. */
static void view_axis_camera(SceneSpec *s)
{
    set3(s->cam_pos, 0, 3, 4);
    set3(s->cam_target, 0, 0, 0);
}

static void light_along_view(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    view_axis_camera(s);
    set3(s->light_pos, 0, 3, 4);
    set3(s->light_aim, 0, 0, 0);
}

static void light_against_view(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    view_axis_camera(s);
    set3(s->light_pos, 0, 0, 0);
    set3(s->light_aim, 0, 3, 4);
}

/* Straight down: a light-space "look at" with up = +Y degenerates. */
static void light_straight_down(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->light_pos, 0, 4, 0);
    set3(s->light_aim, 0, 0, 0);
}

/* ---- geometry cases --------------------------------------------------------- */

static void geo_contact(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    base_objects(s, "    { name = 'ground', shape = 'plane', size = {6, 6} },\n"
                    "    { name = 'box', shape = 'box', size = {0.8, 0.8, 0.8}, translate = {0, 0.4, 0} },\n"
                    "    { name = 'ball', shape = 'sphere', radius = 0.3, segments = 24, translate = {1.1, 0.3, 0.6} },\n");
}

static void geo_coplanar(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    stab_objects_add(s, "    { name = 'decal', shape = 'disk', radius = 0.7, segments = 32, translate = {-0.8, 0, 0.5} },\n");
}

static void mesh_object(SceneSpec *s, const char *file, const char *extra)
{
    stab_objects_add(s, "    { name = 'mesh', shape = 'mesh', model = '%s'%s },\n", file, extra);
}

static void geo_zero_area(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "zero-area.obj");
    file_printf(f, "# a quad occluder, then triangles of zero area: collinear, one vertex thrice, two coincident\n"
                   "v -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\nv 0.5 1.5 0.5\nv -0.5 1.5 0.5\n"
                   "v -1 1.8 0\nv 0 1.8 0\nv 1 1.8 0\n"
                   "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 6\nf 1 1 1\nf 2 2 3\nf 6 6 6\n");
    mesh_object(s, "zero-area.obj", "");
}

/* A fan of triangles 2 long and 1e-6 wide, lying and standing. */
static void geo_needles(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "needles.obj");
    for (int i = 0; i < 16; i++) {
        double z = -0.8 + 0.1 * i;
        bool standing = i % 2;
        file_printf(f, "v -1 1.6 %.9g\nv 1 1.6 %.9g\nv 1 %.9g %.9g\nf %d %d %d\n", z, z, standing ? 1.600001 : 1.6,
                    standing ? z : z + 1e-6, 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    mesh_object(s, "needles.obj", "");
}

/* The six faces of a 0.8 box centred at (0, 1.5, 0), as quads of their own
 * four vertices; `skip` is a bit set of faces left out. */
static void box_faces(StabFile *f, unsigned skip, int copies, bool reversed_copy)
{
    static const int axis[6] = {0, 0, 1, 1, 2, 2};
    int base = 0;
    for (int c = 0; c < copies; c++) {
        for (int face = 0; face < 6; face++) {
            if (skip & (1u << face)) continue;
            int a = axis[face], u = (a + 1) % 3, v = (a + 2) % 3;
            double sign = face % 2 ? -0.4 : 0.4;
            static const double corner[4][2] = {{-0.4, -0.4}, {0.4, -0.4}, {0.4, 0.4}, {-0.4, 0.4}};
            for (int q = 0; q < 4; q++) {
                double p[3];
                p[a] = sign;
                p[u] = corner[q][0];
                p[v] = corner[q][1];
                file_printf(f, "v %.9g %.9g %.9g\n", p[0], p[1] + 1.5, p[2]);
            }
            int i = base + 1;
            file_printf(f, "f %d %d %d\nf %d %d %d\n", i, i + 1, i + 2, i, i + 2, i + 3);
            if (reversed_copy) file_printf(f, "f %d %d %d\n", i, i + 2, i + 1);
            base += 4;
        }
    }
}

static void geo_duplicated(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "duplicated.obj");
    file_printf(f, "# an unwelded box listed twice, with one reversed duplicate of every triangle\n");
    box_faces(f, 0, 2, true);
    mesh_object(s, "duplicated.obj", "");
}

static void geo_holes(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "open-box.obj");
    file_printf(f, "# a box without its +y (top) and +x faces\n");
    box_faces(f, (1u << 0) | (1u << 2), 1, false);
    mesh_object(s, "open-box.obj", "");
}

static void geo_single_triangle(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "triangle.obj");
    file_printf(f, "v -2 0 -2\nv 2 0 -2\nv 0 0 2\nf 1 3 2\n");
    base_objects(s, "");
    mesh_object(s, "triangle.obj", "");
}

/* 708 x 708 cells of two triangles: 1,002,528 triangles of bumps. */
static void geo_million(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    base_objects(s, "    { name = 'bumps', shape = 'heightfield', size = {6, 6}, resolution = {708, 708},\n"
                    "      elevation = function(x, z) return 0.15 * math.sin(3 * x) * math.cos(3 * z) end },\n"
                    "    { name = 'box', shape = 'box', size = {0.8, 0.8, 0.8}, translate = {0, 1, 0} },\n");
}

/* Everything moved to x = z = 1e6 (a float ulp there is 0.0625), with a box
 * of 1e-3 on the ground: detail far below the coordinates' resolution. */
static void geo_far_coordinates(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    const double o = 1e6;
    base_objects(s, "");
    stab_objects_add(s,
                     "    { name = 'ground', shape = 'plane', size = {6, 6}, translate = {%.17g, 0, %.17g} },\n"
                     "    { name = 'box', shape = 'box', size = {0.8, 0.8, 0.8}, translate = {%.17g, 1, %.17g} },\n"
                     "    { name = 'grain', shape = 'box', size = {0.001, 0.001, 0.001}, translate = {%.17g, 0.0005, %.17g} },\n",
                     o, o, o, o, o + 0.5, o + 0.5);
    set3(s->cam_pos, o, 3, o + 4);
    set3(s->cam_target, o, 0.4, o);
    set3(s->light_pos, o + 0.6, 4, o + 0.4);
    set3(s->light_aim, o, 0, o);
}

static void geo_background(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->cam_target, 0, 10, 10); /* 52 degrees up: nothing in view */
}

static void geo_camera_inside(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    set3(s->cam_pos, 0, 1, 0);
    set3(s->cam_target, 0.3, 0.8, 1);
    s->near_d = 0.01;
}

/* ---- camera cases ------------------------------------------------------------ */

static void cam_near_tiny(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->near_d = 1e-6;
}

static void cam_far_near(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->near_d = 1e-3;
    s->far_d = 1e3;
}

static void cam_fov_1(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->fov_deg = 1;
}

static void cam_fov_170(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->fov_deg = 170;
}

static void cam_1x1(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->width = s->height = 1;
}

static void cam_4096(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->width = s->height = 4096;
}

/* ---- input that must be refused before any computation ---------------------- */

static void bad_obj(SceneSpec *s, const char *vertex, const char *extra)
{
    StabFile *f = stab_file_add(s, "bad.obj");
    file_printf(f, "v 0 1 0\n%s\nv 0 1 1\nf 1 2 3\n", vertex);
    mesh_object(s, "bad.obj", extra);
}

static void in_nan_vertex_obj(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    bad_obj(s, "v 1 nan 0", "");
}

static void in_inf_vertex_obj(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    bad_obj(s, "v 1 inf 0", "");
}

static void in_inf_vertex_ply(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    StabFile *f = stab_file_add(s, "bad.ply");
    file_printf(f, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
    const float v[9] = {0, 1, 0, 1, INFINITY, 0, 0, 1, 1};
    const unsigned char three = 3;
    const int idx[3] = {0, 1, 2};
    file_bytes(f, v, sizeof v); /* little-endian hosts only, like the test data it mirrors */
    file_bytes(f, &three, 1);
    file_bytes(f, idx, sizeof idx);
    mesh_object(s, "bad.ply", "");
}

static void in_nan_translate(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    stab_objects_add(s, "    { shape = 'box', translate = {0/0, 1, 0} },\n");
}

static void in_nan_elevation(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    stab_objects_add(s, "    { shape = 'heightfield', size = {2, 2}, resolution = {4, 4},\n"
                        "      elevation = function(x, z) if x > 0 then return 0/0 end return 0 end },\n");
}

static void in_overflow_transform(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    bad_obj(s, "v 1e38 1 0", ", scale = 1e7");
}

static void in_light(SceneSpec *s, const char *light)
{
    snprintf(s->light_extra, sizeof s->light_extra, "%s", light);
}

static void in_nan_light_position(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    in_light(s, "{ type = 'point', position = {0, 0/0, 0} }");
}

static void in_inf_light_position(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    in_light(s, "{ type = 'sphere', position = {0, 1/0, 0}, radius = 0.2 }");
}

static void in_nan_light_radius(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    in_light(s, "{ type = 'sphere', position = {0, 4, 0}, radius = 0/0 }");
}

static void in_nan_light_direction(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    in_light(s, "{ type = 'directional', direction = {0/0, -1, 0} }");
}

static void light_image(SceneSpec *s, float texel)
{
    StabFile *f = stab_file_add(s, "bad-light.exr");
    f->exr = true;
    f->exr_texel = texel;
    in_light(s, "{ type = 'textured_rect', position = {0, 4, 0}, direction = {0, -1, 0}, width = 1, height = 1, "
                "image = 'bad-light.exr' }");
}

static void in_nan_light_image(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    light_image(s, NAN);
}

static void in_inf_light_image(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    light_image(s, INFINITY);
}

static void in_negative_light_image(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    light_image(s, -0.5f);
}

static void in_nan_camera(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    s->fov_deg = NAN;
}

/* Procedural geometry past the scene's triangle budget: refused, never an
 * allocation of many gigabytes. */
static void in_triangle_budget(SceneSpec *s, LightKind k, const StabSettings *st)
{
    (void)k; (void)st;
    for (int i = 0; i < 5; i++) stab_objects_add(s, "    { shape = 'sphere', segments = 2048 },\n");
}

/* ---- the table ---------------------------------------------------------------- */

#define AREA LIGHTS_AREA
#define POSITIONED (LIGHTS_ALL & ~LIGHT_BIT(LIGHT_DIRECTIONAL))
#define AIMED (LIGHT_BIT(LIGHT_SPOT) | LIGHT_BIT(LIGHT_DIRECTIONAL) | LIGHT_BIT(LIGHT_RECT) | LIGHT_BIT(LIGHT_DISK) | \
               LIGHT_BIT(LIGHT_TEXTURED_RECT))
#define DIRECTIONAL LIGHT_BIT(LIGHT_DIRECTIONAL)

static const StabCase cases[] = {
    {"light_size_1e-6", GROUP_LIGHT,
     "area light of size 1e-6: converges to the hard shadow where it is (band RMSE <= 0.2, <= 5% misclassified)",
     AREA, PLAN_EACH, false, false, true, light_tiny, limit_hard, {0}, tiny_light_known},
    {"light_larger_than_scene", GROUP_LIGHT, "area light of size 100 (a sphere light containing the whole scene)",
     AREA, PLAN_EACH, false, false, false, light_huge, NULL, {0}, NULL},
    {"light_touching_occluder", GROUP_LIGHT, "light centre on the box's top face (a sphere light resting on it)",
     POSITIONED, PLAN_EACH, false, false, false, light_touching, NULL, {0}, NULL},
    {"light_inside_occluder", GROUP_LIGHT,
     "light inside the closed box: the ground is in umbra (mean leak <= 0.02, <= 1% of it lit)",
     POSITIONED, PLAN_EACH, false, true, false, light_inside_occluder, limit_all_umbra, {0}, inside_occluder_known},
    {"light_inside_scene_bounds", GROUP_LIGHT, "light beside the box, inside the scene's bounding box",
     POSITIONED, PLAN_EACH, false, true, false, light_inside_bounds, NULL, {0}, NULL},
    {"light_below_receiver", GROUP_LIGHT, "light under the ground plane: the ground is back-facing, not shadowed",
     LIGHTS_ALL, PLAN_EACH, false, false, false, light_below, limit_no_ground_candidates, {0}, NULL},
    {"light_straddling_receiver", GROUP_LIGHT,
     "area light cut by the ground's plane (centre 0.1 below it): the ground is scored as terminator",
     AREA, PLAN_EACH, false, false, false, light_straddling, limit_terminator_present, {0}, NULL},
    {"light_grazing_89.9deg", GROUP_LIGHT, "light at 89.9 degrees from the ground's normal",
     LIGHTS_ALL, PLAN_EACH, false, false, false, light_grazing, NULL, {0}, NULL},
    {"light_straight_down", GROUP_LIGHT, "light aimed exactly along -Y (a light 'look at' with up = +Y degenerates)",
     AIMED, PLAN_EACH, false, false, false, light_straight_down, NULL, {0}, NULL},
    {"directional_along_view", GROUP_LIGHT, "directional light exactly parallel to the view direction",
     DIRECTIONAL, PLAN_EACH, false, false, false, light_along_view, NULL, {0}, NULL},
    {"directional_against_view", GROUP_LIGHT, "directional light exactly opposite to the view direction",
     DIRECTIONAL, PLAN_EACH, false, false, false, light_against_view, NULL, {0}, NULL},

    {"contact", GROUP_GEOMETRY, "box and ball resting on the ground (receiver touching the caster)",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_contact, NULL, {0}, NULL},
    {"coplanar_caster", GROUP_GEOMETRY, "a disk lying in the ground's plane, casting and receiving",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_coplanar, NULL, {0}, NULL},
    {"zero_area_triangles", GROUP_GEOMETRY, "collinear and coincident-vertex triangles in a mesh",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_zero_area, NULL, {0}, NULL},
    {"needle_triangles", GROUP_GEOMETRY, "triangles 2 long and 1e-6 wide",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_needles, NULL, {0}, NULL},
    /* may refuse: issue 14's open and non-manifold meshes, handled or refused naming the caster and its edge
     * counts (the wedge family): a refusal without the caster's name fails */
    {"duplicated_vertices", GROUP_GEOMETRY, "an unwelded box listed twice, with reversed duplicates of its triangles",
     LIGHTS_ALL, PLAN_TWO, false, true, false, geo_duplicated, NULL, {"caster '", " edges"}, NULL},
    {"mesh_with_holes", GROUP_GEOMETRY, "a box missing two faces",
     LIGHTS_ALL, PLAN_TWO, false, true, false, geo_holes, NULL, {"caster '", " edges"}, NULL},
    {"single_triangle", GROUP_GEOMETRY, "a scene of one triangle",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_single_triangle, NULL, {0}, NULL},
    {"triangles_1e6", GROUP_GEOMETRY, "1,002,528 triangles of self-shadowing bumps",
     LIGHTS_ALL, PLAN_ONE, true, false, false, geo_million, NULL, {0}, NULL},
    {"coordinates_near_1e6", GROUP_GEOMETRY, "the scene at x = z = 1e6 with a box of 1e-3 (below the float ulp 0.0625)",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_far_coordinates, NULL, {0}, NULL},
    {"every_pixel_background", GROUP_GEOMETRY, "camera looking at the empty sky",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_background, limit_all_background, {0}, NULL},
    {"camera_inside_object", GROUP_GEOMETRY, "camera inside the closed box",
     LIGHTS_ALL, PLAN_TWO, false, false, false, geo_camera_inside, NULL, {0}, NULL},

    {"near_1e-6", GROUP_CAMERA, "near plane at 1e-6", LIGHTS_ALL, PLAN_TWO, false, false, false, cam_near_tiny, NULL, {0}, NULL},
    {"far_over_near_1e6", GROUP_CAMERA, "near 1e-3, far 1e3", LIGHTS_ALL, PLAN_TWO, false, false, false, cam_far_near, NULL, {0}, NULL},
    {"fov_1deg", GROUP_CAMERA, "vertical field of view 1 degree", LIGHTS_ALL, PLAN_TWO, false, false, false, cam_fov_1, NULL, {0}, NULL},
    {"fov_170deg", GROUP_CAMERA, "vertical field of view 170 degrees", LIGHTS_ALL, PLAN_TWO, false, false, false, cam_fov_170, NULL, {0}, NULL},
    {"image_1x1", GROUP_CAMERA, "a 1 x 1 image", LIGHTS_ALL, PLAN_TWO, false, false, false, cam_1x1, NULL, {0}, NULL},
    {"image_4096x4096", GROUP_CAMERA, "a 4096 x 4096 image", LIGHTS_ALL, PLAN_ONE, true, false, false, cam_4096, NULL, {0}, NULL},

    {"nan_vertex_obj", GROUP_INPUT, "OBJ vertex 'nan': refused with file and line", 0, PLAN_NONE, false, false, false,
     in_nan_vertex_obj, NULL, {"bad.obj:2", "not finite"}, NULL},
    {"inf_vertex_obj", GROUP_INPUT, "OBJ vertex 'inf': refused with file and line", 0, PLAN_NONE, false, false, false,
     in_inf_vertex_obj, NULL, {"bad.obj:2", "not finite"}, NULL},
    {"inf_vertex_ply", GROUP_INPUT, "binary PLY vertex +Inf: refused with file and record", 0, PLAN_NONE, false, false, false,
     in_inf_vertex_ply, NULL, {"bad.ply", "not finite"}, NULL},
    {"vertex_overflows_after_transform", GROUP_INPUT, "vertex 1e38 scaled by 1e7: refused after its transform", 0,
     PLAN_NONE, false, false, false, in_overflow_transform, NULL, {"objects[4]", "not finite"}, NULL},
    {"nan_translate", GROUP_INPUT, "translate = {0/0, 1, 0}: refused with the key path", 0, PLAN_NONE, false, false, false,
     in_nan_translate, NULL, {"objects[4].translate[1]", "outside"}, NULL},
    {"nan_heightfield", GROUP_INPUT, "elevation returning 0/0: refused with the key path", 0, PLAN_NONE, false, false, false,
     in_nan_elevation, NULL, {"objects[4].elevation", "nan"}, NULL},
    {"nan_light_position", GROUP_INPUT, "light position {0, 0/0, 0}: refused with the key path", 0, PLAN_NONE, false,
     false, false, in_nan_light_position, NULL, {"lights[1].position[2]", "outside"}, NULL},
    {"inf_light_position", GROUP_INPUT, "light position {0, 1/0, 0}: refused with the key path", 0, PLAN_NONE, false,
     false, false, in_inf_light_position, NULL, {"lights[1].position[2]", "outside"}, NULL},
    {"nan_light_radius", GROUP_INPUT, "light radius 0/0: refused with the key path and range", 0, PLAN_NONE, false,
     false, false, in_nan_light_radius, NULL, {"lights[1].radius", "(0, 1e+07]"}, NULL},
    {"nan_light_direction", GROUP_INPUT, "light direction {0/0, -1, 0}: refused with the key path", 0, PLAN_NONE,
     false, false, false, in_nan_light_direction, NULL, {"lights[1].direction[1]", "outside"}, NULL},
    {"nan_light_image", GROUP_INPUT, "light image with a NaN texel: refused naming the file and texel", 0, PLAN_NONE,
     false, false, false, in_nan_light_image, NULL, {"bad-light.exr", "texel"}, NULL},
    {"inf_light_image", GROUP_INPUT, "light image with an Inf texel: refused naming the file and texel", 0, PLAN_NONE,
     false, false, false, in_inf_light_image, NULL, {"bad-light.exr", "texel"}, NULL},
    {"negative_light_image", GROUP_INPUT, "light image with a negative texel: refused naming the file and texel", 0,
     PLAN_NONE, false, false, false, in_negative_light_image, NULL, {"bad-light.exr", "texel"}, NULL},
    {"nan_camera", GROUP_INPUT, "camera fov and position NaN: refused with the key path", 0, PLAN_NONE, false, false, false,
     in_nan_camera, NULL, {"camera.fov", "(0, 180)"}, NULL},
    {"scene_triangle_budget", GROUP_INPUT, "five 2048-segment spheres (21M triangles): refused at the scene's triangle budget", 0,
     PLAN_NONE, false, false, false, in_triangle_budget, NULL, {"objects[7]", "triangle"}, NULL},
};

int stab_cases_count(void) { return (int)(sizeof cases / sizeof cases[0]); }
const StabCase *stab_cases_at(int i) { return &cases[i]; }
