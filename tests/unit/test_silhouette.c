/* test_silhouette.c -- the edge adjacency and possible silhouette edges of
 * resources/geometry/silhouette.h on a closed box, a sphere, an open plane and a
 * non-manifold fan with a degenerate triangle: edge counts from the
 * geometry, and the silhouette's defining property (it is the boundary of the
 * triangles turned toward the light, so at every welded vertex as many edge
 * ends arrive as leave, counted with their multiplicity). ~10 ms. */
#include <string.h>
#include "fixtures.h"
#include "resources/geometry/silhouette.h"
#include "test.h"

#define SCENE_HEAD                                                                                         \
    "return { name = 'sil', camera = { position = {0, 3, 6}, target = {0, 0, 0}, up = {0, 1, 0}, fov = 45," \
    " width = 16, height = 12 }, lights = { { type = 'point', position = {3, 4, 5}, color = {1, 1, 1}," \
    " intensity = 1 } }, objects = { "

static Silhouette *build(const char *name, const char *objects, Lab **lab)
{
    char text[2048];
    snprintf(text, sizeof text, SCENE_HEAD "%s } }", objects);
    *lab = fixture_lab(name, text);
    if (!*lab) return NULL;
    Error err;
    Silhouette *sil = silhouette_build(lab_scene(*lab), 0, &err);
    if (!sil) printf("    %s\n", err.msg);
    return sil;
}

/* Net count of edge ends at position p: +count leaving, -count arriving. */
static long net_at(const Silhouette *sil, vec3 p)
{
    long net = 0;
    for (int i = 0; i < sil->num_edges; i++) {
        const SilEdge *e = &sil->edges[i];
        net += (memcmp(&e->a, &p, sizeof p) == 0) ? e->count : 0;
        net -= (memcmp(&e->b, &p, sizeof p) == 0) ? e->count : 0;
    }
    return net;
}

static bool silhouette_is_a_cycle(const Silhouette *sil)
{
    for (int i = 0; i < sil->num_edges; i++)
        if (net_at(sil, sil->edges[i].a) != 0 || net_at(sil, sil->edges[i].b) != 0) return false;
    return true;
}

TEST(test_silhouette_closed_box)
{
    Lab *lab;
    Silhouette *sil = build("box.lua", "{ name = 'box', shape = 'box', size = {1, 1, 1} }", &lab);
    CHECK(sil && sil->num_objects == 1);
    const SilObject *so = &sil->objects[0];
    /* 24 vertices (4 per face) weld to the 8 corners: 12 cube edges + 6 face diagonals */
    CHECK(so->triangles == 12 && so->degenerate == 0 && so->grazing == 0);
    CHECK(so->edges == 18 && so->open_edges == 0 && so->nonmanifold_edges == 0 && so->misoriented_edges == 0);
    CHECK(so->closed);
    /* the light at (3, 4, 5) sees the +x, +y, +z faces: a hexagon of 6 edges, each once */
    CHECK(so->silhouette_edges == 6 && sil->num_edges == 6);
    for (int i = 0; i < sil->num_edges; i++) CHECK(sil->edges[i].count == 1);
    CHECK(silhouette_is_a_cycle(sil));
    char report[256];
    silhouette_report(sil, lab_scene(lab), report, sizeof report);
    CHECK(report[0] == '\0');
    silhouette_free(sil);
    lab_close(lab);
}

TEST(test_silhouette_sphere_is_closed_after_welding)
{
    Lab *lab;
    Silhouette *sil = build("sphere.lua", "{ name = 'ball', shape = 'sphere', radius = 1, segments = 16 }", &lab);
    CHECK(sil && sil->num_objects == 1);
    const SilObject *so = &sil->objects[0];
    printf("    %d triangles, %d degenerate, %ld edges, %ld silhouette edges\n", so->triangles, so->degenerate,
           so->edges, so->silhouette_edges);
    /* the grid's pole rows collapse to a point (the south pole too, where sinf(PI_F) != 0 once left a
     * hole): one triangle of each of the 16 quads at each pole has zero area */
    CHECK(so->degenerate == 2 * 16);
    /* Euler: V - E + F = 2 for the welded sphere, E = 3F/2 */
    int faces = so->triangles - so->degenerate;
    CHECK(2 * so->edges == 3L * faces);
    CHECK(so->closed && so->open_edges == 0 && so->nonmanifold_edges == 0);
    CHECK(so->silhouette_edges >= 16);
    for (int i = 0; i < sil->num_edges; i++) CHECK(sil->edges[i].count == 1);
    CHECK(silhouette_is_a_cycle(sil));
    silhouette_free(sil);
    lab_close(lab);
}

TEST(test_silhouette_open_plane_extrudes_its_border_from_either_side)
{
    Lab *lab;
    const char *plane = "{ name = 'ground', shape = 'plane', size = {4, 4} }";
    Silhouette *sil = build("plane.lua", plane, &lab);
    CHECK(sil && sil->num_objects == 1);
    const SilObject *so = &sil->objects[0];
    CHECK(so->triangles == 2 && so->edges == 5 && so->open_edges == 4 && !so->closed);
    /* Bergeron: the 4 open edges once each, the shared diagonal not at all */
    CHECK(so->silhouette_edges == 4);
    for (int i = 0; i < sil->num_edges; i++) CHECK(sil->edges[i].count == 1);
    CHECK(silhouette_is_a_cycle(sil));
    char report[256];
    silhouette_report(sil, lab_scene(lab), report, sizeof report);
    CHECK_MSG(strcmp(report, "'ground': 4 open edges") == 0, "report: %s", report);
    /* from below, the triangles count turned toward the light: the same border, reversed */
    vec3 a = sil->edges[0].a, b = sil->edges[0].b;
    silhouette_free(sil);
    lab_close(lab);
    Error err;
    const char *over[] = {"lights[1].position={1,-3,1}"};
    char text[1024];
    snprintf(text, sizeof text, SCENE_HEAD "%s } }", plane);
    Lab *l2 = lab_open(fixture_file("below.lua", text), over, 1, &err);
    CHECK_MSG(l2, "%s", err.msg);
    sil = silhouette_build(lab_scene(l2), 0, &err);
    CHECK(sil && sil->num_edges == 4);
    bool reversed = false;
    for (int i = 0; i < sil->num_edges; i++)
        reversed |= memcmp(&sil->edges[i].a, &b, sizeof b) == 0 && memcmp(&sil->edges[i].b, &a, sizeof a) == 0;
    CHECK(reversed);
    silhouette_free(sil);
    lab_close(l2);
}

TEST(test_silhouette_counts_non_manifold_and_degenerate_triangles)
{
    /* three triangles on the edge (0,0,0)-(1,0,0), and one with a repeated corner */
    fixture_file("fan.obj", "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0.2\nv 0.5 0 1\n"
                            "f 1 2 3\nf 2 1 4\nf 1 2 5\nf 3 3 4\n");
    Lab *lab;
    Silhouette *sil = build("fan.lua", "{ name = 'fan', shape = 'mesh', model = 'fan.obj' }", &lab);
    CHECK(sil && sil->num_objects == 1);
    const SilObject *so = &sil->objects[0];
    CHECK(so->triangles == 4 && so->degenerate == 1);
    CHECK(so->edges == 7 && so->nonmanifold_edges == 1 && so->open_edges == 6 && !so->closed);
    CHECK(silhouette_is_a_cycle(sil));
    char report[256];
    silhouette_report(sil, lab_scene(lab), report, sizeof report);
    CHECK_MSG(strcmp(report, "'fan': 6 open, 1 non-manifold edges, 1 zero-area triangles skipped") == 0, "report: %s",
              report);
    silhouette_free(sil);
    lab_close(lab);
}
