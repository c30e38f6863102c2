/* silhouette.h -- edge adjacency of the casters and their possible
 * silhouette edges for one point: the light's centre (course §2.2,
 * "Geometry"; Crow 1977). A keyed frame resource, built once per light.
 *
 * Adjacency: positions that are equal (bit for bit, -0 = +0) are welded, so
 * a mesh whose faces carry their own vertex copies is still one surface;
 * every undirected welded edge counts the triangles that use it. An edge of
 * one triangle is open, of more than two non-manifold, of two that traverse
 * it the same way misoriented; an object without such edges is closed.
 * Zero-area triangles (welded corners coincide, or the cross product is 0 in
 * double) are skipped and counted.
 *
 * Silhouette (course §2.2): each triangle is given a weight w toward the
 * centre L: on a closed object w = -1 where the triangle's back faces L and 0
 * elsewhere (only light-silhouette edges are extruded, and the volume starts
 * at the dark side, which bounds the same shadow as the course's light-facing
 * front cap, but no lit surface lies on a cap); on any other object
 * w = +1 where the front faces L and -1 where the back does (Bergeron 1986:
 * the triangle counts as turned toward the light, so a shared silhouette edge
 * gets 2 quads and an open edge 1), and 0 for a triangle edge-on to L
 * (grazing: it casts nothing). An edge's multiplicity is the sum over its
 * triangles of w times +1 (the triangle traverses it lo -> hi) or -1; the
 * possible silhouette edges are those where it is not 0, stored directed so
 * that their multiplicity is positive. The caps of a volume are the
 * triangles with w != 0, turned toward L when w < 0. */
#ifndef SL_SILHOUETTE_H
#define SL_SILHOUETTE_H
#include <stdint.h>
#include "resources/resources.h"
#include "scene/scene.h"

/* A possible silhouette edge a -> b (world space) as the triangles turned
 * toward the light traverse it, extruded `count` times (>= 1). */
typedef struct SilEdge {
    vec3 a, b;
    int32_t count;
    int32_t object; /* index into Scene.objects */
} SilEdge;

/* What the adjacency found on one caster object. */
typedef struct SilObject {
    int object;                 /* index into Scene.objects */
    int triangles, degenerate;  /* degenerate: zero area, skipped */
    int grazing;                /* edge-on to the light's centre: weight 0 */
    long edges, open_edges, nonmanifold_edges, misoriented_edges;
    long silhouette_edges;      /* possible silhouette edges for the centre */
    bool closed;                /* no open, non-manifold or misoriented edge */
    int8_t *weight;             /* per triangle: w of the header comment */
} SilObject;

typedef struct Silhouette {
    uint64_t key;
    /* The light's centre in homogeneous world coordinates: (p, 1) for a
     * light with a position, (-direction, 0) for a directional light. */
    double light[4];
    int num_objects;            /* casters with at least one triangle */
    SilObject *objects;
    int num_edges;              /* possible silhouette edges of every caster */
    SilEdge *edges;
} Silhouette;

const Silhouette *res_silhouette(ResourceManager *rm, const Scene *scene, int light_index, Error *err);

/* Which weights an object that is not closed gets. SIL_BERGERON: the
 * header's rule (+1 front, -1 back), so a shell counts twice where a ray
 * crosses both its layers, which a count-not-zero test does not see but an
 * integral of counts does (soft shadow volumes). SIL_SHELLS_DARK_SIDE: a
 * shell, an object without non-manifold or misoriented edges whose open
 * edges are under 1/SIL_SHELL_OPEN of its edges (the bunny: 223 of 104k; a
 * plane: 4 of 5), takes the closed rule (its back faces, -1), so it counts
 * once, and a ray through a hole past no back face is not counted; other
 * objects keep Bergeron's rule. */
typedef enum SilRule { SIL_BERGERON, SIL_SHELLS_DARK_SIDE } SilRule;
#define SIL_SHELL_OPEN 64

/* The same for any homogeneous point L (silhouette.h's `light`), e.g. the
 * centre of a patch of an area light (soft shadow volumes' light splitting);
 * keyed by the casters, L and the rule, `desc` naming the point in the
 * resource log. */
const Silhouette *res_silhouette_point(ResourceManager *rm, const Scene *scene, const double L[4], SilRule rule,
                                       const char *desc, Error *err);

/* Build one without a manager (tests, the bench); free with silhouette_free. */
Silhouette *silhouette_build(const Scene *scene, int light_index, Error *err);
Silhouette *silhouette_build_point(const Scene *scene, const double L[4], SilRule rule, Error *err);
void silhouette_free(Silhouette *sil);

/* "'name': 12 open, 1 non-manifold edges, 2 zero-area triangles skipped"
 * (counts that are 0 left out) for each object that is not closed or
 * skipped triangles, "; " between them, or "" when every caster is a closed
 * 2-manifold without zero-area triangles. */
void silhouette_report(const Silhouette *sil, const Scene *scene, char *out, size_t n);

#endif
