/* fuzz_params.c -- libFuzzer harness for parameter strings: the first line
 * as "name=value" for every registered technique (tech_param_parse, the CLI's
 * and Lua's path), then the whole input as a scene override "key.path=value"
 * whose value Lua evaluates in the sandbox. Accepted values must be in range;
 * refusals must carry a message. */
#include <string.h>
#include "fuzz_util.h"
#include "techniques/registry.h"

static const char base_scene[] =
    "return { camera = { position = {0, 2, 4}, target = {0, 0, 0}, width = 8, height = 6 },\n"
    "  lights = { { type = 'sphere', position = {0, 4, 0}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane' }, { shape = 'box', translate = {0, 0.5, 0} } } }\n";

static void fuzz_technique_params(const char *line)
{
    for (int t = 0; t < tech_count(); t++) {
        const Technique *tech = tech_at(t);
        double vals[TECH_MAX_PARAMS];
        tech_params_default(tech, vals);
        Error err = {{0}};
        if (!tech_param_parse(tech, line, vals, &err)) {
            if (!err.msg[0]) abort();
            continue;
        }
        if (!tech_params_check(tech, vals, &err)) abort(); /* accepted a value out of its range */
    }
}

static void fuzz_override(const char *spec, const char *scene_path)
{
    Scene sc;
    Error err = {{0}};
    const char *ov[1] = {spec};
    if (scene_load(scene_path, ov, 1, &sc, &err)) scene_free(&sc);
    else if (!err.msg[0]) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char scene_path[512];
    if (!scene_path[0]) {
        const char *p = fuzz_file((const uint8_t *)base_scene, sizeof base_scene - 1, "lua");
        if (!p) return 0;
        snprintf(scene_path, sizeof scene_path, "%s", p);
    }
    if (size > 2000) return 0;
    char text[2001];
    memcpy(text, data, size);
    text[size] = '\0';
    if (strlen(text) != size) return 0; /* NUL inside: not a C string */
    char line[2001];
    snprintf(line, sizeof line, "%.*s", (int)strcspn(text, "\n"), text);
    fuzz_technique_params(line);
    fuzz_override(text, scene_path);
    return 0;
}
