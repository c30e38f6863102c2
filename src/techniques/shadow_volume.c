/* shadow_volume.c -- `shadow_volume`: Crow's shadow volumes counted per view
 * sample (course §2.2). The volume of the casters for the light's centre is
 * the possible silhouette edges' quads, extruded away from the centre
 * (resources/geometry/silhouette.h: Bergeron's rule on meshes that are not closed, so
 * open and non-manifold meshes are handled, not refused), and for z-fail the
 * caps: the triangles turned toward the centre, and the same triangles
 * extruded (far cap). The camera-space pass (raster/camera_count.h) counts
 * the faces in front of each sample (z-pass, Heidmann 1991) or behind it
 * (z-fail, Bilodeau & Songy 1999, "Carmack's reverse"), or in front of it
 * from counts started at the near plane's (ZP+, Hornus et al. 2005: the near
 * caps projected from the centre onto the near plane); a count that is not
 * zero means shadow (course §2.2 [OWN] correction: overlapping volumes give
 * counts >= 2). Every light kind is shadowed from its centre, as `hard`. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/hash.h"
#include "raster/camera_count.h"
#include "resources/geometry/silhouette.h"
#include "resources/standard.h"
#include "techniques/shadow_volume.h"

static const char *const method_names[] = {"zpass", "zfail", "zpplus", NULL};
static const char *const extrusion_names[] = {"infinite", "finite", NULL};
enum { SV_METHOD, SV_EXTRUSION, SV_DISTANCE, SV_OFFSET };
enum { METHOD_ZPASS, METHOD_ZFAIL, METHOD_ZPPLUS };
enum { EXTRUDE_INFINITE, EXTRUDE_FINITE };

static const ParamDesc sv_params[] = {
    {"method", PARAM_ENUM, METHOD_ZFAIL, 0, 2, "",
     "zpass: count volume faces in front of the sample (Heidmann 1991; wrong where the camera is inside a volume, "
     "whose faces the near plane clips); zfail: count those behind it, volumes capped (Carmack's reverse); zpplus: "
     "z-pass from counts that start at the near plane's, the near caps projected from the light's centre onto it "
     "(ZP+, Hornus et al. 2005)",
     method_names},
    {"extrusion", PARAM_ENUM, EXTRUDE_INFINITE, 0, 1, "",
     "infinite: silhouette quads and far cap at infinity (homogeneous w = 0, Everitt & Kilgard 2002); finite: "
     "extruded by `distance`, so receivers farther than that behind a caster are lit",
     extrusion_names},
    {"distance", PARAM_FLOAT, 1000.0, 1e-6, 1e9, "world units",
     "extrusion=finite: how far each silhouette and cap vertex moves away from the light's centre", NULL},
    {"offset_scale", PARAM_FLOAT, 1.0, 0.0, 1e4, "x rt_ray_offset",
     "each sample is tested at its point moved toward the camera along its view ray by this multiple of the "
     "engine's scale-aware ray offset (`hard`'s ray-origin offset), and by the rasterizer's snapping margin, so the "
     "caps through it do not count it",
     NULL},
};

static const char *const sv_resources[] = {"silhouette", "shadow_volume_counts", NULL};
static const char *const sv_aux[] = {"count", NULL};

/* The volume as one homogeneous mesh with a signed count per triangle. */
typedef struct Volume {
    vec3 *p;
    float *w;
    uint32_t *ix;
    int16_t *count;
    int nv, nt;
} Volume;

typedef struct Extrude {
    double L[4];     /* the light's centre, homogeneous (silhouette.h) */
    bool infinite;
    float distance;  /* world units, finite extrusion */
} Extrude;

/* Vertex x moved away from the centre: the direction x L.w - L.xyz, at
 * infinity (w = 0) or `distance` along it. */
static void push_extruded(Volume *v, const Extrude *e, vec3 x)
{
    vec3 dir = v3((float)(x.x * e->L[3] - e->L[0]), (float)(x.y * e->L[3] - e->L[1]), (float)(x.z * e->L[3] - e->L[2]));
    v->p[v->nv] = e->infinite ? dir : v3_madd(x, v3_normalize_or(dir, v3(0, 0, 0)), e->distance);
    v->w[v->nv++] = e->infinite ? 0.0f : 1.0f;
}

static void push_point(Volume *v, vec3 x)
{
    v->p[v->nv] = x;
    v->w[v->nv++] = 1.0f;
}

static void push_tri(Volume *v, uint32_t a, uint32_t b, uint32_t c, int16_t count)
{
    uint32_t *ix = &v->ix[3 * v->nt];
    ix[0] = a;
    ix[1] = b;
    ix[2] = c;
    v->count[v->nt++] = count;
}

/* Quad over the directed silhouette edge a -> b: (b, a, a', b'), which the
 * triangles turned toward the centre traverse the other way round, so its
 * front faces out of the volume. */
static void push_quad(Volume *v, const Extrude *e, const SilEdge *s)
{
    uint32_t base = (uint32_t)v->nv;
    push_point(v, s->b);
    push_point(v, s->a);
    push_extruded(v, e, s->a);
    push_extruded(v, e, s->b);
    push_tri(v, base, base + 1, base + 2, (int16_t)s->count);
    push_tri(v, base, base + 2, base + 3, (int16_t)s->count);
}

/* Which parts of the volume a method draws. */
enum { PART_SIDES = 1, PART_NEAR_CAPS = 2, PART_FAR_CAPS = 4 };

/* Near cap (a, b, c) turned toward the centre, and the far cap (c', b', a'). */
static void push_caps(Volume *v, const Extrude *e, vec3 a, vec3 b, vec3 c, unsigned parts)
{
    uint32_t base = (uint32_t)v->nv;
    if (parts & PART_NEAR_CAPS) {
        push_point(v, a);
        push_point(v, b);
        push_point(v, c);
        push_tri(v, base, base + 1, base + 2, 1);
        base += 3;
    }
    if (parts & PART_FAR_CAPS) {
        push_extruded(v, e, a);
        push_extruded(v, e, b);
        push_extruded(v, e, c);
        push_tri(v, base + 2, base + 1, base, 1);
    }
}

static void volume_free(Volume *v)
{
    free(v->p);
    free(v->w);
    free(v->ix);
    free(v->count);
}

static bool volume_build(const Scene *scene, const Silhouette *sil, const Extrude *e, unsigned parts, Volume *v,
                         Error *err)
{
    bool caps = parts & (PART_NEAR_CAPS | PART_FAR_CAPS);
    int cap_parts = ((parts & PART_NEAR_CAPS) != 0) + ((parts & PART_FAR_CAPS) != 0);
    long quads = parts & PART_SIDES ? sil->num_edges : 0, cap_tris = 0;
    for (int i = 0; caps && i < sil->num_objects; i++)
        for (int t = 0; t < sil->objects[i].triangles; t++) cap_tris += sil->objects[i].weight[t] != 0;
    for (int i = 0; i < sil->num_edges; i++)
        if (sil->edges[i].count > INT16_MAX)
            return error_set(err, "shadow_volume: an edge of object '%s' is extruded %d times (at most %d)",
                             scene->objects[sil->edges[i].object].name, sil->edges[i].count, INT16_MAX);
    long nv = 4 * quads + 3L * cap_parts * cap_tris, nt = 2 * quads + (long)cap_parts * cap_tris;
    if (nv >= INT32_MAX || nt >= INT32_MAX / 3)
        return error_set(err, "shadow_volume: %ld volume triangles exceed the rasterizer's range", nt);
    memset(v, 0, sizeof *v);
    v->p = malloc(sizeof *v->p * (size_t)(nv + 1));
    v->w = malloc(sizeof *v->w * (size_t)(nv + 1));
    v->ix = malloc(sizeof *v->ix * 3 * (size_t)(nt + 1));
    v->count = malloc(sizeof *v->count * (size_t)(nt + 1));
    if (!v->p || !v->w || !v->ix || !v->count) {
        volume_free(v);
        return error_set(err, "out of memory for %ld shadow-volume triangles", nt);
    }
    for (int i = 0; i < quads; i++) push_quad(v, e, &sil->edges[i]);
    for (int i = 0; caps && i < sil->num_objects; i++) {
        const SilObject *so = &sil->objects[i];
        const Mesh *m = &scene->objects[so->object].mesh;
        for (int t = 0; t < so->triangles; t++) {
            if (!so->weight[t]) continue;
            const uint32_t *ix = &m->indices[3 * t];
            vec3 a = m->positions[ix[0]], b = m->positions[ix[1]], c = m->positions[ix[2]];
            if (so->weight[t] > 0) push_caps(v, e, a, b, c, parts);
            else push_caps(v, e, a, c, b, parts);
        }
    }
    return true;
}

/* The counts: per view sample, the number of volumes it is in (z-fail's
 * sign turned). A frame resource keyed by the silhouette, the view samples
 * and the parameters that shape the volume, so `--repeat` times its builds
 * (the volume and the camera pass) as it times a shadow map's. */
typedef struct SvCounts {
    int n;
    int32_t *count;
    RasterStats fill; /* the volume's triangles in and drawn, fragments counted (ZP+'s near caps included) */
} SvCounts;

/* The view depth each sample is tested at: its point moved toward the
 * camera along its own view ray (the sample's pixel is where its counter
 * is) by the ray offset, d - off (r.f), and by the rasterizer's snapping
 * margin: vertices snap to 1/256 of a sample (raster.h), which moves a
 * plane's depth at a sample by up to its depth gradient times sqrt(2)/512
 * samples; the gradient of a surface at view distance d is d tan(gamma)
 * 2 tan_y / H per sample (gamma between the normal and the view ray), and
 * the margin is 1/256 of it (tan clamped at 1e3, grazing). Without them the
 * caps of open meshes, which lie on their surface, count their own samples.
 * (Lifting along the normal instead, as `hard`'s ray origin, moves the
 * point's depth the wrong way where the normal leans away from the view
 * axis, e.g. the ground at the bottom of a level view.) */
static float *test_depths(const TechContext *ctx, double offset_scale)
{
    const ViewSamples *vs = ctx->vs;
    const Camera *cam = &ctx->scene->camera;
    vec3 f, r, u;
    float tx, ty;
    camera_axes(cam, vs->width, vs->height, &f, &r, &u, &tx, &ty);
    float extent = scene_extent(ctx->scene), *d = malloc(sizeof *d * (size_t)vs->count);
    float sample_angle = 2.0f * ty / (float)vs->height;
    for (int s = 0; d && s < vs->count; s++) {
        if (vs->object[s] < 0) { d[s] = 0.0f; continue; }
        vec3 p = vs->p_world[s], n = vs->n_geom_world[s], ray = v3_normalize_or(v3_sub(p, cam->position), f);
        float c = fabsf(v3_dot(n, ray)), tan_gamma = c > 1e-3f ? sqrtf(fmaxf(0.0f, 1.0f - c * c)) / c : 1e3f;
        float off = (float)offset_scale * rt_ray_offset(extent, p);
        float snap = vs->depth_view[s] * tan_gamma * sample_angle / 256.0f;
        d[s] = vs->depth_view[s] - off * v3_dot(ray, f) - snap;
    }
    return d;
}

static bool count_volumes(const TechContext *ctx, const Volume *v, const Volume *near_caps, const double L[4],
                          int method, double offset_scale, int32_t *out, RasterStats *stats, Error *err)
{
    float *depth = test_depths(ctx, offset_scale);
    if (!depth) return error_set(err, "out of memory for %d test depths", ctx->vs->count);
    CameraCount cc;
    bool ok = camera_count_init(&cc, &ctx->scene->camera, ctx->vs, depth, err);
    free(depth);
    if (!ok) return false;
    RasterMesh mesh = {v->p, v->ix, v->nv, v->nt};
    RasterMeshExtra extra = {v->w, v->count};
    CountTest test = method == METHOD_ZFAIL ? COUNT_FARTHER : COUNT_NEARER;
    if (near_caps) {
        RasterMesh caps = {near_caps->p, near_caps->ix, near_caps->nv, near_caps->nt};
        RasterMeshExtra caps_extra = {near_caps->w, near_caps->count};
        RasterStats near;
        ok = camera_count_near_caps(&cc, &ctx->scene->camera, &caps, &caps_extra, L, &near, err);
        stats->triangles_in += near.triangles_in;
        stats->triangles_drawn += near.triangles_drawn;
        stats->texels_written += near.texels_written;
    }
    RasterStats st;
    ok = ok && camera_count_render(&cc, &mesh, &extra, 1, test, &st, err);
    if (ok) {
        stats->triangles_in += st.triangles_in;
        stats->triangles_drawn += st.triangles_drawn;
        stats->texels_written += st.texels_written;
    }
    /* z-pass counts entries minus exits in front of p; z-fail the exits
     * minus entries behind it: the same number with the faces' signs turned */
    for (int s = 0; ok && s < ctx->vs->count; s++) {
        int32_t c = camera_count_at(&cc, s);
        out[s] = method != METHOD_ZFAIL ? c : c == INT32_MIN ? INT32_MAX : -c;
    }
    camera_count_free(&cc);
    return ok;
}

bool shadow_volume_zfail_counts(const TechContext *ctx, const Silhouette *sil, double offset_scale, int32_t *count,
                                RasterStats *fill, Error *err)
{
    Extrude e = {{sil->light[0], sil->light[1], sil->light[2], sil->light[3]}, true, 0.0f};
    Volume v;
    if (!volume_build(ctx->scene, sil, &e, PART_SIDES | PART_NEAR_CAPS | PART_FAR_CAPS, &v, err)) return false;
    *fill = (RasterStats){0};
    bool ok = count_volumes(ctx, &v, NULL, sil->light, METHOD_ZFAIL, offset_scale, count, fill, err);
    volume_free(&v);
    return ok;
}

static size_t counts_bytes(const void *res) { return sizeof(SvCounts) + sizeof(int32_t) * (size_t)((const SvCounts *)res)->n; }

static void counts_destroy(void *res)
{
    SvCounts *c = res;
    free(c->count);
    free(c);
}

static const ResourceKind kind_counts = {"shadow_volume_counts", counts_bytes, counts_destroy, RES_FRAME};

typedef struct CountArgs {
    const TechContext *ctx;
    const Silhouette *sil;
} CountArgs;

static void *build_counts(const void *args, Error *err)
{
    const CountArgs *a = args;
    const TechContext *ctx = a->ctx;
    int method = (int)ctx->params[SV_METHOD];
    Extrude e = {{a->sil->light[0], a->sil->light[1], a->sil->light[2], a->sil->light[3]},
                 (int)ctx->params[SV_EXTRUSION] == EXTRUDE_INFINITE, (float)ctx->params[SV_DISTANCE]};
    Volume v, near_caps = {0};
    unsigned parts = method == METHOD_ZFAIL ? PART_SIDES | PART_NEAR_CAPS | PART_FAR_CAPS : PART_SIDES;
    if (!volume_build(ctx->scene, a->sil, &e, parts, &v, err)) return NULL;
    if (method == METHOD_ZPPLUS && !volume_build(ctx->scene, a->sil, &e, PART_NEAR_CAPS, &near_caps, err)) {
        volume_free(&v);
        return NULL;
    }
    SvCounts *c = malloc(sizeof *c);
    int32_t *count = malloc(sizeof *count * (size_t)ctx->vs->count);
    RasterStats fill = {0};
    bool ok = c && count &&
              count_volumes(ctx, &v, method == METHOD_ZPPLUS ? &near_caps : NULL, a->sil->light, method,
                            ctx->params[SV_OFFSET], count, &fill, err);
    if (!c || !count) error_set(err, "out of memory for %d shadow-volume counts", ctx->vs->count);
    volume_free(&v);
    volume_free(&near_caps);
    if (!ok) {
        free(c);
        free(count);
        return NULL;
    }
    *c = (SvCounts){ctx->vs->count, count, fill};
    return c;
}

static bool sv_prepare(const TechContext *ctx, void **state, Error *err)
{
    const Silhouette *sil = res_silhouette(ctx->rm, ctx->scene, ctx->light_index, err);
    if (!sil) return false;
    bool finite = (int)ctx->params[SV_EXTRUSION] == EXTRUDE_FINITE;
    Hasher h;
    hash_init(&h);
    hash_str(&h, "shadow volume counts 1");
    hash_u64(&h, sil->key);
    hash_u64(&h, ctx->scene->hash_geometry); /* the view samples: geometry and camera */
    hash_u64(&h, ctx->scene->hash_camera);
    hash_f64(&h, ctx->params[SV_METHOD]);
    hash_f64(&h, ctx->params[SV_EXTRUSION]);
    hash_f64(&h, finite ? ctx->params[SV_DISTANCE] : 0.0); /* only a finite extrusion reads it */
    hash_f64(&h, ctx->params[SV_OFFSET]);
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %s, %s extrusion, %dx%d samples", ctx->light_index + 1,
             method_names[(int)ctx->params[SV_METHOD]], extrusion_names[finite], ctx->vs->width, ctx->vs->height);
    CountArgs a = {ctx, sil};
    uint64_t key = hash_final(&h);
    const SvCounts *c = rm_acquire(ctx->rm, &kind_counts, key, desc, build_counts, &a, err);
    if (!c) return false;
    char fill[160]; /* the cost the course's discussion is about (§2.3: silhouette edges, "high fill from long quads") */
    snprintf(fill, sizeof fill, "%d silhouette edges, %ld volume triangles, %ld drawn, %ld fragments counted",
             sil->num_edges, c->fill.triangles_in, c->fill.triangles_drawn, c->fill.texels_written);
    rm_log_note(ctx->rm, kind_counts.name, key, fill);
    *state = (void *)c;
    return true;
}

static void sv_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const SvCounts *st = state;
    for (int s = begin; s < end; s++) {
        if (ctx->cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        tech_store(ctx, out, begin, s, st->count[s] != 0 ? 0.0f : 1.0f); /* count != 0: shadowed */
        if (ctx->aux) ctx->aux[s] = (float)st->count[s];
    }
}

/* A finite volume's length; infinite volumes reach w = 0. */
static const ParamCondition sv_conditions[] = {
    {"distance", "extrusion=finite"},
    {NULL, NULL},
};

const Technique tech_shadow_volume = {
    .conditions = sv_conditions,
    .name = "shadow_volume",
    .family = "geometry",
    .source = "course §2.2 (Crow 1977; z-pass Heidmann 1991; z-fail Bilodeau & Songy 1999; ZP+ Hornus et al. 2005; open meshes Bergeron 1986)",
    .summary = "shadow volumes from the light's centre: silhouette quads (and caps) counted per view sample in camera "
               "space, shadowed where the count is not zero",
    .params = sv_params,
    .num_params = (int)(sizeof sv_params / sizeof sv_params[0]),
    .resources = sv_resources,
    .rgb = true,
    .lights = LIGHTS_ALL,
    .main_param = "method",
    .prepare = sv_prepare,
    .evaluate = sv_evaluate,
    .release = NULL, /* the state is the counts resource, which the manager owns */
    .aux = sv_aux,
};
