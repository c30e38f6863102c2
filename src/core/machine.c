/* machine.c -- the machine a run was measured on (machine.h). */
#include "core/machine.h"
#include <stdio.h>
#include <string.h>

void machine_cpu_model(char *out, size_t n)
{
    snprintf(out, n, "unknown");
    FILE *fp = fopen("/proc/cpuinfo", "r");
    if (!fp) return;
    char line[512];
    while (fgets(line, sizeof line, fp)) {
        char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) == 0 && colon) {
            snprintf(out, n, "%s", colon + 2);
            out[strcspn(out, "\n")] = '\0';
            break;
        }
    }
    fclose(fp);
}
