#include "mps_kernel.h"

#include <math.h>

struct mps_lattice_consts mps_lattice_consts(double l0, double re)
{
    struct mps_lattice_consts c = {0.0, 0.0, 0};
    int k = (int)ceil(re / l0) + 1;
    double sum_w = 0.0, sum_r2w = 0.0;
#if MPS_DIM == 2
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++) {
            if (a == 0 && b == 0)
                continue;
            double r = l0 * sqrt((double)(a * a + b * b));
            if (r < re) {
                double w = mps_weight(r, re);
                sum_w += w;
                sum_r2w += r * r * w;
                c.count++;
            }
        }
#else
#error "mps_lattice_consts: only MPS_DIM == 2 is implemented"
#endif
    c.n0 = sum_w;
    c.lambda = sum_w > 0.0 ? sum_r2w / sum_w : 0.0;
    return c;
}
