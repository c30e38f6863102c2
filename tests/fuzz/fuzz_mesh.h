/* fuzz_mesh.h -- the body of the OBJ and PLY harnesses: a mesh that loads
 * has finite vertices and in-range indices; a refusal carries a message. */
#ifndef SL_FUZZ_MESH_H
#define SL_FUZZ_MESH_H
#include "fuzz_util.h"
#include "scene/mesh.h"

static int fuzz_mesh(const uint8_t *data, size_t size, const char *ext, bool (*load)(const char *, Mesh *, Error *))
{
    const char *path = fuzz_file(data, size, ext);
    if (!path) return 0;
    Mesh m;
    Error err = {{0}};
    if (!load(path, &m, &err)) {
        if (!err.msg[0]) abort();
        return 0;
    }
    for (int v = 0; v < m.num_vertices; v++)
        if (!v3_finite(m.positions[v]) || !v3_finite(m.normals[v])) abort();
    for (long i = 0; i < 3L * m.num_triangles; i++)
        if (m.indices[i] >= (uint32_t)m.num_vertices) abort();
    mesh_free(&m);
    return 0;
}

#endif
