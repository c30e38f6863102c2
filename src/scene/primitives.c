/* primitives.c -- procedural meshes in object space: plane, box, sphere,
 * cylinder, cone, torus, disk and heightfield. All are closed where the shape
 * is (box, sphere, cylinder, cone, torus), counter-clockwise seen from outside,
 * with +Y up. Each is a (u, v) grid mapped by a shape function, so one grid
 * builder serves every revolved shape. */
#include "scene/scene.h"
#include <math.h>

#define PI_F 3.14159265358979323846f

/* A shape maps grid coordinates (s, t) in [0,1]^2 to object space; revolved
 * shapes sweep a profile at height t around +Y by angle 2*pi*s. */
typedef vec3 (*GridFn)(float s, float t, const float *params);

static bool grid_mesh(Mesh *m, int nu, int nv, GridFn fn, const float *params, Error *err)
{
    if (!mesh_alloc(m, (nu + 1) * (nv + 1), 2 * nu * nv, err)) return false;
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++)
            m->positions[j * (nu + 1) + i] = fn((float)i / (float)nu, (float)j / (float)nv, params);
    uint32_t *ix = m->indices;
    for (int j = 0; j < nv; j++) {
        for (int i = 0; i < nu; i++) {
            uint32_t a = (uint32_t)(j * (nu + 1) + i), b = a + 1;
            uint32_t c = a + (uint32_t)(nu + 1), d = c + 1;
            *ix++ = a; *ix++ = c; *ix++ = b;
            *ix++ = b; *ix++ = c; *ix++ = d;
        }
    }
    return true;
}

/* Revolve the point at radius r, height y by angle 2*pi*s (counter-clockwise
 * seen from +Y, so the grid winding faces outwards for t running downwards). */
static vec3 revolve(float s, float r, float y)
{
    float a = 2.0f * PI_F * (s >= 1.0f ? 0.0f : s);
    return v3(r * sinf(a), y, r * cosf(a));
}

static vec3 sphere_fn(float s, float t, const float *p)
{
    float th = PI_F * t; /* t = 0 at the north pole */
    /* sinf(PI_F) is -8.7e-8, not 0: each pole is one point, or the mesh has a hole there */
    float r = t <= 0.0f || t >= 1.0f ? 0.0f : p[0] * sinf(th);
    return revolve(s, r, p[0] * cosf(th));
}

/* Cylinder and cone share one profile: top cap centre, top rim, bottom rim,
 * bottom cap centre; p = {bottom radius, top radius, height}. Centred on y. */
static vec3 frustum_fn(float s, float t, const float *p)
{
    float h = 0.5f * p[2];
    int row = (int)lroundf(t * 3.0f);
    switch (row) {
    case 0: return v3(0.0f, h, 0.0f);
    case 1: return revolve(s, p[1], h);
    case 2: return revolve(s, p[0], -h);
    default: return v3(0.0f, -h, 0.0f);
    }
}

static vec3 torus_fn(float s, float t, const float *p)
{
    float b = 2.0f * PI_F * (t >= 1.0f ? 0.0f : t);
    return revolve(s, p[0] + p[1] * cosf(b), -p[1] * sinf(b)); /* downwards outside: outward winding */
}

static vec3 disk_fn(float s, float t, const float *p) { return revolve(s, p[0] * t, 0.0f); }

static vec3 plane_fn(float s, float t, const float *p)
{
    return v3((s - 0.5f) * p[0], 0.0f, (t - 0.5f) * p[1]);
}

static bool check_segments(int segments, Error *err)
{
    if (segments < 3 || segments > 4096) return error_set(err, "segments = %d outside [3, 4096]", segments);
    return true;
}

bool prim_plane(Mesh *m, float size_x, float size_z, Error *err)
{
    float p[2] = {size_x, size_z};
    if (!grid_mesh(m, 1, 1, plane_fn, p, err)) return false;
    mesh_compute_normals(m);
    return true;
}

bool prim_sphere(Mesh *m, float radius, int segments, Error *err)
{
    float p[1] = {radius};
    if (!check_segments(segments, err) || !grid_mesh(m, segments, segments / 2 + 1, sphere_fn, p, err)) return false;
    mesh_compute_normals(m);
    return true;
}

static bool frustum(Mesh *m, float r_bottom, float r_top, float height, int segments, Error *err)
{
    float p[3] = {r_bottom, r_top, height};
    if (!check_segments(segments, err) || !grid_mesh(m, segments, 3, frustum_fn, p, err)) return false;
    mesh_compute_normals(m);
    return true;
}

bool prim_cylinder(Mesh *m, float radius, float height, int segments, Error *err)
{
    return frustum(m, radius, radius, height, segments, err);
}

bool prim_cone(Mesh *m, float radius, float height, int segments, Error *err)
{
    return frustum(m, radius, 0.0f, height, segments, err);
}

bool prim_torus(Mesh *m, float major, float minor, int segments, Error *err)
{
    float p[2] = {major, minor};
    if (!check_segments(segments, err) || !grid_mesh(m, segments, segments / 2 + 1, torus_fn, p, err)) return false;
    mesh_compute_normals(m);
    return true;
}

bool prim_disk(Mesh *m, float radius, int segments, Error *err)
{
    float p[1] = {radius};
    if (!check_segments(segments, err) || !grid_mesh(m, segments, 1, disk_fn, p, err)) return false;
    mesh_compute_normals(m);
    return true;
}

/* Box: six faces, four vertices each (sharp normals), outward winding. */
bool prim_box(Mesh *m, vec3 size, Error *err)
{
    if (!mesh_alloc(m, 24, 12, err)) return false;
    vec3 h = v3_scale(size, 0.5f);
    static const float axes[6][3][3] = {
        /* normal, u, v  with u x v = normal */
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    static const float corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int f = 0; f < 6; f++) {
        vec3 n = v3(axes[f][0][0], axes[f][0][1], axes[f][0][2]);
        vec3 u = v3(axes[f][1][0], axes[f][1][1], axes[f][1][2]);
        vec3 v = v3(axes[f][2][0], axes[f][2][1], axes[f][2][2]);
        for (int c = 0; c < 4; c++) {
            vec3 p = v3_add(n, v3_add(v3_scale(u, corner[c][0]), v3_scale(v, corner[c][1])));
            m->positions[4 * f + c] = v3_mul(p, h);
        }
        uint32_t b = (uint32_t)(4 * f);
        uint32_t tri[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        for (int k = 0; k < 6; k++) m->indices[6 * f + k] = tri[k];
    }
    mesh_compute_normals(m);
    return true;
}

bool prim_heightfield(Mesh *m, float size_x, float size_z, int nx, int nz, const float *heights, Error *err)
{
    float p[2] = {size_x, size_z};
    if (!grid_mesh(m, nx, nz, plane_fn, p, err)) return false;
    for (int i = 0; i < (nx + 1) * (nz + 1); i++) m->positions[i].y = heights[i];
    mesh_compute_normals(m);
    return true;
}
