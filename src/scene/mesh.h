/* mesh.h -- indexed triangle meshes and the strict OBJ/PLY readers.
 * Readers report file and line (or element index for binary PLY) on every
 * error: unreadable file, malformed number, non-finite coordinate, face index
 * out of range, empty mesh. Positions are in the file's object space. */
#ifndef SL_MESH_H
#define SL_MESH_H
#include <stdint.h>
#include "core/error.h"
#include "core/vec.h"

typedef struct Mesh {
    vec3 *positions;    /* num_vertices, object space */
    vec3 *normals;      /* num_vertices, unit shading normals (area-weighted face normals) */
    uint32_t *indices;  /* 3 * num_triangles, counter-clockwise = front */
    int num_vertices;
    int num_triangles;
} Mesh;

/* Load by extension (.obj or .ply, case-insensitive). On failure *mesh is
 * left empty and err says "<path>:<line>: <problem>". */
bool mesh_load(const char *path, Mesh *mesh, Error *err);
bool mesh_load_obj(const char *path, Mesh *mesh, Error *err);
bool mesh_load_ply(const char *path, Mesh *mesh, Error *err);

/* Allocate positions/normals/indices for the given counts (zeroed). */
bool mesh_alloc(Mesh *mesh, int num_vertices, int num_triangles, Error *err);
/* Area-weighted vertex normals from the faces; vertices of no (or only
 * zero-area) faces get (0, 0, 1). */
void mesh_compute_normals(Mesh *mesh);
void mesh_free(Mesh *mesh);

#endif
