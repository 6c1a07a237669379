/* Deflation by aggregates for CG on the PPE (Saad, Yeung, Erhel &
 * Guyomarc'h 2000; Tang, Nabben, Vuik & Erlangga 2009). Z is the n x m
 * indicator matrix of the aggregates (groups of rows close in space: the
 * fluid gives square cells of a few spacings), E = Z^T A Z the m x m coarse
 * matrix, factorised with CHOLMOD at every setup. The start is corrected so
 * that Z^T r = 0, and every search direction is made A-orthogonal to
 * range(Z): p = z + beta p - Z E^-1 (A Z)^T z. The coarse space carries the
 * smooth pressure modes that make CG's iteration count grow with
 * resolution; Jacobi handles the rest. Measured on the dam break
 * (docs/ppe_solvers.md): iterations stop growing with n. */
#include "fluid_defl.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "mps_mem.h"

struct fluid_defl {
    int nthreads, par_min_rows;
    /* aggregates (borrowed from the caller until the next solve), A Z
     * stored in A's row slots (azlen entries from rowptr[i]), (A Z)^T by
     * aggregate, the factor of E, per-thread work */
    const int *agg;
    int nagg, agg_n;     /* agg_n: rows the aggregates were given for */
    int *own_agg;        /* fallback: blocks of consecutive rows */
    size_t cap_own;
    int *azlen, *azcol;
    double *azval;
    int *amark;          /* per thread, per aggregate: last row seen and its slot */
    int *ztptr, *ztrow;  /* (A Z)^T in CSR: for each aggregate, the rows that touch it */
    double *ztval;
    size_t cap_ztptr, cap_zt;
    size_t cap_az, cap_azlen, cap_crhs, cap_amark;
    double *crhs;        /* coarse right-hand side, m */
    cholmod_common cm;
    cholmod_factor *Lc;
    cholmod_dense *Xc, *Yc, *Ec;
    int coarse_n;        /* size of the last coarse system (statistics) */
};

/* thread t of nt's contiguous block of n rows */
static inline void block(int n, int *lo, int *hi)
{
    int t = omp_get_thread_num(), nt = omp_get_num_threads();
    *lo = (int)((long long)n * t / nt);
    *hi = (int)((long long)n * (t + 1) / nt);
}

static enum mps_status coarse_fail(struct fluid_defl *s, const char *call, struct mps_err *err)
{
    int st = s->cm.status;
    return mps_err_set(err, st == CHOLMOD_OUT_OF_MEMORY ? MPS_ENOMEM : MPS_ELIB,
                       "pcg_defl: %s failed on the coarse matrix (CHOLMOD status %d)", call, st);
}

enum mps_status fluid_defl_create(struct fluid_defl **out, int nthreads, int par_min_rows,
                                  struct mps_err *err)
{
    *out = NULL;
    struct fluid_defl *s = calloc(1, sizeof *s);
    if (!s)
        return mps_err_set(err, MPS_ENOMEM, "pcg_defl: out of memory");
    s->nthreads = nthreads > 0 ? nthreads : 1;
    s->par_min_rows = par_min_rows;
    if (!cholmod_start(&s->cm)) {
        free(s);
        return mps_err_set(err, MPS_ELIB, "pcg_defl: cholmod_start failed");
    }
    s->cm.print = 0; /* errors come back through err, not stderr */
    /* simplicial: no BLAS (see direct() in fluid_linsolve.c on OpenBLAS
     * threads), and E is small and sparse; AMD alone, without trying other
     * orderings */
    s->cm.supernodal = CHOLMOD_SIMPLICIAL;
    s->cm.nmethods = 1;
    s->cm.method[0].ordering = CHOLMOD_AMD;
    *out = s;
    return MPS_OK;
}

void fluid_defl_destroy(struct fluid_defl **d)
{
    struct fluid_defl *s = d ? *d : NULL;
    if (!s)
        return;
    cholmod_free_factor(&s->Lc, &s->cm);
    cholmod_free_dense(&s->Xc, &s->cm);
    cholmod_free_dense(&s->Yc, &s->cm);
    cholmod_free_dense(&s->Ec, &s->cm);
    cholmod_finish(&s->cm);
    free(s->azlen);
    free(s->azcol);
    free(s->azval);
    free(s->crhs);
    free(s->amark);
    free(s->ztptr);
    free(s->ztrow);
    free(s->ztval);
    free(s->own_agg);
    free(s);
    *d = NULL;
}

enum mps_status fluid_defl_set_aggregates(struct fluid_defl *s, const int *agg, int n, int nagg,
                                          struct mps_err *err)
{
    if ((n > 0 && !agg) || n < 0 || nagg < 1 || nagg > (n > 0 ? n : 1))
        return mps_err_set(err, MPS_EINPUT,
                           "fluid_linsolve_set_aggregates: %d aggregates for %d rows: need "
                           "1 <= aggregates <= rows and an array", nagg, n);
    for (int i = 0; i < n; i++)
        if (agg[i] < 0 || agg[i] >= nagg)
            return mps_err_set(err, MPS_EINPUT,
                               "fluid_linsolve_set_aggregates: row %d: aggregate %d out of "
                               "range [0, %d)", i, agg[i], nagg);
    s->agg = agg;
    s->agg_n = n;
    s->nagg = nagg;
    return MPS_OK;
}

int fluid_defl_coarse_size(const struct fluid_defl *s)
{
    return s ? s->coarse_n : 0;
}

/* Fallback aggregates for a caller that gave none: DEFL_BLOCK consecutive
 * rows (particles sorted by cell are roughly local in index). */
#define DEFL_BLOCK 16

static enum mps_status defl_aggregates(struct fluid_defl *s, int n, struct mps_err *err)
{
    if (s->agg && s->agg_n == n)
        return MPS_OK;
    if ((size_t)n > s->cap_own) {
        int fail = 0;
        s->own_agg = mps_realloc_or_flag(s->own_agg, (size_t)n + (size_t)n / 8 + 1,
                                         sizeof *s->own_agg, &fail);
        if (fail)
            return mps_err_set(err, MPS_ENOMEM, "pcg_defl: cannot allocate aggregates for %d rows",
                               n);
        s->cap_own = (size_t)n + (size_t)n / 8 + 1;
    }
    for (int i = 0; i < n; i++)
        s->own_agg[i] = i / DEFL_BLOCK;
    s->agg = s->own_agg;
    s->agg_n = n;
    s->nagg = (n + DEFL_BLOCK - 1) / DEFL_BLOCK;
    return MPS_OK;
}

/* A Z (row i's distinct aggregates and the sums of its entries in each,
 * stored from rowptr[i]), E = Z^T A Z (upper triangle) and its factor. */
enum mps_status fluid_defl_setup(struct fluid_defl *s, const struct fluid_csr *A,
                                 struct mps_err *err)
{
    const int n = A->n;
    enum mps_status rc = defl_aggregates(s, n, err);
    if (rc)
        return rc;
    const int m = s->nagg, *agg = s->agg;
    const size_t nnz = (size_t)A->rowptr[n], nmark = 2 * (size_t)s->nthreads * (size_t)m;
    int fail = 0;
    if ((size_t)n > s->cap_azlen) {
        s->azlen = mps_realloc_or_flag(s->azlen, (size_t)n + (size_t)n / 8 + 1,
                                       sizeof *s->azlen, &fail);
        if (!fail)
            s->cap_azlen = (size_t)n + (size_t)n / 8 + 1;
    }
    if (nnz > s->cap_az) {
        s->azcol = mps_realloc_or_flag(s->azcol, nnz + nnz / 8 + 1, sizeof *s->azcol, &fail);
        s->azval = mps_realloc_or_flag(s->azval, nnz + nnz / 8 + 1, sizeof *s->azval, &fail);
        if (!fail)
            s->cap_az = nnz + nnz / 8 + 1;
    }
    if ((size_t)m > s->cap_crhs) {
        s->crhs = mps_realloc_or_flag(s->crhs, (size_t)m, sizeof *s->crhs, &fail);
        if (!fail)
            s->cap_crhs = (size_t)m;
    }
    if (nmark > s->cap_amark) {
        s->amark = mps_realloc_or_flag(s->amark, nmark, sizeof *s->amark, &fail);
        if (!fail)
            s->cap_amark = nmark;
    }
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "pcg_defl: cannot allocate the coarse space (%d rows, "
                                            "%d aggregates)", n, m);
    int *azlen = s->azlen, *azcol = s->azcol;
    double *azval = s->azval;
    long long total = 0;
#pragma omp parallel num_threads(s->nthreads) if (n >= s->par_min_rows) reduction(+ : total)
    {
        /* seen[a] = the last row that met aggregate a, slot[a] its place
         * in that row: one lookup per entry instead of a search */
        int *seen = s->amark + 2 * (size_t)omp_get_thread_num() * (size_t)m, *slot = seen + m;
        for (int a = 0; a < m; a++)
            seen[a] = -1;
#pragma omp for schedule(static)
        for (int i = 0; i < n; i++) {
            const int base = A->rowptr[i];
            int len = 0;
            for (int k = base; k < A->rowptr[i + 1]; k++) {
                int a = agg[A->col[k]];
                if (seen[a] != i) {
                    seen[a] = i;
                    slot[a] = base + len;
                    azcol[base + len] = a;
                    azval[base + len++] = 0.0;
                }
                azval[slot[a]] += A->val[k];
            }
            azlen[i] = len;
            total += len;
        }
    }

    /* (A Z)^T by rows: the projection's restriction then gathers per
     * aggregate instead of scattering per row (consecutive rows mostly hit
     * the same aggregate, and a scatter waits on its own last store) */
    if ((size_t)m + 1 > s->cap_ztptr) {
        s->ztptr = mps_realloc_or_flag(s->ztptr, (size_t)m + 1, sizeof *s->ztptr, &fail);
        if (!fail)
            s->cap_ztptr = (size_t)m + 1;
    }
    if ((size_t)total + 1 > s->cap_zt) {
        size_t c = (size_t)total + (size_t)total / 8 + 1;
        s->ztrow = mps_realloc_or_flag(s->ztrow, c, sizeof *s->ztrow, &fail);
        s->ztval = mps_realloc_or_flag(s->ztval, c, sizeof *s->ztval, &fail);
        if (!fail)
            s->cap_zt = c;
    }
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "pcg_defl: cannot allocate (A Z)^T (%lld entries)",
                           total);
    int *ztptr = s->ztptr;
    memset(ztptr, 0, ((size_t)m + 1) * sizeof *ztptr);
    for (int i = 0; i < n; i++)
        for (int q = 0; q < azlen[i]; q++)
            ztptr[azcol[A->rowptr[i] + q] + 1]++;
    for (int a = 0; a < m; a++)
        ztptr[a + 1] += ztptr[a];
    for (int i = 0; i < n; i++) {
        const int base = A->rowptr[i];
        for (int q = 0; q < azlen[i]; q++) {
            int at = ztptr[azcol[base + q]]++;
            s->ztrow[at] = i;
            s->ztval[at] = azval[base + q];
        }
    }
    for (int a = m; a > 0; a--)
        ztptr[a] = ztptr[a - 1];
    ztptr[0] = 0;

    cholmod_common *cm = &s->cm;
    cholmod_triplet *T = cholmod_allocate_triplet((size_t)m, (size_t)m, (size_t)total, 1,
                                                  CHOLMOD_REAL, cm);
    if (!T)
        return coarse_fail(s, "cholmod_allocate_triplet", err);
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    size_t t = 0;
    for (int i = 0; i < n; i++) {
        const int base = A->rowptr[i], ai = agg[i];
        for (int q = 0; q < azlen[i]; q++)
            if (ai <= azcol[base + q]) {   /* E is symmetric: its upper triangle */
                ti[t] = ai;
                tj[t] = azcol[base + q];
                tx[t++] = azval[base + q];
            }
    }
    T->nnz = t;
    cholmod_sparse *E = cholmod_triplet_to_sparse(T, t, cm);
    cholmod_free_triplet(&T, cm);
    if (!E)
        return coarse_fail(s, "cholmod_triplet_to_sparse", err);
    cholmod_free_factor(&s->Lc, cm);
    s->Lc = cholmod_analyze(E, cm);
    int ok = s->Lc && cm->status >= CHOLMOD_OK;
    if (ok)
        ok = cholmod_factorize(E, s->Lc, cm) && cm->status >= CHOLMOD_OK;
    int notpd = cm->status == CHOLMOD_NOT_POSDEF;
    cholmod_free_sparse(&E, cm);
    if (!ok || notpd) {
        if (notpd)
            rc = mps_err_set(err, MPS_ESOLVE,
                             "pcg_defl: the coarse matrix Z^T A Z (%d aggregates) is not positive "
                             "definite: A is not, or an aggregate has no row",
                             m);
        else
            rc = coarse_fail(s, !s->Lc ? "cholmod_analyze" : "cholmod_factorize", err);
        cholmod_free_factor(&s->Lc, cm);
        return rc;
    }
    s->coarse_n = m;
    return MPS_OK;
}

/* mu = E^-1 (Z^T v) (with_az = 0) or E^-1 ((A Z)^T v) (with_az = 1), into
 * s->Xc. The second, once per iteration, gathers per aggregate over (A Z)^T
 * in parallel. */
static enum mps_status defl_coarse(struct fluid_defl *s, const struct fluid_csr *A,
                                   const double *v, int with_az, const double **mu,
                                   struct mps_err *err)
{
    const int n = A->n, m = s->nagg, *agg = s->agg;
    double *rhs = s->crhs;
    if (with_az) {
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static)
        for (int a = 0; a < m; a++) {
            double sum = 0.0;
            for (int k = s->ztptr[a]; k < s->ztptr[a + 1]; k++)
                sum += s->ztval[k] * v[s->ztrow[k]];
            rhs[a] = sum;
        }
    } else {
        /* once per solve (and restart): serial */
        memset(rhs, 0, (size_t)m * sizeof *rhs);
        for (int i = 0; i < n; i++)
            rhs[agg[i]] += v[i];
    }
    cholmod_dense B = {0};
    B.nrow = B.nzmax = B.d = (size_t)m;
    B.ncol = 1;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    B.x = rhs;
    if (!cholmod_solve2(CHOLMOD_A, s->Lc, &B, NULL, &s->Xc, NULL, &s->Yc, &s->Ec, &s->cm) ||
        s->cm.status < CHOLMOD_OK)
        return coarse_fail(s, "cholmod_solve2 (coarse)", err);
    *mu = s->Xc->x;
    return MPS_OK;
}

/* x += Z c, r -= A Z c with c = E^-1 Z^T r, so that Z^T r = 0; returns r.r
 * in *rr. */
enum mps_status fluid_defl_start(struct fluid_defl *s, const struct fluid_csr *A, double *x,
                                 double *r, double *rr, struct mps_err *err)
{
    const double *c;
    enum mps_status rc = defl_coarse(s, A, r, 0, &c, err);
    if (rc)
        return rc;
    const int n = A->n, *agg = s->agg;
    double sum = 0.0;
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static) \
    reduction(+ : sum)
    for (int i = 0; i < n; i++) {
        const int base = A->rowptr[i];
        double azc = 0.0;
        for (int q = 0; q < s->azlen[i]; q++)
            azc += s->azval[base + q] * c[s->azcol[base + q]];
        x[i] += c[agg[i]];
        r[i] -= azc;
        sum += r[i] * r[i];
    }
    *rr = sum;
    return MPS_OK;
}

/* p -= Z E^-1 (A Z)^T z */
enum mps_status fluid_defl_project(struct fluid_defl *s, const struct fluid_csr *A,
                                   const double *z, double *p, struct mps_err *err)
{
    const double *mu;
    enum mps_status rc = defl_coarse(s, A, z, 1, &mu, err);
    if (rc)
        return rc;
    const int n = A->n, *agg = s->agg;
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static)
    for (int i = 0; i < n; i++)
        p[i] -= mu[agg[i]];
    return MPS_OK;
}

