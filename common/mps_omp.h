/* Splitting loops by hand inside an OpenMP parallel region. */
#ifndef MPS_OMP_H
#define MPS_OMP_H

#include <omp.h>

/* The calling thread's contiguous block [*lo, *hi) of n rows: fixed by the
 * thread count alone, so sums taken per block are reproducible. */
static inline void mps_omp_block(int n, int *lo, int *hi)
{
    int t = omp_get_thread_num(), nt = omp_get_num_threads();
    *lo = (int)((long long)n * t / nt);
    *hi = (int)((long long)n * (t + 1) / nt);
}

#endif
