/* filtered_fixtures.c -- helpers of the prefiltered shadow-map tests. */
#include "filtered_fixtures.h"
#include <stdio.h>
#include <string.h>

Lab *filtered_open(const char *scene, int width, int height)
{
    Error err;
    char w[48], h[48];
    snprintf(w, sizeof w, "camera.width=%d", width);
    snprintf(h, sizeof h, "camera.height=%d", height);
    const char *ov[] = {w, h};
    Lab *lab = lab_open(scene, ov, 2, &err);
    if (!lab) printf("    %s: %s\n", scene, err.msg);
    return lab;
}

bool filtered_params(const Technique *t, const char *list, double *values)
{
    Error err;
    char buf[512], *save = NULL;
    tech_params_default(t, values);
    snprintf(buf, sizeof buf, "%s", list ? list : "");
    for (char *tok = strtok_r(buf, " ", &save); tok; tok = strtok_r(NULL, " ", &save))
        if (!tech_param_parse(t, tok, values, &err)) {
            printf("    %s\n", err.msg);
            return false;
        }
    return true;
}

bool filtered_render(Lab *lab, const char *tech, const char *list, RenderResult *out)
{
    Error err;
    double values[TECH_MAX_PARAMS];
    const Technique *t = tech_find(tech, &err);
    if (!t) {
        printf("    %s\n", err.msg);
        return false;
    }
    if (!filtered_params(t, list, values)) return false;
    RenderRequest rq = {.tech = t, .params = values, .light_index = 0, .repeat = 1};
    if (lab_render(lab, &rq, out, &err)) return true;
    printf("    %s %s: %s\n", tech, list ? list : "", err.msg);
    return false;
}

bool filtered_acquires_moments(const Technique *t)
{
    if (strcmp(t->family, "filtered") != 0) return false; /* the soft family's prefiltered PCSS: test_filtered_soft.c */
    for (int i = 0; t->resources[i]; i++)
        if (strcmp(t->resources[i], "moments") == 0) return true;
    return false;
}
