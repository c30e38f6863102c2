/* logmap.c -- LogPSM depth maps by ray casting (logmap.h). Texel (i, j)
 * holds what the rasterizer would store for a caster covering its centre:
 * the linear depth along the light of the nearest hit, or the base's z_ndc
 * of it; +INFINITY where the ray meets no caster. */
#include "resources/maps/logmap.h"
#include <stdlib.h>
#include "resources/views/warp.h"

const char *logmap_refusal(const ShadowMapSpec *spec)
{
    if (spec->depth_bits) return "depth_bits must be f32 (the ray-cast map stores float depths)";
    if (spec->layer != MAP_LAYER_FIRST) return "only the first depth layer can be ray cast";
    if (spec->cull != RASTER_CULL_NONE) return "back-face culling has no ray-cast counterpart here";
    if (spec->conservative) return "conservative rasterization has no ray-cast counterpart";
    return NULL;
}

/* Triangle index across the caster meshes in scene order, as raster ids count. */
static int *caster_offsets(const Scene *sc)
{
    int *off = malloc(sizeof *off * (size_t)(sc->num_objects + 1));
    if (!off) return NULL;
    int n = 0;
    for (int i = 0; i < sc->num_objects; i++) {
        off[i] = n;
        if (sc->objects[i].caster) n += sc->objects[i].mesh.num_triangles;
    }
    return off;
}

static void cast_face(ShadowMap *m, int face, RTCScene rtc, const RtScene *rs, const int *offsets)
{
    const MapFace *f = &m->view.face[face];
    const LightView *lv = &m->view;
    size_t base = (size_t)face * (size_t)m->res * (size_t)m->res;
    bool ndc = m->spec.depth == RASTER_DEPTH_NDC;
#pragma omp parallel for schedule(dynamic, 8)
    for (int j = 0; j < m->res; j++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (int i = 0; i < m->res; i++) {
            dvec3 org, dir;
            lightview_texel_ray(lv, face, i + 0.5, j + 0.5, &org, &dir);
            /* the ray runs from the base's near plane to its far plane */
            double depth0 = f->raster.depth_row[0] * org.x + f->raster.depth_row[1] * org.y +
                            f->raster.depth_row[2] * org.z + f->raster.depth_row[3];
            double along = d3_dot(dir, f->axis_world), reach = (f->raster.depth_far - depth0) / fmax(along, 1e-12);
            struct RTCRayHit rh = {0};
            rh.ray.org_x = (float)org.x; rh.ray.org_y = (float)org.y; rh.ray.org_z = (float)org.z;
            rh.ray.dir_x = (float)dir.x; rh.ray.dir_y = (float)dir.y; rh.ray.dir_z = (float)dir.z;
            rh.ray.tnear = 0.0f;
            rh.ray.tfar = (float)fmax(reach, 0.0);
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rt_intersect1(rtc, &ctx, &rh);
            size_t k = base + (size_t)j * (size_t)m->res + (size_t)i;
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                m->depth[k] = INFINITY;
                if (m->triangle) m->triangle[k] = -1;
                continue;
            }
            dvec3 p = d3_madd(org, dir, rh.ray.tfar);
            MapCoord mc = lightview_locate_on(lv, face, p);
            m->depth[k] = (float)(ndc ? mc.z_ndc : mc.depth_linear);
            if (m->triangle) m->triangle[k] = offsets[rt_scene_object(rs, rh.hit.geomID)] + (int32_t)rh.hit.primID;
        }
    }
}

bool logmap_cast(ShadowMap *m, const Scene *scene, const RtScene *casters, Error *err)
{
    int *offsets = caster_offsets(scene);
    if (!offsets) return error_set(err, "out of memory");
    RTCScene rtc = rt_scene_handle(casters);
    long written = 0;
    for (int f = 0; f < m->num_faces; f++) cast_face(m, f, rtc, casters, offsets);
    size_t texels = (size_t)m->num_faces * (size_t)m->res * (size_t)m->res;
    for (size_t k = 0; k < texels; k++) written += isfinite(m->depth[k]);
    m->stats.texels_written = written;
    free(offsets);
    return true;
}
