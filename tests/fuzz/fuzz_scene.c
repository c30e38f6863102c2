/* fuzz_scene.c -- libFuzzer harness for scene files: any bytes as a scene
 * file through the sandboxed Lua reader and validation. A scene that loads
 * must be finite everywhere; one that does not must say why. */
#include <math.h>
#include "fuzz_util.h"
#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file(data, size, "lua");
    if (!path) return 0;
    Scene sc;
    Error err = {{0}};
    if (!scene_load(path, NULL, 0, &sc, &err)) {
        if (!err.msg[0]) abort(); /* a refusal without a message */
        return 0;
    }
    for (int i = 0; i < sc.num_objects; i++)
        for (int v = 0; v < sc.objects[i].mesh.num_vertices; v++)
            if (!v3_finite(sc.objects[i].mesh.positions[v])) abort();
    for (int i = 0; i < sc.num_lights; i++)
        if (!v3_finite(sc.lights[i].position) || !isfinite(sc.lights[i].radius)) abort();
    scene_free(&sc);
    return 0;
}
