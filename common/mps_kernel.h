/* The MPS weight function (Eq. 7) and the constants derived from the initial
 * lattice: n0 (Eq. 8), N0 (neighbour count) and lambda (Eq. 13). */
#ifndef MPS_KERNEL_H
#define MPS_KERNEL_H

#include <math.h>
#include <stddef.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "mps_dim.h"

/* Eq. 7: w(r) = re/r - 1 for 0 < r <= re, else 0. */
static inline double mps_weight(double r, double re)
{
    return (r > 0.0 && r < re) ? re / r - 1.0 : 0.0;
}

/* Eq. 7 from the squared distance, without a branch: max(re/r - 1, 0) is
 * re/r - 1 inside re and 0 outside, and r = 0 maps to r = inf (w = 0, as
 * mps_weight). Neighbour loops visit a skin list of which about a third
 * lies beyond re, in no order a branch predictor could learn. */
static inline double mps_weight_r2(double r2, double re)
{
    double w = re / sqrt(r2 > 0.0 ? r2 : INFINITY) - 1.0;
    return 0.5 * (w + fabs(w)); /* max(w, 0), exact, and compiled without a jump */
}

/* mps_weight_r2 of n squared distances, in place, times scale. Kept apart
 * from the loops that gather the distances so that it runs over contiguous
 * values with packed square roots and divisions: one at a time, these
 * bound a neighbour loop (about 10 cycles a candidate). Written with SSE2
 * intrinsics because the compiler vectorises the plain loop only without
 * errno from sqrt (-fno-math-errno), and that flag made the scalar square
 * roots elsewhere 6-7% slower (3.5 mm dam break, 2 threads). The same bits
 * as mps_weight_r2: max(w, 0) is 0.5 (w + |w|) for every w it meets (no
 * NaN: r^2 = 0 maps to infinity, w = -1). */
static inline void mps_weights_r2(double *restrict w, size_t n, double re, double scale)
{
    size_t k = 0;
#ifdef __SSE2__
    const __m128d vre = _mm_set1_pd(re), vscale = _mm_set1_pd(scale), one = _mm_set1_pd(1.0),
                  zero = _mm_setzero_pd(), inf = _mm_set1_pd(INFINITY);
    for (; k + 2 <= n; k += 2) {
        __m128d r2 = _mm_loadu_pd(w + k), pos = _mm_cmpgt_pd(r2, zero);
        r2 = _mm_or_pd(_mm_and_pd(pos, r2), _mm_andnot_pd(pos, inf));
        __m128d v = _mm_sub_pd(_mm_div_pd(vre, _mm_sqrt_pd(r2)), one);
        _mm_storeu_pd(w + k, _mm_mul_pd(vscale, _mm_max_pd(v, zero)));
    }
#endif
    for (; k < n; k++)
        w[k] = scale * mps_weight_r2(w[k], re);
}

/* Neighbour loops that call mps_weights_r2 take their list in chunks of this
 * many candidates, with stack buffers of this size. */
#define MPS_WEIGHT_CHUNK 128

struct mps_lattice_consts {
    double n0;       /* Eq. 8 on the full square lattice */
    double lambda;   /* Eq. 13, m^2 */
    int count;       /* neighbours inside re (N0 of the free-surface check) */
};

/* Constants for a particle inside a full square lattice of spacing l0, with
 * effective radius re (both in m). */
struct mps_lattice_consts mps_lattice_consts(double l0, double re);

#endif
