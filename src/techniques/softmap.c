/* softmap.c -- the light in a face's frame, tangent-frame texel geometry and
 * a Poisson-disk pattern for the single-map soft-shadow techniques (softmap.h). */
#include "techniques/softmap.h"
#include "core/hash.h"

/* The light's half-axes (world) in the face's plane: columns of M. */
static void light_axes(const Light *light, dvec3 ex, dvec3 ey, double M[2][2], bool *square)
{
    dvec3 a, b;
    *square = false;
    if (light->kind == LIGHT_SPHERE) {
        M[0][0] = M[1][1] = light->radius;
        M[0][1] = M[1][0] = 0.0;
        return;
    }
    dvec3 normal = d3_from(light->direction);
    if (light->kind == LIGHT_RECT || light->kind == LIGHT_TEXTURED_RECT) {
        dvec3 up = d3_from(light->up);
        a = d3_scale(d3_cross(up, normal), 0.5 * light->width);
        b = d3_scale(up, 0.5 * light->height);
        *square = true;
    } else { /* disk: any orthonormal pair in its plane */
        dvec3 t = d3_normalize_or(d3_cross(normal, fabs(normal.y) < 0.9 ? d3(0, 1, 0) : d3(1, 0, 0)), d3(1, 0, 0));
        a = d3_scale(t, light->radius);
        b = d3_scale(d3_cross(normal, t), light->radius);
    }
    M[0][0] = d3_dot(a, ex);
    M[1][0] = d3_dot(a, ey);
    M[0][1] = d3_dot(b, ex);
    M[1][1] = d3_dot(b, ey);
}

static void soft_light(const Light *light, const MapFace *f, SoftLight *L)
{
    const double(*v)[4] = f->view_from_world.m; /* rows 0 and 1: the face's x and y axes */
    light_axes(light, d3(v[0][0], v[0][1], v[0][2]), d3(v[1][0], v[1][1], v[1][2]), L->M, &L->square);
    double det = L->M[0][0] * L->M[1][1] - L->M[0][1] * L->M[1][0];
    double inv = fabs(det) > 0.0 ? 1.0 / det : 0.0; /* an edge-on light covers nothing: contains() is false */
    L->Minv[0][0] = L->M[1][1] * inv;
    L->Minv[0][1] = -L->M[0][1] * inv;
    L->Minv[1][0] = -L->M[1][0] * inv;
    L->Minv[1][1] = L->M[0][0] * inv;
    L->area_world = fabs(det) * (L->square ? 4.0 : M_PI);
    L->radius_world = sqrt(L->area_world / M_PI);
    if (L->square) {
        L->half_x = fabs(L->M[0][0]) + fabs(L->M[0][1]);
        L->half_y = fabs(L->M[1][0]) + fabs(L->M[1][1]);
    } else { /* an ellipse x = M (cos a, sin a): half-extent sqrt(m0^2 + m1^2) per row */
        L->half_x = hypot(L->M[0][0], L->M[0][1]);
        L->half_y = hypot(L->M[1][0], L->M[1][1]);
    }
}

bool softmap_frames(SoftMap *sm, const ShadowMap *map, const Light *light, const char *tech, Error *err)
{
    const LightView *lv = &map->view;
    bool projective = lv->projection == MAP_PROJ_PERSPECTIVE || lv->projection == MAP_PROJ_CUBE;
    for (int k = 0; k < map->num_faces; k++) projective = projective && lv->face[k].perspective;
    if (!projective)
        return error_set(err, "%s: projection %s is not supported: the light-size geometry needs plain perspective "
                              "faces from the light's centre (projection auto, perspective or cube)",
                         tech, map_projection_name(lv->projection));
    sm->map = map;
    sm->pyramid = NULL;
    for (int k = 0; k < map->num_faces; k++) {
        const MapFace *f = &lv->face[k];
        SoftFace *sf = &sm->face[k];
        sf->l = f->l;
        sf->b = f->b;
        sf->dx = (f->r - f->l) / map->res;
        sf->dy = (f->t - f->b) / map->res;
        sf->near_world = f->raster.depth_near;
        soft_light(light, f, &sf->light);
    }
    return true;
}

bool softmap_init(SoftMap *sm, ResourceManager *rm, const ShadowMap *map, const Light *light, const char *tech,
                  Error *err)
{
    if (!softmap_frames(sm, map, light, tech, err)) return false;
    sm->pyramid = res_minmax_pyramid(rm, map, err);
    return sm->pyramid != NULL;
}

bool softmap_may_block(const SoftMap *sm, const SmapReceiver *r, int i0, int j0, int i1, int j1,
                       double *z_min_linear)
{
    float zmin, zmax;
    minmax_query(sm->pyramid, r->mc.face, i0, j0, i1, j1, &zmin, &zmax);
    return softmap_bounds_may_block(sm, r, zmin, i0, j0, i1, j1, z_min_linear);
}

bool softmap_bounds_may_block(const SoftMap *sm, const SmapReceiver *r, float zmin, int i0, int j0, int i1, int j1,
                              double *z_min_linear)
{
    if (z_min_linear) *z_min_linear = smap_linear_depth(sm->map, r->mc.face, zmin);
    double ref = nan_max(nan_max(smap_ref_at(r, i0, j0), smap_ref_at(r, i1, j0)),
                         nan_max(smap_ref_at(r, i0, j1), smap_ref_at(r, i1, j1)));
    return !(zmin >= ref); /* NaN-safe: an unknown reference may block */
}

static double uniform01(uint32_t *state)
{
    *state = hash_u32(*state + 0x68e31da4u);
    return (*state >> 8) / 16777216.0;
}

void softmap_poisson(float (*pts)[2], int n)
{
    uint32_t state = 0x2545f491u;
    double radius = 2.0 / sqrt((double)n); /* above the densest packing: it shrinks to fit */
    int placed = 0, misses = 0;
    while (placed < n) {
        double x = 2.0 * uniform01(&state) - 1.0, y = 2.0 * uniform01(&state) - 1.0;
        if (x * x + y * y >= 1.0) continue;
        bool ok = true;
        for (int k = 0; k < placed && ok; k++) {
            double ddx = x - pts[k][0], ddy = y - pts[k][1];
            ok = ddx * ddx + ddy * ddy >= radius * radius;
        }
        if (!ok) {
            if (++misses >= 64) { radius *= 0.95; misses = 0; }
            continue;
        }
        pts[placed][0] = (float)x;
        pts[placed][1] = (float)y;
        placed++;
        misses = 0;
    }
}

void softmap_rotation(bool rotate, uint32_t sample, double *cs, double *sn)
{
    double a = rotate ? 2.0 * M_PI * (hash_u32(sample ^ 0x5bd1e995u) >> 8) / 16777216.0 : 0.0;
    *cs = cos(a);
    *sn = sin(a);
}
