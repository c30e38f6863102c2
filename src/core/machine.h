/* machine.h -- what a record says about the machine it ran on. */
#ifndef SL_MACHINE_H
#define SL_MACHINE_H
#include <stddef.h>

/* The CPU's model name from /proc/cpuinfo, or "unknown". */
void machine_cpu_model(char *out, size_t n);

#endif
