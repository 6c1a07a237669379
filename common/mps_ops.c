#include "mps_ops.h"

#include <math.h>

#include "mps_kernel.h"
#include "mps_omp.h"
#include "mps_simd.h"

/* the AVX-512 operator paths are written for 2D */
#if defined(MPS_HAVE_WIDE) && MPS_DIM == 2
#define OPS_WIDE 1
#endif

#define USE(in, j) (!(in)->use || (in)->use[j])
#define QUERY(in, i) (!(in)->query || (in)->query[i])
#define PAIR(in, k) (!(in)->pair_use || (in)->pair_use[k])

/* Eq. 8's sum and count, and with nq the sum of mps_weight_quadratic with the
 * particle itself, in the same pass over the pairs */
static void density_sums(const struct mps_ops_in *in, double *n, int *count, double *nq)
{
    const struct mps_nbr_list *nl = in->nl;
    const double re2 = in->re * in->re;
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        if (!QUERY(in, i))
            continue;
        double s = 0.0, sq = 1.0;
        int c = 0;
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            int j = nl->j[k];
            if (!USE(in, j))
                continue;
            double r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = in->x[j][d] - in->x[i][d];
                r2 += dx * dx;
            }
            if (r2 < re2) {
                double r = sqrt(r2);
                s += mps_weight(r, in->re);
                if (nq)
                    sq += mps_weight_quadratic(r, in->re);
                c++;
            }
        }
        n[i] = s;
        if (nq)
            nq[i] = sq;
        if (count)
            count[i] = c;
    }
}

void mps_ops_number_density(const struct mps_ops_in *in, double *n, int *count)
{
    density_sums(in, n, count, NULL);
}

void mps_ops_number_density_quadratic(const struct mps_ops_in *in, double *n, int *count,
                                      double *nq)
{
    density_sums(in, n, count, nq);
}

#ifdef OPS_WIDE
/* The sums of mps_ops_laplacian_vec for row i, eight candidates at a time
 * (mps_simd_wide): positions and field gathered, weights by mps_weight8_r2,
 * the use mask from one byte per candidate. */
__attribute__((target("avx512f"))) static void laplacian_vec_row_avx512(
    const struct mps_ops_in *in, size_t i, const double (*f)[2], double acc[2])
{
    const struct mps_nbr_list *nl = in->nl;
    const int *nj = nl->j + nl->start[i];
    const size_t len = nl->start[i + 1] - nl->start[i];
    const double *xd = &in->x[0][0], *fd = &f[0][0];
    const __m512d vxi = _mm512_set1_pd(in->x[i][0]), vyi = _mm512_set1_pd(in->x[i][1]),
                  vfx = _mm512_set1_pd(f[i][0]), vfy = _mm512_set1_pd(f[i][1]),
                  vre = _mm512_set1_pd(in->re), zero = _mm512_setzero_pd();
    __m512d ax = zero, ay = zero;
    for (size_t k = 0; k < len; k += 8) {
        const __mmask8 lanes = mps_lanes8(len - k);
        __mmask8 use = lanes;
        if (in->use) {
            use = 0;
            for (size_t l = 0; l < 8 && k + l < len; l++)
                use |= (__mmask8)((in->use[nj[k + l]] != 0) << l);
        }
        const __m256i j2 = _mm256_slli_epi32(
            _mm512_castsi512_si256(_mm512_maskz_loadu_epi32(lanes, nj + k)), 1);
        const __m512d dx = _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, lanes, j2, xd, 8), vxi),
                      dy = _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, lanes, j2, xd + 1, 8), vyi);
        const __m512d w =
            mps_weight8_r2(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), vre);
        const __m512d gx = _mm512_sub_pd(_mm512_mask_i32gather_pd(vfx, use, j2, fd, 8), vfx),
                      gy = _mm512_sub_pd(_mm512_mask_i32gather_pd(vfy, use, j2, fd + 1, 8), vfy);
        ax = _mm512_fmadd_pd(gx, w, ax); /* f_j - f_i = 0 where not used */
        ay = _mm512_fmadd_pd(gy, w, ay);
    }
    acc[0] = _mm512_reduce_add_pd(ax);
    acc[1] = _mm512_reduce_add_pd(ay);
}
#endif

void mps_ops_laplacian_vec(const struct mps_ops_in *in, double n0, double lambda,
                           const double (*f)[MPS_DIM], double (*lap)[MPS_DIM])
{
    const struct mps_nbr_list *nl = in->nl;
    const double coef = 2.0 * MPS_DIM / (lambda * n0);
#ifdef OPS_WIDE
    const int wide = mps_simd_wide();
#endif
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        mps_nbr_prefetch_row(nl, i + MPS_NBR_PREFETCH_ROWS);
        if (!QUERY(in, i))
            continue;
        double acc[MPS_DIM] = {0}, w[MPS_WEIGHT_CHUNK];
#ifdef OPS_WIDE
        if (wide) {
            laplacian_vec_row_avx512(in, i, f, acc);
            for (int d = 0; d < MPS_DIM; d++)
                lap[i][d] = coef * acc[d];
            continue;
        }
#endif
        /* in chunks: distances, weights packed (mps_weights_r2), sums */
        for (size_t c0 = nl->start[i]; c0 < nl->start[i + 1]; c0 += MPS_WEIGHT_CHUNK) {
            const size_t len = nl->start[i + 1] - c0 < MPS_WEIGHT_CHUNK ? nl->start[i + 1] - c0
                                                                        : MPS_WEIGHT_CHUNK;
            for (size_t k = 0; k < len; k++) {
                int j = nl->j[c0 + k];
                double r2 = 0.0;
                for (int d = 0; d < MPS_DIM; d++) {
                    double dx = in->x[j][d] - in->x[i][d];
                    r2 += dx * dx;
                }
                w[k] = r2;
            }
            mps_weights_r2(w, len, in->re, 1.0);
            for (size_t k = 0; k < len; k++) {
                int j = nl->j[c0 + k];
                if (!USE(in, j))
                    continue;
                for (int d = 0; d < MPS_DIM; d++)
                    acc[d] += (f[j][d] - f[i][d]) * w[k];
            }
        }
        for (int d = 0; d < MPS_DIM; d++)
            lap[i][d] = coef * acc[d];
    }
}

void mps_ops_laplacian(const struct mps_ops_in *in, double n0, double lambda, const double *f,
                       double *lap)
{
    const struct mps_nbr_list *nl = in->nl;
    const double re2 = in->re * in->re, coef = 2.0 * MPS_DIM / (lambda * n0);
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        if (!QUERY(in, i))
            continue;
        double acc = 0.0;
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            int j = nl->j[k];
            if (!USE(in, j))
                continue;
            double r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = in->x[j][d] - in->x[i][d];
                r2 += dx * dx;
            }
            if (r2 < re2)
                acc += (f[j] - f[i]) * mps_weight(sqrt(r2), in->re);
        }
        lap[i] = coef * acc;
    }
}

/* The reference value subtracted from f_j: f_i, or the neighbourhood minimum. */
static double grad_ref(const struct mps_ops_in *in, size_t i, const double *f, int use_min)
{
    double ref = f[i];
    if (!use_min)
        return ref;
    const struct mps_nbr_list *nl = in->nl;
    const double re2 = in->re * in->re;
    for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
        int j = nl->j[k];
        if (!USE(in, j) || !PAIR(in, k) || f[j] >= ref)
            continue;
        double r2 = 0.0;
        for (int d = 0; d < MPS_DIM; d++) {
            double dx = in->x[j][d] - in->x[i][d];
            r2 += dx * dx;
        }
        if (r2 < re2)
            ref = f[j];
    }
    return ref;
}

/* Sums over the neighbours of i: g = sum (f_j - ref) e_ij / r w, and, if m is
 * not NULL, m = sum e_ij (x) e_ij w and the sum of weights. */
static double grad_sums(const struct mps_ops_in *in, size_t i, const double *f, double ref,
                        double r_floor, double g[MPS_DIM], double m[MPS_DIM][MPS_DIM])
{
    const struct mps_nbr_list *nl = in->nl;
    const double re2 = in->re * in->re, rf2 = r_floor * r_floor;
    const double w_floor = r_floor > 0.0 ? in->re / r_floor - 1.0 : 0.0;
    double wsum = 0.0;
    for (int a = 0; a < MPS_DIM; a++) {
        g[a] = 0.0;
        if (m)
            for (int b = 0; b < MPS_DIM; b++)
                m[a][b] = 0.0;
    }
    for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
        int j = nl->j[k];
        if (!USE(in, j) || !PAIR(in, k))
            continue;
        double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])in->x, i, (size_t)j, dx);
        if (r2 >= re2 || r2 <= 0.0)
            continue;
        /* one division: w / r^2 = (re / r - 1) / r^2 from 1 / r. Divisions
         * bound this loop (it had one per term of m). */
        double ir = 1.0 / sqrt(r2), w = in->re * ir - 1.0, wr2 = w * ir * ir;
        if (r2 < rf2) { /* the pair read at r_floor: w / r^2 -> w(r_f) / (r_f r) */
            w = w_floor;
            wr2 = mps_divergence_floor_factor(r2, in->re, r_floor);
        }
        double s = (f[j] - ref) * wr2; /* (f_j-ref)/r * e * w = (f_j-ref) dx w / r^2 */
        for (int a = 0; a < MPS_DIM; a++)
            g[a] += s * dx[a];
        if (m)
            for (int a = 0; a < MPS_DIM; a++)
                for (int b = 0; b < MPS_DIM; b++)
                    m[a][b] += dx[a] * dx[b] * wr2;
        wsum += w;
    }
    return wsum;
}

void mps_ops_gradient(const struct mps_ops_in *in, double n0, const double *f, int use_min,
                      double r_floor, double (*grad)[MPS_DIM])
{
    const struct mps_nbr_list *nl = in->nl;
    const double coef = MPS_DIM / n0;
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        if (!QUERY(in, i))
            continue;
        double g[MPS_DIM];
        grad_sums(in, i, f, grad_ref(in, i, f, use_min), r_floor, g, NULL);
        for (int a = 0; a < MPS_DIM; a++)
            grad[i][a] = coef * g[a];
    }
}

void mps_ops_gradient_corrected(const struct mps_ops_in *in, double n0, const double *f,
                                int use_min, double cond_floor, double r_floor,
                                double (*grad)[MPS_DIM], unsigned char *fallback)
{
    const struct mps_nbr_list *nl = in->nl;
    const double coef = MPS_DIM / n0;
#if MPS_DIM == 2
    /* On a full lattice M = (1/n) sum e(x)e w = I/d, so det M = 1/d^2. */
    const double det_full = 1.0 / (MPS_DIM * MPS_DIM);
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        if (!QUERY(in, i))
            continue;
        double g[2], m[2][2];
        double ref = grad_ref(in, i, f, use_min);
        double wsum = grad_sums(in, i, f, ref, r_floor, g, m);
        double det = 0.0;
        if (wsum > 0.0) {
            /* Eq. 14-15: A = M^-1 with M normalised by n_i; the 1/n_i of the
             * bracket in Eq. 14 cancels against it. */
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++)
                    m[a][b] /= wsum;
            det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        }
        if (det > cond_floor * det_full) {
            double inv00 = m[1][1] / det, inv11 = m[0][0] / det, inv01 = -m[0][1] / det;
            grad[i][0] = (inv00 * g[0] + inv01 * g[1]) / wsum;
            grad[i][1] = (inv01 * g[0] + inv11 * g[1]) / wsum;
            if (fallback)
                fallback[i] = 0;
        } else {
            grad[i][0] = coef * g[0];
            grad[i][1] = coef * g[1];
            if (fallback)
                fallback[i] = 1;
        }
    }
#else
#error "mps_ops_gradient_corrected: only MPS_DIM == 2 is implemented"
#endif
}

void mps_ops_divergence(const struct mps_ops_in *in, double n0, const double (*f)[MPS_DIM],
                        double r_floor, double *div)
{
    const struct mps_nbr_list *nl = in->nl;
    const double re2 = in->re * in->re, coef = MPS_DIM / n0, rf2 = r_floor * r_floor;
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < nl->n; i++) {
        if (!QUERY(in, i))
            continue;
        double acc = 0.0;
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++) {
            int j = nl->j[k];
            if (!USE(in, j))
                continue;
            double dx[MPS_DIM], r2 = 0.0, dot = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                dx[d] = in->x[j][d] - in->x[i][d];
                r2 += dx[d] * dx[d];
            }
            if (r2 >= re2 || r2 <= 0.0)
                continue;
            for (int d = 0; d < MPS_DIM; d++)
                dot += (f[j][d] - f[i][d]) * dx[d];
            if (r2 < rf2) {
                acc += dot * mps_divergence_floor_factor(r2, in->re, r_floor);
                continue;
            }
            double ir = 1.0 / sqrt(r2); /* one division, as in grad_sums */
            acc += dot * ((in->re * ir - 1.0) * ir * ir);
        }
        div[i] = coef * acc;
    }
}
