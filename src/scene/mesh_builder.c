/* mesh_builder.c -- growable arrays for the mesh readers (see mesh_builder.h). */
#include "scene/mesh_builder.h"
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Make room for `extra` more elements of `size` bytes, doubling. */
static bool reserve(void **data, size_t *cap, size_t len, size_t extra, size_t size)
{
    if (*cap - len >= extra) return true;
    size_t n = *cap ? *cap : 4096;
    while (n - len < extra) {
        if (n > SIZE_MAX / 2 / size) return false;
        n *= 2;
    }
    void *p = realloc(*data, n * size);
    if (!p) return false;
    *data = p;
    *cap = n;
    return true;
}

const char *mb_add_vertex(MeshBuilder *b, vec3 p)
{
    if (b->num_pos >= INT_MAX) return "too many vertices (limit 2147483647)";
    if (!reserve((void **)&b->pos, &b->cap_pos, b->num_pos, 1, sizeof(vec3))) return "out of memory";
    b->pos[b->num_pos++] = p;
    return NULL;
}

const char *mb_add_triangle(MeshBuilder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    if (b->num_idx / 3 >= INT_MAX) return "too many triangles (limit 2147483647)";
    if (!reserve((void **)&b->idx, &b->cap_idx, b->num_idx, 3, sizeof(uint32_t))) return "out of memory";
    b->idx[b->num_idx++] = i0;
    b->idx[b->num_idx++] = i1;
    b->idx[b->num_idx++] = i2;
    return NULL;
}

bool mb_finish(const MeshBuilder *b, const char *path, Mesh *mesh, Error *err)
{
    if (b->num_idx == 0) return error_set(err, "%s: no triangles", path);
    if (!mesh_alloc(mesh, (int)b->num_pos, (int)(b->num_idx / 3), err)) return error_prefix(err, "%s: ", path);
    memcpy(mesh->positions, b->pos, b->num_pos * sizeof(vec3));
    memcpy(mesh->indices, b->idx, b->num_idx * sizeof(uint32_t));
    mesh_compute_normals(mesh);
    return true;
}

void mb_free(MeshBuilder *b)
{
    free(b->pos);
    free(b->idx);
    *b = (MeshBuilder){0};
}
