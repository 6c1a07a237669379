#include "mps_kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef MPS_HAVE_WIDE
#include <immintrin.h>
#endif

static int simd_wide_found, simd_wide;

/* Before main, so that the loops that ask never race on the answer. */
__attribute__((constructor)) static void simd_init(void)
{
#ifdef MPS_HAVE_WIDE
    const char *env = getenv("MPS_SIMD");
    __builtin_cpu_init(); /* constructors may run before libgcc's own */
    simd_wide_found = __builtin_cpu_supports("avx512f") && !(env && !strcmp(env, "sse2"));
#endif
    simd_wide = simd_wide_found;
}

int mps_simd_wide(void) { return simd_wide; }

void mps_simd_set_wide(int on) { simd_wide = on ? simd_wide_found : 0; }

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
    const __m512d vre = _mm512_set1_pd(re), vscale = _mm512_set1_pd(scale),
                  one = _mm512_set1_pd(1.0), three_halves = _mm512_set1_pd(1.5),
                  half = _mm512_set1_pd(0.5), zero = _mm512_setzero_pd();
    for (size_t k = 0; k < n; k += 8) {
        /* the last, partial group through a mask: lanes past n load as 0
         * (w = 0) and are not stored */
        const __mmask8 in = n - k >= 8 ? 0xFF : (__mmask8)((1u << (n - k)) - 1u);
        __m512d r2 = _mm512_maskz_loadu_pd(in, w + k), hr2 = _mm512_mul_pd(half, r2);
        __mmask8 pos = _mm512_cmp_pd_mask(r2, zero, _CMP_GT_OQ);
        /* y ~ 1/r to 2^-14; each Newton step y (3/2 - r^2 y^2 / 2) squares
         * the relative error: 2^-27, then rounding. r^2 = 0 gives y = inf
         * and NaN below, masked to w = 0 as mps_weight_r2 does. */
        __m512d y = _mm512_rsqrt14_pd(r2);
        y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
        y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
        __m512d v = _mm512_maskz_max_pd(pos, _mm512_fmsub_pd(vre, y, one), zero);
        _mm512_mask_storeu_pd(w + k, in, _mm512_mul_pd(vscale, v));
    }
}
#endif

int mps_weights_r2_wide(double *restrict w, size_t n, double re, double scale)
{
#ifdef MPS_HAVE_WIDE
    if (simd_wide) {
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
