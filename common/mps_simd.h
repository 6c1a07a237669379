/* Which vector paths run, and the 8-lane pieces they share. A loop that has
 * an AVX-512 path keeps its portable one; the choice is made at run time
 * (mps_simd_wide), so one build runs on every x86-64 CPU. */
#ifndef MPS_SIMD_H
#define MPS_SIMD_H

#include <stddef.h>

#include "mps_err.h"

/* Builds that can carry AVX-512 paths (GCC or Clang on x86-64). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MPS_HAVE_WIDE 1
#include <immintrin.h>
#endif

/* 1 when the AVX-512 paths run: the CPU has AVX-512F, and neither
 * MPS_SIMD=sse2 in the environment (read at start-up) nor
 * mps_simd_set_wide(0) turned them off. The portable paths give other last
 * bits, so MPS_SIMD=sse2 reproduces a run of a machine without AVX-512. */
int mps_simd_wide(void);
/* MPS_SIMD as read at start-up: unset, empty, "auto" or "sse2" is MPS_OK;
 * any other value is MPS_EINPUT naming it, so that a misspelt request for
 * the portable paths cannot run the vector ones unnoticed. Every program
 * checks it with its command line (mps_cli_parse). */
enum mps_status mps_simd_check_env(struct mps_err *err);
/* 0: the portable paths from now on; 1: back to what mps_simd_wide found.
 * For tests that compare the two; not thread-safe against running loops. */
void mps_simd_set_wide(int on);

#ifdef MPS_HAVE_WIDE
/* Eq. 7 for eight squared distances: max(re/r - 1, 0), 0 at r = 0. 1/r
 * from the hardware estimate (14 bits) and two Newton steps with FMA, each
 * y (3/2 - r^2 y^2 / 2) squaring the relative error: within a few units in
 * the last place of mps_weight_r2 (tests/common/test_nbr.c), not the same
 * bits. Packed square roots and divisions are no faster per element at 512
 * bits than at 128 on recent x86 cores, so only the estimate helps. */
__attribute__((target("avx512f"))) static inline __m512d mps_weight8_r2(__m512d r2, __m512d re)
{
    const __m512d half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5),
                  one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd();
    const __m512d hr2 = _mm512_mul_pd(half, r2);
    const __mmask8 pos = _mm512_cmp_pd_mask(r2, zero, _CMP_GT_OQ);
    /* r^2 = 0: y = inf and NaN below, masked to w = 0 */
    __m512d y = _mm512_rsqrt14_pd(r2);
    y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
    y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
    return _mm512_maskz_max_pd(pos, _mm512_fmsub_pd(re, y, one), zero);
}

/* Lanes [0, min(n, 8)) of eight: the last, partial group of a loop, or the
 * first n lanes a compressed store fills. Without a jump (a compress count
 * follows no pattern a predictor could learn). */
static inline __mmask8 mps_lanes8(size_t n)
{
    const unsigned c = n < 8 ? (unsigned)n : 8u;
    return (__mmask8)((1u << c) - 1u);
}
#endif

#endif
