/* The one place that fixes the spatial dimension. Vectors are interleaved
 * arrays `double (*x)[MPS_DIM]`; 3D follows by changing this and the few
 * places that say `#if MPS_DIM == 2` (cross products, rotations, lattices). */
#ifndef MPS_DIM_H
#define MPS_DIM_H

#ifndef MPS_DIM
#define MPS_DIM 2
#endif

typedef double mps_vec[MPS_DIM];

#endif
