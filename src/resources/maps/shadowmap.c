/* shadowmap.c -- building and keying light-space depth maps (shadowmap.h). */
#include "resources/maps/shadowmap.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/bufpool.h"
#include "core/hash.h"
#include "resources/maps/logmap.h"
#include "resources/standard.h"

ShadowMapSpec shadowmap_spec_default(void)
{
    return (ShadowMapSpec){.res = 1024, .projection = MAP_PROJ_AUTO, .fit = MAP_FIT_SCENE,
                           .depth = RASTER_DEPTH_LINEAR, .layer = MAP_LAYER_FIRST, .cull = RASTER_CULL_NONE,
                           .view = lightview_params_default()};
}

/* Faces the map may need: AUTO may turn a point or sphere light into a cube. */
static int max_faces(const Light *light, const ShadowMapSpec *spec)
{
    MapProjection p = spec->projection;
    if (spec->view.split == SPLIT_FACES) return 6;
    if (spec->view.cascades > 1) return spec->view.cascades;
    if (p == MAP_PROJ_CUBE) return 6;
    if (p == MAP_PROJ_PARABOLOID) return 2;
    if (p == MAP_PROJ_AUTO && (light->kind == LIGHT_POINT || light->kind == LIGHT_SPHERE)) return 6;
    return 1;
}

size_t shadowmap_bytes_for(const Light *light, const ShadowMapSpec *spec)
{
    size_t texels = (size_t)max_faces(light, spec) * (size_t)spec->res * (size_t)spec->res;
    return texels * (sizeof(float) + (spec->triangle_ids ? sizeof(int32_t) : 0));
}

void shadowmap_free(void *r)
{
    ShadowMap *m = r;
    bufpool_free(m->depth);
    bufpool_free(m->triangle);
    free(m);
}

size_t shadowmap_bytes(const void *r)
{
    const ShadowMap *m = r;
    size_t texels = (size_t)m->num_faces * (size_t)m->res * (size_t)m->res;
    return sizeof *m + texels * (sizeof(float) + (m->triangle ? sizeof(int32_t) : 0));
}

static const ResourceKind kind_shadow_map = {"shadow_map", shadowmap_bytes, shadowmap_free, RES_FRAME};

typedef struct MapArgs {
    ResourceManager *rm;
    const Scene *scene;
    int light_index;
    ShadowMapSpec spec;
    uint64_t key;
} MapArgs;

static int caster_meshes(const Scene *sc, RasterMesh *out)
{
    int n = 0;
    for (int i = 0; i < sc->num_objects; i++) {
        const Object *o = &sc->objects[i];
        if (!o->caster) continue;
        out[n++] = (RasterMesh){o->mesh.positions, o->mesh.indices, o->mesh.num_vertices, o->mesh.num_triangles};
    }
    return n;
}

static RasterOptions raster_options(const ShadowMapSpec *spec, const float *peel)
{
    RasterOptions o = {.cull = spec->cull, .test = RASTER_NEAREST, .depth = spec->depth,
                       .depth_bits = spec->depth_bits, .conservative = spec->conservative,
                       .triangle_ids = spec->triangle_ids, .peel = peel};
    if (spec->layer == MAP_LAYER_BACKFACES || spec->layer == MAP_LAYER_FARTHEST_BACKFACES) o.cull = RASTER_CULL_FRONT;
    if (spec->layer == MAP_LAYER_FARTHEST_BACKFACES) o.test = RASTER_FARTHEST;
    if (spec->layer == MAP_LAYER_PEELED) o.cull = RASTER_CULL_NONE;
    return o;
}

/* The first layer a peeled map peels behind: unquantised, no ids, same view. */
static const ShadowMap *peel_source(const MapArgs *a, Error *err)
{
    ShadowMapSpec first = a->spec;
    first.layer = MAP_LAYER_FIRST;
    first.cull = RASTER_CULL_NONE;
    first.depth_bits = 0;
    first.triangle_ids = false;
    return res_shadow_map(a->rm, a->scene, a->light_index, &first, err);
}

/* A homography-warped face rasterizes z_ndc scaled by w_min / w (lightview.h);
 * w is constant along a light ray, so each texel's depth times w / w_min at
 * its centre is the base projection's z_ndc of the surface there, what the
 * lookups compare with. */
static void base_ndc_depths(const LightView *lv, int face, float *depth)
{
    const MapFace *f = &lv->face[face];
    if (f->warp != MAP_WARP_HOMOGRAPHY) return;
    const double(*Hi)[3] = f->H_inv;
#pragma omp parallel for schedule(static)
    for (int j = 0; j < lv->res; j++) {
        double v = 2.0 * (j + 0.5) / lv->res - 1.0;
        for (int i = 0; i < lv->res; i++) {
            double u = 2.0 * (i + 0.5) / lv->res - 1.0, w = 1.0 / (Hi[2][0] * u + Hi[2][1] * v + Hi[2][2]);
            float *d = &depth[(size_t)j * lv->res + i];
            if (isfinite(*d)) *d = (float)fmin(fmax(*d * w / f->w_min, 0.0), 1.0);
        }
    }
}

/* The peel test's epsilon on one face (raster.h: fragments within it behind
 * the layer peeled are discarded), in the map's value space: PEEL_EPSILON_REL
 * of the face's depth range (linear: world units along the light's axis;
 * ndc: of [0, 1]), plus one quantisation step on a quantised map, whose
 * stored layer lies up to half a step in front of the surface it holds. */
#define PEEL_EPSILON_REL 1e-5
float shadowmap_peel_epsilon(const ShadowMap *m, int face)
{
    const RasterView *v = &m->view.face[face].raster;
    double range = m->spec.depth == RASTER_DEPTH_NDC ? 1.0 : v->depth_far - v->depth_near;
    if (!(range > 0.0)) range = 0.0; /* a degenerate range: peel behind the exact values */
    double step = m->spec.depth_bits ? range / (double)((1u << m->spec.depth_bits) - 1u) : 0.0;
    return (float)(PEEL_EPSILON_REL * range + step);
}

/* Render m's faces from its view with its spec; under (a map of the same
 * view, or NULL) is the layer peeled, by its exact depths (epsilon 0, the
 * second layer of MAP_LAYER_PEELED) or with shadowmap_peel_epsilon. */
static bool render_faces(ShadowMap *m, const Scene *sc, const ShadowMap *under, bool epsilon, Error *err)
{
    RasterMesh *meshes = malloc(sizeof *meshes * (size_t)(sc->num_objects > 0 ? sc->num_objects : 1));
    if (!meshes) return error_set(err, "out of memory");
    int nm = caster_meshes(sc, meshes);
    size_t face_texels = (size_t)m->res * (size_t)m->res;
    bool ok = true;
    RasterScratch *scratch = NULL; /* the faces' working memory, shared */
    for (int f = 0; ok && f < m->num_faces; f++) {
        DepthBuffer db = {m->res, m->res, m->depth + f * face_texels, m->triangle ? m->triangle + f * face_texels : NULL,
                          scratch};
        RasterOptions opt = raster_options(&m->spec, under ? under->depth + f * face_texels : NULL);
        if (under && epsilon) opt.peel_epsilon = shadowmap_peel_epsilon(under, f);
        RasterStats st;
        ok = raster_depth(meshes, nm, &m->view.face[f].raster, &opt, &db, &st, err);
        scratch = db.scratch;
        if (ok && m->spec.depth == RASTER_DEPTH_NDC) base_ndc_depths(&m->view, f, db.depth);
        for (size_t i = 0; opt.test == RASTER_FARTHEST && i < face_texels; i++) /* the map's empty: +INFINITY */
            if (db.depth[i] == -INFINITY) db.depth[i] = INFINITY;
        m->stats.triangles_in += st.triangles_in;
        m->stats.triangles_culled += st.triangles_culled;
        m->stats.triangles_clipped += st.triangles_clipped;
        m->stats.triangles_drawn += st.triangles_drawn;
        m->stats.texels_written += st.texels_written;
    }
    raster_scratch_free(scratch);
    free(meshes);
    return ok;
}

/* A map of the spec from the view, its depth allocated (ids when the spec
 * asks for them), nothing drawn yet. */
static ShadowMap *map_alloc(const ShadowMapSpec *spec, uint64_t key, const LightView *view, Error *err)
{
    ShadowMap *m = calloc(1, sizeof *m);
    if (!m) {
        error_set(err, "out of memory");
        return NULL;
    }
    m->spec = *spec;
    m->key = key;
    m->view = *view;
    m->res = spec->res;
    m->num_faces = m->view.num_faces;
    size_t texels = (size_t)m->num_faces * (size_t)m->res * (size_t)m->res;
    m->depth = bufpool_alloc(texels * sizeof *m->depth);
    if (spec->triangle_ids) m->triangle = bufpool_alloc(texels * sizeof *m->triangle);
    if (!m->depth || (spec->triangle_ids && !m->triangle)) {
        error_set(err, "out of memory for a %d-face %d^2 shadow map", m->num_faces, m->res);
        shadowmap_free(m);
        return NULL;
    }
    return m;
}

/* Why a layer peeled behind a map of this spec cannot be drawn, or NULL. */
static const char *peel_refusal(const ShadowMapSpec *s)
{
    if (s->projection >= MAP_PROJ_PSM && s->depth == RASTER_DEPTH_NDC)
        return "a peeled layer of a warped map needs linear depth (its ndc depth is rescaled per texel)";
    return NULL;
}

ShadowMap *shadowmap_render_behind(const Scene *scene, const ShadowMap *under, uint64_t key, Error *err)
{
    MapProjection p = under->spec.projection;
    const char *why = p == MAP_PROJ_LOGPSM ? "a ray-cast map has no rasterized layer to peel behind"
                                           : peel_refusal(&under->spec);
    if (why) {
        error_set(err, "projection %s: %s", map_projection_name(p), why);
        return NULL;
    }
    ShadowMapSpec spec = under->spec;
    spec.layer = MAP_LAYER_PEELED;
    spec.triangle_ids = false;
    ShadowMap *m = map_alloc(&spec, key, &under->view, err);
    if (m && !render_faces(m, scene, under, true, err)) {
        shadowmap_free(m);
        return NULL;
    }
    return m;
}

/* ---- the light view: the map's fit, a frame resource of its own ---------- */

/* Fitting to the view (fit=view, body_visible) reads the visible samples: a
 * renderer has them in its G-buffer, so they are not charged, but the
 * reduction over them that the fit needs (their bounds in light space, the
 * farthest one's depth; course §3.2.1, a visibility pre-pass pulling the far
 * plane in) is this resource's own build time, charged to the frame. */
static void *build_light_view(const void *args, Error *err)
{
    const MapArgs *a = args;
    const Scene *sc = a->scene;
    const ViewSamples *vs = NULL;
    const uint8_t *cls = NULL;
    if (a->spec.fit == MAP_FIT_VIEW || a->spec.fit == MAP_FIT_BODY_VISIBLE) {
        vs = res_view_samples(a->rm, sc, err);
        cls = vs ? res_classes(a->rm, sc, a->light_index, err) : NULL;
        if (!cls) return NULL;
    }
    LightView *lv = malloc(sizeof *lv);
    if (!lv) {
        error_set(err, "out of memory");
        return NULL;
    }
    if (!lightview_fit_with(sc, &sc->lights[a->light_index], a->spec.projection, a->spec.fit, a->spec.res,
                            &a->spec.view, vs, cls, lv, err)) {
        free(lv);
        return NULL;
    }
    return lv;
}
static size_t light_view_bytes(const void *r) { return sizeof *(const LightView *)r; }
static const ResourceKind kind_light_view = {"light_view", light_view_bytes, free, RES_FRAME};

static uint64_t map_key(const Scene *sc, int light_index, const ShadowMapSpec *s);

/* The view of a map: keyed like the map less what only its rasterization
 * reads (depth format, layer, culling, ids), so a map's layers share it. */
static const LightView *res_light_view(const MapArgs *a, Error *err)
{
    MapArgs v = *a;
    ShadowMapSpec *s = &v.spec;
    s->depth = RASTER_DEPTH_LINEAR;
    s->depth_bits = 0;
    s->layer = MAP_LAYER_FIRST;
    s->cull = RASTER_CULL_NONE;
    s->triangle_ids = false;
    s->conservative = false;
    Hasher h;
    hash_init(&h);
    hash_str(&h, "light view");
    hash_u64(&h, map_key(a->scene, a->light_index, s));
    char desc[160];
    snprintf(desc, sizeof desc, "light %d, %d^2 %s, fit %s", a->light_index + 1, s->res,
             map_projection_name(s->projection), map_fit_name(s->fit));
    uint64_t key = hash_final(&h);
    const LightView *lv = rm_acquire(a->rm, &kind_light_view, key, desc, build_light_view, &v, err);
    if (lv && s->projection == MAP_PROJ_AUTO) { /* what auto resolved to, in the run's record */
        char note[64];
        snprintf(note, sizeof note, "auto = %s, %d face%s", map_projection_name(lv->projection), lv->num_faces,
                 lv->num_faces == 1 ? "" : "s");
        rm_log_note(a->rm, kind_light_view.name, key, note);
    }
    return lv;
}

static void *build_map(const void *args, Error *err)
{
    const MapArgs *a = args;
    const Scene *sc = a->scene;
    const LightView *view = res_light_view(a, err);
    if (!view) return NULL;
    bool cast = a->spec.projection == MAP_PROJ_LOGPSM;
    const RtScene *casters = cast ? res_bvh(a->rm, sc, RT_CASTERS, err) : NULL;
    if (cast && !casters) return NULL;
    const ShadowMap *under = a->spec.layer == MAP_LAYER_PEELED ? peel_source(a, err) : NULL;
    if (a->spec.layer == MAP_LAYER_PEELED && !under) return NULL;
    ShadowMap *m = map_alloc(&a->spec, a->key, view, err);
    if (!m) return NULL;
    if (!(cast ? logmap_cast(m, sc, casters, err) : render_faces(m, sc, under, false, err))) {
        shadowmap_free(m);
        return NULL;
    }
    return m;
}

/* The view parameters that shape this map (the others zeroed), so a sweep
 * over, say, tsm_focus reuses a LiSPSM map. */
static LightViewParams relevant_params(const ShadowMapSpec *s)
{
    LightViewParams v = s->view, z = {0};
    MapProjection p = s->projection;
    bool warp = p >= MAP_PROJ_PSM && p <= MAP_PROJ_LOGPSM, partitioned = v.cascades > 1 || v.split == SPLIT_FACES;
    if (!warp || p == MAP_PROJ_PSM) { v.warp_n = z.warp_n; v.falloff = z.falloff; }
    if (p != MAP_PROJ_LISPSM && p != MAP_PROJ_LOGPSM) v.warp_n_world = z.warp_n_world;
    if (!warp && !partitioned) v.pseudo_near = z.pseudo_near;
    if (p != MAP_PROJ_TSM) v.tsm_focus = z.tsm_focus;
    if (v.split != SPLIT_EXPLICIT) memcpy(v.split_at, z.split_at, sizeof v.split_at); /* given ones may be refused */
    if (!partitioned) { v.split = z.split; v.select = z.select; v.blend = z.blend; v.cascades = 1; }
    if (!partitioned || v.split != SPLIT_PRACTICAL) v.split_lambda = z.split_lambda;
    return v;
}

/* What of the light a map depends on: the frame it is rendered from (kind,
 * centre, axis, cone), not its size or colour, so a sweep over the light's
 * radius reuses the map. Fitting to the view reads the sample classes,
 * which do depend on the size: then the whole light counts. */
static void hash_light_frame(Hasher *h, const Scene *sc, int light_index, bool follows_camera)
{
    if (follows_camera) {
        hash_u64(h, sc->hash_lights[light_index]);
        return;
    }
    const Light *l = &sc->lights[light_index];
    hash_u64(h, (uint64_t)l->kind);
    hash_f32(h, l->position.x); hash_f32(h, l->position.y); hash_f32(h, l->position.z);
    hash_f32(h, l->direction.x); hash_f32(h, l->direction.y); hash_f32(h, l->direction.z);
    hash_f32(h, l->cone_half_rad);
}

static uint64_t map_key(const Scene *sc, int light_index, const ShadowMapSpec *s)
{
    Hasher h;
    hash_init(&h);
    hash_u64(&h, sc->hash_casters);                 /* what is drawn */
    hash_u64(&h, sc->hash_geometry);                /* the bounds it is fitted to */
    bool follows_camera = lightview_follows_camera(s->projection, s->fit, &s->view);
    hash_light_frame(&h, sc, light_index, follows_camera);
    if (follows_camera) hash_u64(&h, sc->hash_camera);
    const int64_t fields[] = {s->res, s->projection, s->fit, s->depth, s->depth_bits, s->layer,
                              s->cull, s->triangle_ids, s->conservative};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) hash_u64(&h, (uint64_t)fields[i]);
    LightViewParams v = relevant_params(s);
    const int64_t ints[] = {v.falloff, v.stabilize, v.cascades, v.split, v.select};
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++) hash_u64(&h, (uint64_t)ints[i]);
    const double reals[] = {v.warp_n, v.pseudo_near, v.tsm_focus, v.split_lambda, v.blend};
    for (size_t i = 0; i < sizeof reals / sizeof reals[0]; i++) hash_f64(&h, reals[i]);
    hash_f64(&h, v.warp_n_world);
    for (int i = 0; i < LIGHTVIEW_EXPLICIT_SPLITS; i++) hash_f64(&h, v.split_at[i]);
    return hash_final(&h);
}

static const char *layer_name(MapLayer l)
{
    static const char *const names[] = {"first layer", "back faces", "peeled second layer", "farthest back faces"};
    return names[l];
}

const ShadowMap *res_shadow_map(ResourceManager *rm, const Scene *scene, int light_index, const ShadowMapSpec *spec,
                                Error *err)
{
    const Light *light = &scene->lights[light_index];
    if (spec->res < 1 || spec->res > RASTER_MAX_SIZE) {
        error_set(err, "map_size %d outside [1, %d]", spec->res, RASTER_MAX_SIZE);
        return NULL;
    }
    size_t bytes = shadowmap_bytes_for(light, spec);
    if (bytes > SHADOWMAP_MAX_BYTES) {
        error_set(err, "map_size %d: a %d-face map needs %.2f GiB, above the %.0f GiB cap on shadow maps", spec->res,
                  max_faces(light, spec), (double)bytes / (1 << 30), (double)SHADOWMAP_MAX_BYTES / (1 << 30));
        return NULL;
    }
    const char *why = spec->projection == MAP_PROJ_LOGPSM ? logmap_refusal(spec) : NULL;
    const char *peel_why = spec->layer == MAP_LAYER_PEELED ? peel_refusal(spec) : NULL;
    if (peel_why) why = peel_why;
    if (why) {
        error_set(err, "projection %s: %s", map_projection_name(spec->projection), why);
        return NULL;
    }
    MapArgs a = {rm, scene, light_index, *spec, map_key(scene, light_index, spec)};
    char desc[160], parts[24] = "";
    if (spec->view.cascades > 1) snprintf(parts, sizeof parts, " x%d cascades", spec->view.cascades);
    snprintf(desc, sizeof desc, "light %d, %d^2%s %s, fit %s, %s %s, %s%s", light_index + 1, spec->res, parts,
             map_projection_name(spec->projection), map_fit_name(spec->fit),
             spec->depth == RASTER_DEPTH_LINEAR ? "linear" : "ndc",
             spec->depth_bits ? (spec->depth_bits == 16 ? "16-bit" : "24-bit") : "f32", layer_name(spec->layer),
             spec->cull == RASTER_CULL_BACK ? ", back faces culled" : "");
    return rm_acquire(rm, &kind_shadow_map, a.key, desc, build_map, &a, err);
}
