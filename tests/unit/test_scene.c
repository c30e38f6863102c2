/* test_scene.c -- scene files: overrides, validation messages with key
 * paths and ranges, and the sandbox (no io/os/require/load, bounded
 * instructions and memory). */
#include <string.h>
#include "core/fsutil.h"
#include "fixtures.h"
#include "test.h"

static const char *const base =
    "return {\n"
    "  camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 32, height = 24 },\n"
    "  lights = { { type = 'sphere', position = {0, 4, 0}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane' }, { shape = 'box', translate = {0, 0.5, 0} } },\n"
    "}\n";

static bool load(const char *text, const char *const *ov, int nov, Scene *sc, Error *err)
{
    const char *path = fixture_file("s.lua", text);
    return scene_load(path, ov, nov, sc, err);
}

TEST(test_scene_overrides_apply_and_change_the_hash)
{
    Scene a, b;
    Error err;
    CHECK_MSG(load(base, NULL, 0, &a, &err), "%s", err.msg);
    const char *ov[] = {"lights[1].radius=0.25", "camera.width=40", "objects[2].translate={1,0.5,0}"};
    CHECK_MSG(load(base, ov, 3, &b, &err), "%s", err.msg);
    CHECK_NEAR(b.lights[0].radius, 0.25, 1e-7);
    CHECK(b.camera.width == 40);
    CHECK(b.hash != a.hash && b.hash_lights[0] != a.hash_lights[0] && b.hash_camera != a.hash_camera);
    CHECK(b.hash_geometry != a.hash_geometry);
    scene_free(&a);
    scene_free(&b);
    const char *same[] = {"lights[1].radius=0.5"};
    CHECK(load(base, same, 1, &a, &err) && load(base, NULL, 0, &b, &err));
    CHECK(a.hash == b.hash);
    scene_free(&a);
    scene_free(&b);
}

/* Each case: scene text (or override) and words the message must contain. */
static void expect_error(const char *text, const char *override, const char *must1, const char *must2)
{
    Scene sc;
    Error err;
    const char *ov[] = {override};
    bool ok = load(text, ov, override ? 1 : 0, &sc, &err);
    if (ok) {
        scene_free(&sc);
        test_fail(__FILE__, __LINE__, "accepted: %s", override ? override : text);
        return;
    }
    if (!strstr(err.msg, must1) || (must2 && !strstr(err.msg, must2)))
        test_fail(__FILE__, __LINE__, "message '%s' lacks '%s'/'%s'", err.msg, must1, must2 ? must2 : "");
    if (!strstr(err.msg, "s.lua")) test_fail(__FILE__, __LINE__, "message '%s' does not name the file", err.msg);
}

TEST(test_scene_errors_name_key_path_and_range)
{
    expect_error(base, "lights[1].radius=-1", "lights[1].radius", "(0, 1e+07]");
    expect_error(base, "lights[1].radus=1", "lights[1].radus", "valid:");
    expect_error(base, "camera.fov=200", "camera.fov", "(0, 180)");
    expect_error(base, "camera.width=0.5", "camera.width", "[1, 16384]");
    expect_error(base, "objects[2].shape=blob", "objects[2].shape", "plane, box");
    expect_error(base, "objects[1].albedo={1,2,0}", "objects[1].albedo[2]", "[0, 1]");
    expect_error(base, "objects[1].size='big'", "objects[1].size", "list of 2 numbers");
    expect_error(base, "camera.far=0.001", "far", "near");
    expect_error(base, "lights[2].radius=1", "lights[2]", "not a table");
    expect_error(base, "lights[1].position={0,0/0,0}", "lights[1].position[2]", NULL);
    expect_error("return {}", NULL, "camera", "must be a table");
    expect_error("return 42", NULL, "must return a table", NULL);
    expect_error("return {", NULL, "s.lua:1", NULL);
    expect_error(base, "objects[1]=3", "objects[1]", "must be a table");
}

TEST(test_scene_sandbox_refuses_escape_hang_and_bloat)
{
    expect_error("os.execute('touch /tmp/pwned') return {}", NULL, "os", NULL);
    expect_error("io.open('/etc/passwd') return {}", NULL, "io", NULL);
    expect_error("require('os') return {}", NULL, "require", NULL);
    expect_error("load('return 1')() return {}", NULL, "load", NULL);
    expect_error("dofile('/etc/passwd') return {}", NULL, "dofile", NULL);
    expect_error("while true do end", NULL, "instruction limit", NULL);
    expect_error("local t = {} for i = 1, 1e9 do t[i] = string.rep('x', 1000000) .. i end return {}", NULL,
                 "memory", NULL);
    CHECK(!file_exists("/tmp/pwned"));
}

/* Escapes found by the stability suite (issue 7): libraries absent, C loops
 * the instruction count cannot see charged or removed, finalizers refused,
 * and a limit that pcall cannot swallow. Each must fail fast with a message. */
TEST(test_scene_sandbox_refuses_hidden_loops_and_missing_libraries)
{
    expect_error("local x = package.loadlib('libc.so.6', 'system') return {}", NULL, "package", NULL);
    expect_error("debug.sethook() return {}", NULL, "debug", NULL);
    expect_error("local d = string.dump(function() end) return {}", NULL, "dump", NULL);
    expect_error("local s = string.rep('a', 30000) string.find(s, '.-.-.-.-b') return {}", NULL, "find", NULL);
    expect_error("local s = ('a'):rep(30000) s:match('.-.-.-.-b') return {}", NULL, "match", NULL);
    expect_error("table.move({}, 1, 1e14, 2) return {}", NULL, "move", NULL);
    expect_error("warn('@on') return {}", NULL, "warn", NULL);
    expect_error("local s = string.rep('', 1e15) return {}", NULL, "instruction limit", NULL);
    /* A border #t of 2^61 + 1 with 127 entries: insert and remove would shift that many in C. */
    const char *border = "local t = {} for i = 1, 8 do t[i] = i end\n"
                         "for k = 0, 58 do t[8 << k] = 1 t[(8 << k) + 1] = 1 end\n";
    char text[400];
    snprintf(text, sizeof text, "%s table.insert(t, 1, 0) return {}", border);
    expect_error(text, NULL, "instruction limit", NULL);
    snprintf(text, sizeof text, "%s table.remove(t, 1) return {}", border);
    expect_error(text, NULL, "instruction limit", NULL);
    expect_error("setmetatable({}, {__gc = function() while true do end end}) return {}", NULL, "__gc", NULL);
    expect_error("while true do pcall(function() while true do end end) end", NULL, "instruction limit", NULL);
}

TEST(test_scene_heightfield_and_procedural_loops)
{
    const char *text =
        "local objs = { { shape = 'heightfield', size = {10, 10}, resolution = {8, 8},\n"
        "                 elevation = function(x, z) return 0.1 * math.sin(x) * math.cos(z) end } }\n"
        "for i = 1, 5 do objs[#objs + 1] = { shape = 'cone', radius = 0.2, height = 1,\n"
        "  translate = {math.random() * 4 - 2, 0.5, math.random() * 4 - 2} } end\n"
        "return { camera = { position = {0, 3, 6}, target = {0, 0, 0} },\n"
        "  lights = { { type = 'directional', direction = {-1, -2, -1} } }, objects = objs }\n";
    Scene a, b;
    Error err;
    CHECK_MSG(load(text, NULL, 0, &a, &err), "%s", err.msg);
    CHECK(a.num_objects == 6 && a.objects[0].mesh.num_triangles == 2 * 8 * 8);
    CHECK_MSG(load(text, NULL, 0, &b, &err), "%s", err.msg);
    CHECK_MSG(a.hash == b.hash, "math.random is not deterministic across loads");
    scene_free(&a);
    scene_free(&b);
}

/* A model named by alternatives: the first file found is used, with its own
 * scale and translate mapping it into the first alternative's frame. */
TEST(test_scene_model_alternatives_and_their_transforms)
{
    fixture_file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n");
    const char *text =
        "return { camera = { position = {0, 3, 6}, target = {0, 0, 0} },\n"
        "  lights = { { type = 'point', position = {0, 4, 0} } },\n"
        "  objects = { { shape = 'mesh', translate = {0, 1, 0},\n"
        "    model = { 'absent.obj', 'absent2.ply', { file = 'tri.obj', scale = 2, translate = {5, 0, 0} } } } } }\n";
    Scene sc;
    Error err;
    CHECK_MSG(load(text, NULL, 0, &sc, &err), "%s", err.msg);
    CHECK(strstr(sc.objects[0].source, "tri.obj") != NULL);
    vec3 p = sc.objects[0].mesh.positions[1]; /* (1,0,0) -> x2 -> +5 in x -> +1 in y */
    CHECK_NEAR(p.x, 7, 1e-6);
    CHECK_NEAR(p.y, 1, 1e-6);
    scene_free(&sc);
    expect_error(text, "objects[1].model={'absent.obj'}", "model not found", "absent.obj");
    expect_error(text, "objects[1].model={{file='tri.obj', scale=-1}}", "objects[1].model[1].scale", NULL);
    expect_error(text, "objects[1].model={{scale=2}}", "objects[1].model[1].file", "missing");
    expect_error(text, "objects[1].model=3", "objects[1].model", "file name");
}
