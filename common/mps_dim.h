/* The one place that fixes the spatial dimension. Vectors are interleaved
 * arrays `double (*x)[MPS_DIM]`; 3D follows by changing this and the few
 * places that say `#if MPS_DIM == 2` (cross products, rotations, lattices). */
#ifndef MPS_DIM_H
#define MPS_DIM_H

#include <stddef.h>

#ifndef MPS_DIM
#define MPS_DIM 2
#endif

typedef double mps_vec[MPS_DIM];

/* dx = x_j - x_i; returns |dx|^2. The pair loop every operator starts with. */
static inline double mps_pair_delta(const double (*x)[MPS_DIM], size_t i, size_t j,
                                    double dx[MPS_DIM])
{
    double r2 = 0.0;
    for (int d = 0; d < MPS_DIM; d++) {
        dx[d] = x[j][d] - x[i][d];
        r2 += dx[d] * dx[d];
    }
    return r2;
}

#endif
