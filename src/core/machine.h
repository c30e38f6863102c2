/* machine.h -- what a record says about the machine it ran on. */
#ifndef SL_MACHINE_H
#define SL_MACHINE_H
#include <stdbool.h>
#include <stddef.h>

/* The CPU's model name from /proc/cpuinfo, or "unknown". */
void machine_cpu_model(char *out, size_t n);

/* The machine a record and an experiment's build identity name: the CPU
 * model and, when uname succeeds (named), host, system, release, arch. */
typedef struct MachineInfo {
    char cpu[256];
    bool named;
    char host[256], system[256], release[256], arch[256];
} MachineInfo;
void machine_info(MachineInfo *m);

#endif
