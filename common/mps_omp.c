#define _GNU_SOURCE /* sched_setaffinity, CPU_SET */
#include "mps_omp.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mps_omp_bind_threads(char *note, size_t len)
{
    if (getenv("OMP_PLACES") || getenv("OMP_PROC_BIND")) {
        snprintf(note, len, "off: OMP_PLACES or OMP_PROC_BIND set");
        return 0;
    }
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) {
        snprintf(note, len, "off: sched_getaffinity: %s", strerror(errno));
        return 0;
    }
    int cpus[CPU_SETSIZE], ncpu = 0;
    for (int c = 0; c < CPU_SETSIZE; c++)
        if (CPU_ISSET(c, &allowed))
            cpus[ncpu++] = c;
    if (ncpu < 2 || omp_get_max_threads() < 2) {
        snprintf(note, len, "off: one CPU or one thread");
        return 0;
    }
    int failed = 0;
    /* each thread of the pool pins itself; later regions reuse these threads */
#pragma omp parallel reduction(+ : failed)
    {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus[omp_get_thread_num() % ncpu], &one);
        failed += sched_setaffinity(0, sizeof one, &one) != 0;
    }
    if (failed) {
        snprintf(note, len, "off: sched_setaffinity failed for %d threads", failed);
        return 0;
    }
    snprintf(note, len, "%d threads bound to %d CPUs", omp_get_max_threads(),
             omp_get_max_threads() < ncpu ? omp_get_max_threads() : ncpu);
    return 1;
}
