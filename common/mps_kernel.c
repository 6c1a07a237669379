#include "mps_kernel.h"

#include <math.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "mps_simd.h"

struct mps_lattice_consts mps_lattice_consts(double l0, double re)
{
    struct mps_lattice_consts c = {0.0, 0.0, 0.0, 0};
    int k = (int)ceil(re / l0) + 1;
    double sum_w = 0.0, sum_r2w = 0.0, sum_q = 0.0;
#if MPS_DIM == 2
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++) {
            if (a == 0 && b == 0) {
                sum_q += mps_weight_quadratic(0.0, re); /* the particle itself */
                continue;
            }
            double r = l0 * sqrt((double)(a * a + b * b));
            if (r < re) {
                double w = mps_weight(r, re);
                sum_w += w;
                sum_r2w += r * r * w;
                sum_q += mps_weight_quadratic(r, re);
                c.count++;
            }
        }
#else
#error "mps_lattice_consts: only MPS_DIM == 2 is implemented"
#endif
    c.n0 = sum_w;
    c.lambda = sum_w > 0.0 ? sum_r2w / sum_w : 0.0;
    c.nq0 = sum_q;
    return c;
}

/* sum_j -w'(r) e_ij over the lattice, the middle particle moved by dx along x */
static double lattice_gradient_x(double l0, double re, int smooth, double dx)
{
    int k = (int)ceil(re / l0) + 1;
    double g = 0.0;
#if MPS_DIM == 2
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++) {
            double x = l0 * a - dx, y = l0 * b, r = sqrt(x * x + y * y);
            if ((a == 0 && b == 0) || r >= re)
                continue;
            double dw = smooth ? 2.0 * (1.0 - r / re) / re : re / (r * r);
            g += dw * x / r;
        }
#else
#error "lattice_gradient_x: only MPS_DIM == 2 is implemented"
#endif
    return g;
}

double mps_lattice_gradient_response(double l0, double re, int smooth)
{
    const double h = 1e-6 * l0;
    return fabs(lattice_gradient_x(l0, re, smooth, h) - lattice_gradient_x(l0, re, smooth, -h)) /
           (2.0 * h);
}

void mps_weights_r2_sse2(double *restrict w, size_t n, double re, double scale)
{
    size_t k = 0;
#ifdef __SSE2__
    /* max(w, 0) is 0.5 (w + |w|) for every w met here (no NaN: r^2 = 0 maps
     * to infinity, w = -1), so the bits are mps_weight_r2's */
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

#ifdef MPS_HAVE_WIDE
__attribute__((target("avx512f"))) static void weights_avx512(double *restrict w, size_t n,
                                                               double re, double scale)
{
    const __m512d vre = _mm512_set1_pd(re), vscale = _mm512_set1_pd(scale);
    for (size_t k = 0; k < n; k += 8) {
        /* the last, partial group through a mask: lanes past n load as 0
         * (w = 0) and are not stored */
        const __mmask8 in = mps_lanes8(n - k);
        const __m512d r2 = _mm512_maskz_loadu_pd(in, w + k);
        _mm512_mask_storeu_pd(w + k, in, _mm512_mul_pd(vscale, mps_weight8_r2(r2, vre)));
    }
}
#endif

int mps_weights_r2_wide(double *restrict w, size_t n, double re, double scale)
{
#ifdef MPS_HAVE_WIDE
    if (mps_simd_wide()) {
        weights_avx512(w, n, re, scale);
        return 1;
    }
#else
    (void)w, (void)n, (void)re, (void)scale;
#endif
    return 0;
}

void mps_weights_r2(double *restrict w, size_t n, double re, double scale)
{
    if (!mps_weights_r2_wide(w, n, re, scale))
        mps_weights_r2_sse2(w, n, re, scale);
}
