/* The machine a run ran on, for its summary: speed figures belong to a host
 * (the same commit took 1.43x longer per fluid step at 6k particles on one
 * 2-core VM than on another, and 11% less at 80k), so every summary.json
 * names the CPU next to its timings. */
#ifndef MPS_HOST_H
#define MPS_HOST_H

#include <stddef.h>

/* Writes "MODEL (family F model M), N CPUs" into buf (always terminated),
 * from /proc/cpuinfo's first processor and the CPUs online;
 * "unknown CPU, N CPUs" where /proc/cpuinfo is missing or has no model name
 * (non-x86 kernels name it otherwise). */
void mps_host_describe(char *buf, size_t size);

#endif
