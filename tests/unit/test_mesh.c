/* test_mesh.c -- the OBJ and PLY readers and the Mesh helpers: good files
 * (OBJ face forms, quads, negative indices; ascii and binary PLY; the cubes in
 * tests/data/meshes), every rejected input with its "<file>:<line>: <problem>"
 * message, area-weighted normals, and the Stanford bunny when it is present. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/fsutil.h"
#include "scene/mesh.h"
#include "test.h"

#define PATH_LEN 512

/* Write n bytes to test_tmpdir()/name; path receives the full name. */
static bool write_tmp(const char *name, const void *data, size_t n, char *path)
{
    snprintf(path, PATH_LEN, "%s/%s", test_tmpdir(), name);
    FILE *fp = fopen(path, "wb");
    if (!fp) return false;
    bool ok = fwrite(data, 1, n, fp) == n;
    return fclose(fp) == 0 && ok;
}

static bool load_text(const char *name, const char *text, Mesh *m, Error *err)
{
    char path[PATH_LEN];
    return write_tmp(name, text, strlen(text), path) && mesh_load(path, m, err);
}

static bool mesh_is_empty(const Mesh *m)
{
    return !m->positions && !m->normals && !m->indices && m->num_vertices == 0 && m->num_triangles == 0;
}

/* Loading these bytes saved as `name` must fail with a message containing
 * `want` and leave the mesh empty. */
static void check_load_error(const char *name, const void *data, size_t n, const char *want)
{
    char path[PATH_LEN];
    CHECK(write_tmp(name, data, n, path));
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(!mesh_load(path, &m, &err), "%s loaded; expected error '%s'", name, want);
    CHECK_MSG(strstr(err.msg, want), "error '%s' lacks '%s'", err.msg, want);
    CHECK(mesh_is_empty(&m));
}

static bool tri_is(const Mesh *m, int t, uint32_t a, uint32_t b, uint32_t c)
{
    const uint32_t *f = &m->indices[3 * t];
    return f[0] == a && f[1] == b && f[2] == c;
}

static bool normals_are(const Mesh *m, vec3 n)
{
    for (int i = 0; i < m->num_vertices; i++)
        if (v3_len(v3_sub(m->normals[i], n)) > 1e-6f) return false;
    return true;
}

/* Signed volume (positive when faces are counter-clockwise seen from outside). */
static double mesh_volume(const Mesh *m)
{
    double v = 0;
    for (int t = 0; t < m->num_triangles; t++) {
        const uint32_t *f = &m->indices[3 * t];
        v += v3_dot(m->positions[f[0]], v3_cross(m->positions[f[1]], m->positions[f[2]])) / 6.0;
    }
    return v;
}

TEST(mesh_obj_triangle)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("tri.obj",
                        "# a triangle\nv 0 0 0\nv 2 0 0 1.0\nv 0 2.5e0 -0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                        "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n",
                        &m, &err),
              "%s", err.msg);
    CHECK(m.num_vertices == 3 && m.num_triangles == 1);
    CHECK(tri_is(&m, 0, 0, 1, 2));
    CHECK_NEAR(m.positions[1].x, 2.0, 0);
    CHECK_NEAR(m.positions[2].y, 2.5, 0);
    CHECK(normals_are(&m, v3(0, 0, 1)));
    mesh_free(&m);
    CHECK(mesh_is_empty(&m));
}

TEST(mesh_obj_face_forms)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("forms.obj",
                        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                        "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//1\nf 1/1/1 2/2/1 3/3/1\n",
                        &m, &err),
              "%s", err.msg);
    CHECK(m.num_triangles == 4);
    for (int t = 0; t < 4; t++) CHECK(tri_is(&m, t, 0, 1, 2));
    mesh_free(&m);
}

TEST(mesh_obj_polygon_fan)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\nf 1 2 3 4\nf 1 2 3 4 5\n",
                        &m, &err),
              "%s", err.msg);
    CHECK(m.num_vertices == 5 && m.num_triangles == 5);
    CHECK(tri_is(&m, 0, 0, 1, 2) && tri_is(&m, 1, 0, 2, 3));
    CHECK(tri_is(&m, 2, 0, 1, 2) && tri_is(&m, 3, 0, 2, 3) && tri_is(&m, 4, 0, 3, 4));
    mesh_free(&m);
}

TEST(mesh_obj_negative_indices)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("neg.obj",
                        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf -3/-1/-1 -2/-1/-1 -1/-1/-1\n"
                        "v 1 1 0\nf -3 -1 -2\n",
                        &m, &err),
              "%s", err.msg);
    CHECK(m.num_vertices == 4 && m.num_triangles == 2);
    CHECK(tri_is(&m, 0, 0, 1, 2) && tri_is(&m, 1, 1, 3, 2));
    mesh_free(&m);
}

TEST(mesh_obj_ignored_statements)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("ign.obj",
                        "mtllib a.mtl\r\n\r\n  # indented comment\r\no thing\r\ng group\r\ns 1\r\n"
                        "usemtl red\r\n\tv 0 0 0\r\nv 1 0 0 # trailing comment\r\nv 0 1 0\r\n"
                        "l 1 2\r\np 3\r\nf 1 2 3\r\n",
                        &m, &err),
              "%s", err.msg);
    CHECK(m.num_vertices == 3 && m.num_triangles == 1);
    mesh_free(&m);
}

TEST(mesh_obj_degenerate_kept)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("degen.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 9 9 9\nf 1 2 3\nf 1 2 4\nf 2 2 2\n", &m,
                        &err),
              "%s", err.msg);
    CHECK(m.num_vertices == 5 && m.num_triangles == 3);
    CHECK(tri_is(&m, 1, 0, 1, 3) && tri_is(&m, 2, 1, 1, 1));
    /* vertex 3 lies only on a zero-area face, vertex 4 on none */
    CHECK(normals_are(&m, v3(0, 0, 1)));
    mesh_free(&m);
}

TEST(mesh_obj_errors)
{
    static const struct { const char *text, *want; } cases[] = {
        {"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", "bad.obj:3: vertex coordinate is not finite (nan)"},
        {"v 0 0 1e999\n", "bad.obj:1: vertex coordinate is not finite (1e999)"},
        {"vn 0 0 -inf\n", "bad.obj:1: normal component is not finite (-inf)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\nf 1 2 9\n",
         "bad.obj:9: face index 9 out of range [1, 8]"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "bad.obj:4: face index 0 out of range [1, 3]"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "bad.obj:4: face index -4 out of range [-3, -1]"},
        {"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "bad.obj:1: face index 1 out of range [1, 0]"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", "bad.obj:5: texture index 2 out of range [1, 1]"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", "bad.obj:4: normal index 1 out of range [1, 0]"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2/ 3/\n", "bad.obj:4: malformed face vertex '1/'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n", "bad.obj:4: malformed face vertex '3x'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 +3\n", "bad.obj:4: malformed face vertex '+3'"},
        {"v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj:3: face has 2 vertices, need at least 3"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "bad.obj: no triangles"},
        {"# nothing\n\n", "bad.obj: no triangles"},
        {"", "bad.obj: no triangles"},
        {"v 0 0 0\nvp 0.5 0.5\n", "bad.obj:2: unknown keyword 'vp'"},
        {"v 0 0\n", "bad.obj:1: expected 3 numbers after 'v', got 2"},
        {"v 0 0 0 1 1\n", "bad.obj:1: expected at most 4 numbers after 'v'"},
        {"vt\n", "bad.obj:1: expected 1 number after 'vt', got 0"},
        {"vn 0 1\n", "bad.obj:1: expected 3 numbers after 'vn', got 2"},
        {"\n\nv 0 0 0x\n", "bad.obj:3: malformed number '0x' after 'v'"},
        {"v 1,5 0 0\n", "bad.obj:1: malformed number '1,5' after 'v'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        check_load_error("bad.obj", cases[i].text, strlen(cases[i].text), cases[i].want);
    static const char nul[] = "v 0 0 0\nv 1\0 0 0\nv 0 1 0\nf 1 2 3\n";
    check_load_error("bad.obj", nul, sizeof nul - 1, "bad.obj:2: unexpected NUL byte");
}

TEST(mesh_load_unreadable)
{
    char path[PATH_LEN];
    snprintf(path, sizeof path, "%s/missing.obj", test_tmpdir());
    Mesh m;
    Error err = {{0}};
    CHECK(!mesh_load(path, &m, &err));
    CHECK_MSG(strstr(err.msg, path), "%s", err.msg);
    CHECK(mesh_is_empty(&m));
    snprintf(path, sizeof path, "%s/missing.ply", test_tmpdir());
    CHECK(!mesh_load(path, &m, &err));
    CHECK_MSG(strstr(err.msg, path), "%s", err.msg);
    CHECK(mesh_is_empty(&m));
}

TEST(mesh_load_extension)
{
    static const char tri[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    char path[PATH_LEN];
    Mesh m;
    Error err = {{0}};
    CHECK(write_tmp("UPPER.OBJ", tri, sizeof tri - 1, path));
    CHECK_MSG(mesh_load(path, &m, &err), "%s", err.msg);
    CHECK(m.num_triangles == 1);
    mesh_free(&m);
    const char *bad[] = {"mesh.stl", "mesh", "dir.obj/mesh"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(!mesh_load(bad[i], &m, &err));
        CHECK_MSG(strstr(err.msg, bad[i]) && strstr(err.msg, ".obj, .ply"), "%s", err.msg);
        CHECK(mesh_is_empty(&m));
    }
}

TEST(mesh_cube_files)
{
    const char *files[] = {"tests/data/meshes/cube.obj", "tests/data/meshes/cube.ply"};
    for (int i = 0; i < 2; i++) {
        Mesh m;
        Error err = {{0}};
        CHECK_MSG(mesh_load(files[i], &m, &err), "%s", err.msg);
        CHECK(m.num_vertices == 8 && m.num_triangles == 12);
        CHECK_NEAR(mesh_volume(&m), 8.0, 1e-9);
        for (int v = 0; v < 8; v++) {
            vec3 p = m.positions[v], n = m.normals[v];
            CHECK_NEAR(v3_len(n), 1.0, 1e-6);
            CHECK_MSG(n.x * p.x > 0 && n.y * p.y > 0 && n.z * p.z > 0, "%s: normal %d points inward", files[i], v);
        }
        mesh_free(&m);
    }
}

TEST(mesh_normals_area_weighted)
{
    Mesh m;
    Error err = {{0}};
    CHECK(mesh_alloc(&m, 6, 2, &err));
    /* triangle 0: area 0.5 facing +z; triangle 1: area 2 facing +x; vertex 5 unused */
    const vec3 p[6] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 0, 2}, {0, 1, 0}};
    const uint32_t idx[6] = {0, 1, 2, 0, 3, 4};
    memcpy(m.positions, p, sizeof p);
    memcpy(m.indices, idx, sizeof idx);
    mesh_compute_normals(&m);
    CHECK_NEAR(m.normals[0].x, 4 / sqrt(17), 1e-6);
    CHECK_NEAR(m.normals[0].y, 0, 1e-6);
    CHECK_NEAR(m.normals[0].z, 1 / sqrt(17), 1e-6);
    CHECK_NEAR(m.normals[1].z, 1, 1e-6);
    CHECK_NEAR(m.normals[3].x, 1, 1e-6);
    CHECK_NEAR(m.normals[4].x, 1, 1e-6);
    CHECK_NEAR(m.normals[5].z, 1, 0);
    mesh_free(&m);
    CHECK(!mesh_alloc(&m, -1, 0, &err) && mesh_is_empty(&m));
}

static const char ascii_ply[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment a quad and a triangle\n"
    "obj_info from test_mesh.c\n"
    "element vertex 5\n"
    "property float x\n"
    "property float32 y\n"
    "property double z\n"
    "property uchar red\n"
    "property list uchar float extra\n"
    "element face 2\n"
    "property list uint8 int vertex_index\n"
    "property int flags\n"
    "element edge 1\n"
    "property int vertex1\n"
    "property int vertex2\n"
    "end_header\n"
    "0 0 0 255 0\n"
    "1 0 0 255 2 0.5 0.5\n"
    "1 1 0 0 0\n"
    "0 1 0 0 1 7\r\n"
    "0.5 0.5 1e-3 9 0\n"
    "\n"
    "4 0 1 2 3 7\n"
    "3 0 1 4 -1\n"
    "0 1\n";

TEST(mesh_ply_ascii)
{
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(load_text("quad.PLY", ascii_ply, &m, &err), "%s", err.msg);
    CHECK(m.num_vertices == 5 && m.num_triangles == 3);
    CHECK(tri_is(&m, 0, 0, 1, 2) && tri_is(&m, 1, 0, 2, 3) && tri_is(&m, 2, 0, 1, 4));
    CHECK_NEAR(m.positions[4].z, 1e-3, 1e-9);
    CHECK_NEAR(m.positions[2].y, 1, 0);
    mesh_free(&m);
}

typedef struct Bytes {
    unsigned char b[2048];
    size_t n;
    bool big;
} Bytes;

static void put(Bytes *o, uint64_t v, int size)
{
    for (int i = 0; i < size; i++) o->b[o->n + i] = (unsigned char)(v >> 8 * (o->big ? size - 1 - i : i));
    o->n += (size_t)size;
}

static void put_f32(Bytes *o, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put(o, u, 4);
}

static void put_f64(Bytes *o, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    put(o, u, 8);
}

/* A binary PLY of the unit square (a quad and a triangle) with vertex, face
 * and element data the reader must skip. x2 is vertex 2's x, last the last
 * face index. Returns the header length. */
static size_t binary_ply(Bytes *o, bool big, double x2, uint32_t last)
{
    static const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    int n = snprintf((char *)o->b, sizeof o->b,
                     "ply\nformat binary_%s_endian 1.0\ncomment skipped\nelement vertex 4\n"
                     "property double x\nproperty float32 y\nproperty float z\nproperty uchar red\n"
                     "property int16 flags\nelement material 2\nproperty list ushort int8 data\n"
                     "property uint id\nelement face 2\nproperty char kind\n"
                     "property list uchar uint vertex_indices\nproperty list uint8 float texcoord\n"
                     "end_header\n",
                     big ? "big" : "little");
    o->n = (size_t)n;
    o->big = big;
    for (int v = 0; v < 4; v++) {
        put_f64(o, v == 2 ? x2 : xy[v][0]);
        put_f32(o, (float)xy[v][1]);
        put_f32(o, 0.0f);
        put(o, 200, 1);
        put(o, (uint16_t)-5, 2);
    }
    static const uint8_t data[3] = {1, (uint8_t)-2, 3};
    put(o, 3, 2); /* material 0: data {1, -2, 3}, id 7; material 1: data {}, id 8 */
    for (int i = 0; i < 3; i++) put(o, data[i], 1);
    put(o, 7, 4);
    put(o, 0, 2);
    put(o, 8, 4);
    put(o, (uint8_t)-1, 1); /* face 0: kind -1, quad 0 1 2 3, texcoord {0.5, 0.5} */
    put(o, 4, 1);
    for (uint32_t i = 0; i < 4; i++) put(o, i, 4);
    put(o, 2, 1);
    put_f32(o, 0.5f);
    put_f32(o, 0.5f);
    put(o, 1, 1); /* face 1: kind 1, triangle 0 1 last, texcoord {} */
    put(o, 3, 1);
    put(o, 0, 4);
    put(o, 1, 4);
    put(o, last, 4);
    put(o, 0, 1);
    return (size_t)n;
}

TEST(mesh_ply_binary)
{
    for (int big = 0; big < 2; big++) {
        Bytes o;
        binary_ply(&o, big, 1.0, 3);
        char path[PATH_LEN];
        CHECK(write_tmp("bin.ply", o.b, o.n, path));
        Mesh m;
        Error err = {{0}};
        CHECK_MSG(mesh_load(path, &m, &err), "%s", err.msg);
        CHECK(m.num_vertices == 4 && m.num_triangles == 3);
        CHECK(tri_is(&m, 0, 0, 1, 2) && tri_is(&m, 1, 0, 2, 3) && tri_is(&m, 2, 0, 1, 3));
        CHECK(m.positions[2].x == 1 && m.positions[2].y == 1 && m.positions[3].y == 1);
        CHECK(normals_are(&m, v3(0, 0, 1)));
        mesh_free(&m);
    }
}

TEST(mesh_ply_binary_errors)
{
    Bytes o;
    size_t header = binary_ply(&o, false, NAN, 3);
    check_load_error("bad.ply", o.b, o.n, "bad.ply: vertex 2: coordinate 'x' is not finite (nan)");
    binary_ply(&o, true, 1e300, 3);
    check_load_error("bad.ply", o.b, o.n, "bad.ply: vertex 2: coordinate 'x' is not finite (1e+300)");
    binary_ply(&o, false, 1.0, 99);
    check_load_error("bad.ply", o.b, o.n, "bad.ply: face 1: index 99 out of range [0, 3]");
    binary_ply(&o, false, 1.0, 3);
    check_load_error("bad.ply", o.b, o.n - 3, "bad.ply: file truncated in element 'face' (record 1 of 2)");
    check_load_error("bad.ply", o.b, header + 20, "bad.ply: file truncated in element 'vertex' (record 1 of 4)");
    check_load_error("bad.ply", o.b, o.n + 1, "bad.ply: 1 bytes of unexpected data after the last element");
}

#define HDR3                                                                                               \
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"     \
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"

TEST(mesh_ply_ascii_errors)
{
    static const struct { const char *text, *want; } cases[] = {
        {HDR3 "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: vertex 1: coordinate 'y' is not finite (nan)"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "bad.ply:13: face 0: index 7 out of range [0, 2]"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "bad.ply:13: face 0: index -1 out of range [0, 2]"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n", "bad.ply: file truncated in element 'face' (record 0 of 1)"},
        {HDR3 "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "bad.ply:11: vertex 1: too few values on the line"},
        {HDR3 "0 0 0 5\n1 0 0\n0 1 0\n3 0 1 2\n", "bad.ply:10: vertex 0: too many values on the line"},
        {HDR3 "0 0 x\n1 0 0\n0 1 0\n3 0 1 2\n", "bad.ply:10: vertex 0: malformed float value 'x'"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "bad.ply:13: face 0: polygon has 2 vertices, need at least 3"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", "bad.ply:13: face 0: value 300 out of range for type 'uchar'"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "bad.ply:13: face 0: malformed int value '1.5'"},
        {HDR3 "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n5 5 5\n", "bad.ply:15: unexpected data after the last element"},
        {"plx\n", "bad.ply:1: not a PLY file"},
        {"ply\nformat ascii 2.0\n", "bad.ply:2: expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'"},
        {"ply\nformat binary_middle_endian 1.0\n", "bad.ply:2: unknown format 'binary_middle_endian'"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "bad.ply:4: header has no end_header line"},
        {"ply\nformat ascii 1.0\nfoo bar\nend_header\n", "bad.ply:3: unknown header keyword 'foo'"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty quad x\n", "bad.ply:4: unknown property type 'quad'"},
        {"ply\nformat ascii 1.0\nproperty float x\n", "bad.ply:3: property before any element"},
        {"ply\nformat ascii 1.0\nelement vertex -3\n", "bad.ply:3: element count '-3' is not an integer"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n",
         "bad.ply:4: list length type 'float' is not an integer type"},
        {"ply\nelement vertex 0\nend_header\n", "bad.ply:3: header has no format line"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n",
         "bad.ply: no triangles"},
        {"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nelement face 0\nproperty list uchar int "
         "vertex_indices\nend_header\n",
         "bad.ply: no triangles"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
         "bad.ply: no 'vertex' element"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n",
         "bad.ply:3: element 'vertex' has no scalar property 'z'"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 1\nproperty list uchar float vertex_indices\nend_header\n",
         "bad.ply:7: element 'face' has no integer list property"},
        {"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
         "property float z\nelement pad 1000000000\nelement face 1\nproperty list uchar int vertex_indices\n"
         "end_header\n",
         "bad.ply:7: element 'pad' has records but no properties"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        check_load_error("bad.ply", cases[i].text, strlen(cases[i].text), cases[i].want);
}

TEST(mesh_bunny)
{
    const char *dir = getenv("SHADOWLAB_MODEL_PATH");
    char path[PATH_LEN];
    snprintf(path, sizeof path, "%s/stanford-bunny.obj", dir ? dir : "");
    if (!dir || !file_exists(path)) {
        printf("    note: SHADOWLAB_MODEL_PATH unset or no stanford-bunny.obj there; skipped\n");
        return;
    }
    Mesh m;
    Error err = {{0}};
    CHECK_MSG(mesh_load(path, &m, &err), "%s", err.msg);
    CHECK(m.num_triangles == 69451 && m.num_vertices == 35947);
    for (int i = 0; i < m.num_vertices; i++) CHECK_NEAR(v3_len(m.normals[i]), 1.0, 1e-5);
    mesh_free(&m);
}
