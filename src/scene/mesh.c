/* mesh.c -- Mesh storage: allocation, area-weighted vertex normals and
 * freeing, plus mesh_load, which picks the OBJ or PLY reader by the file's
 * extension (case-insensitive). The readers live in mesh_obj.c and
 * mesh_ply.c. */
#include "scene/mesh.h"
#include <stdlib.h>
#include <string.h>
#include <strings.h>

bool mesh_load(const char *path, Mesh *mesh, Error *err)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (dot && strcasecmp(dot, ".obj") == 0) return mesh_load_obj(path, mesh, err);
    if (dot && strcasecmp(dot, ".ply") == 0) return mesh_load_ply(path, mesh, err);
    memset(mesh, 0, sizeof *mesh);
    return error_set(err, "%s: unknown mesh file extension (accepted: .obj, .ply)", path);
}

bool mesh_alloc(Mesh *mesh, int num_vertices, int num_triangles, Error *err)
{
    memset(mesh, 0, sizeof *mesh);
    if (num_vertices < 0 || num_triangles < 0)
        return error_set(err, "invalid mesh size: %d vertices, %d triangles", num_vertices, num_triangles);
    /* At least one element each, so that NULL always means out of memory. */
    size_t nv = num_vertices > 0 ? (size_t)num_vertices : 1;
    size_t nt = num_triangles > 0 ? (size_t)num_triangles : 1;
    mesh->positions = calloc(nv, sizeof(vec3));
    mesh->normals = calloc(nv, sizeof(vec3));
    mesh->indices = calloc(nt, 3 * sizeof(uint32_t));
    if (!mesh->positions || !mesh->normals || !mesh->indices) {
        mesh_free(mesh);
        return error_set(err, "out of memory for a mesh of %d vertices and %d triangles", num_vertices,
                         num_triangles);
    }
    mesh->num_vertices = num_vertices;
    mesh->num_triangles = num_triangles;
    return true;
}

void mesh_compute_normals(Mesh *mesh)
{
    vec3 *n = mesh->normals;
    const vec3 *p = mesh->positions;
    for (int i = 0; i < mesh->num_vertices; i++) n[i] = v3(0, 0, 0);
    for (int t = 0; t < mesh->num_triangles; t++) {
        const uint32_t *f = &mesh->indices[3 * (size_t)t];
        /* |cross| is twice the area: summing it weights faces by area. */
        vec3 w = v3_cross(v3_sub(p[f[1]], p[f[0]]), v3_sub(p[f[2]], p[f[0]]));
        for (int k = 0; k < 3; k++) n[f[k]] = v3_add(n[f[k]], w);
    }
    for (int i = 0; i < mesh->num_vertices; i++) n[i] = v3_normalize_or(n[i], v3(0, 0, 1));
}

void mesh_free(Mesh *mesh)
{
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}
