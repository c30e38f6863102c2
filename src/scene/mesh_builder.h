/* mesh_builder.h -- growable vertex and triangle arrays shared by the mesh
 * readers, turned into a Mesh at the end. Appends return NULL on success or
 * a short reason ("out of memory", "too many triangles ...") that the reader
 * prefixes with its file and line. */
#ifndef SL_MESH_BUILDER_H
#define SL_MESH_BUILDER_H
#include <stddef.h>
#include "scene/mesh.h"

typedef struct MeshBuilder {
    vec3 *pos;
    uint32_t *idx; /* three per triangle */
    size_t num_pos, num_idx, cap_pos, cap_idx;
} MeshBuilder;

const char *mb_add_vertex(MeshBuilder *b, vec3 p);
const char *mb_add_triangle(MeshBuilder *b, uint32_t i0, uint32_t i1, uint32_t i2);
/* Copy into mesh and compute normals; "<path>: no triangles" when empty. */
bool mb_finish(const MeshBuilder *b, const char *path, Mesh *mesh, Error *err);
void mb_free(MeshBuilder *b);

#endif
