/* machine.c -- the machine a run was measured on (machine.h). */
#include "core/machine.h"
#include <stdio.h>
#include <string.h>
#include <sys/utsname.h>

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

void machine_info(MachineInfo *m)
{
    struct utsname u;
    memset(m, 0, sizeof *m);
    machine_cpu_model(m->cpu, sizeof m->cpu);
    m->named = uname(&u) == 0;
    if (!m->named) return;
    snprintf(m->host, sizeof m->host, "%s", u.nodename);
    snprintf(m->system, sizeof m->system, "%s", u.sysname);
    snprintf(m->release, sizeof m->release, "%s", u.release);
    snprintf(m->arch, sizeof m->arch, "%s", u.machine);
}
