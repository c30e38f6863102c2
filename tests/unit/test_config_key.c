/* test_config_key.c -- a sweep row's key (lab_config_key) names what ran:
 * enum parameters hash their choice's name, so a row recorded before the
 * choices were reordered cannot answer for another choice on --resume. */
#include <string.h>
#include "fixtures.h"
#include "lab/compare.h"
#include "techniques/registry.h"
#include "test.h"

static const char *const key_scene =
    "return {\n"
    "  camera = { position = {0, 3, 5}, target = {0, 0.4, 0}, width = 16, height = 12 },\n"
    "  lights = { { type = 'sphere', position = {1, 4, 1}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane', size = {8, 8} } },\n"
    "}\n";

/* Index of `name` among a NULL-terminated choice list, -1 if absent. */
static int choice_index(const char *const *choices, const char *name)
{
    for (int i = 0; choices[i]; i++)
        if (strcmp(choices[i], name) == 0) return i;
    return -1;
}

TEST(test_config_key_hashes_enum_choices_by_name)
{
    Error err;
    Lab *lab = fixture_lab("enum-key.lua", key_scene);
    CHECK(lab);
    const Technique *pcf = tech_find("pcf", &err);
    CHECK(pcf);
    if (!lab || !pcf) return;
    int k = -1;
    for (int i = 0; i < pcf->num_params; i++)
        if (strcmp(pcf->params[i].name, "kernel") == 0) k = i;
    CHECK(k >= 0 && pcf->params[k].type == PARAM_ENUM);
    if (k < 0) { lab_close(lab); return; }
    /* The same technique with its kernel choices in reverse order. */
    const char *const *orig = pcf->params[k].choices;
    int n = 0;
    while (orig[n]) n++;
    const char *reversed[16] = {NULL};
    CHECK(n < 16);
    for (int i = 0; i < n && n < 16; i++) reversed[i] = orig[n - 1 - i];
    Technique moved = *pcf;
    ParamDesc params[TECH_MAX_PARAMS];
    memcpy(params, pcf->params, sizeof(ParamDesc) * (size_t)pcf->num_params);
    params[k].choices = reversed;
    moved.params = params;
    double a[TECH_MAX_PARAMS], b[TECH_MAX_PARAMS];
    tech_params_default(pcf, a);
    tech_params_default(pcf, b);
    a[k] = choice_index(orig, "poisson");
    b[k] = choice_index(reversed, "poisson");
    CHECK(a[k] >= 0 && a[k] != b[k]);
    /* Same choice by name at another index: same key. */
    CHECK(lab_config_key(lab, pcf, a, 0) == lab_config_key(lab, &moved, b, 0));
    /* Same index naming another choice: another key. */
    CHECK(lab_config_key(lab, pcf, a, 0) != lab_config_key(lab, &moved, a, 0));
    lab_close(lab);
}
