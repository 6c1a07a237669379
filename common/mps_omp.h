/* Splitting loops by hand inside an OpenMP parallel region. */
#ifndef MPS_OMP_H
#define MPS_OMP_H

#include <stddef.h>

#include <omp.h>

/* Rows a thread takes at a time in the neighbour-sum loops whose rows differ
 * in cost (schedule(dynamic, MPS_OMP_ROW_CHUNK)): long enough that each
 * thread streams its rows' neighbour lists in order and the threads rarely
 * meet on the shared counter, short enough to balance a few thousand rows.
 * 256 against the 64 before (AMD EPYC VM, 2 threads, dam break, two or more
 * runs each): 3.5 mm 581-592 against 602-608 ns per particle-step, 0.8 mm
 * 938-949 against 985-1000; 512 and 1024 within the runs' spread of 256,
 * 128 between; static (the rows' costs differ at walls and the surface)
 * 670-673 at 3.5 mm. The same rows and sums either way: no loop under it
 * reduces across rows, so the bits do not change. */
#define MPS_OMP_ROW_CHUNK 256

/* Binds each thread of the OpenMP pool to its own CPU (round robin over the
 * CPUs the process may use), unless OMP_PLACES or OMP_PROC_BIND is set (by
 * the user, or by the coupler, which places its solvers itself). Unbound,
 * the fluid's 3.5 mm dam break ran its neighbour phase at 1.3-1.5 ms per
 * step in 6 runs of 8 and at 0.57 ms in the others; bound, 0.57-0.59 ms
 * in 7 of 7 (2 threads, first 0.08 s). Call before the first parallel
 * region that matters. Returns 1 if bound; note says what was done. */
int mps_omp_bind_threads(char *note, size_t len);

/* The calling thread's contiguous block [*lo, *hi) of n rows: fixed by the
 * thread count alone, so sums taken per block are reproducible. */
static inline void mps_omp_block(int n, int *lo, int *hi)
{
    int t = omp_get_thread_num(), nt = omp_get_num_threads();
    *lo = (int)((long long)n * t / nt);
    *hi = (int)((long long)n * (t + 1) / nt);
}

#endif
