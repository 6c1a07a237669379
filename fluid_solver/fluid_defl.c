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
#include "mps_omp.h"

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
    int *ztptr, *ztrow;  /* (A Z)^T in CSR: for each aggregate, the rows that touch it */
    double *ztval;
    /* for a set-up of new values on the same pattern (fluid_defl_setup's
     * same_pattern): each entry of A's slot in its row's A Z list, and each
     * A Z entry's place in (A Z)^T */
    int *entslot, *azpos;
    int pattern_n, pattern_nagg;   /* rows and aggregates they hold for; -1: none */
    size_t pattern_nnz;
    const int *pattern_agg;
    int *ecount;         /* entries of E's column a (upper triangle) */
    int *ecols;          /* a refill of some rows: E's columns they touch, m */
    cholmod_sparse *E;   /* the last set-up's E, kept: a refill has its pattern */
    int *mark;           /* per thread, per aggregate: stamp, slot, count */
    size_t cap_m, cap_n, cap_az, cap_zt, cap_mark;
    double *crhs;        /* coarse right-hand side, m */
    cholmod_common cm;
    cholmod_factor *Lc;
    cholmod_dense *Xc, *Yc, *Ec;
    int coarse_n;        /* size of the last coarse system (statistics) */
};

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
    s->pattern_n = -1;
    s->cm.print = 0; /* errors come back through err, not stderr */
    /* simplicial: no BLAS (see direct() in fluid_linsolve.c on OpenBLAS
     * threads), and E is small and sparse; one ordering, without trying
     * others: fluid_defl_setup picks AMD or E's own order (NATURAL_MAX_BW) */
    s->cm.supernodal = CHOLMOD_SIMPLICIAL;
    s->cm.nmethods = 1;
    *out = s;
    return MPS_OK;
}

void fluid_defl_destroy(struct fluid_defl **d)
{
    struct fluid_defl *s = d ? *d : NULL;
    if (!s)
        return;
    cholmod_free_factor(&s->Lc, &s->cm);
    cholmod_free_sparse(&s->E, &s->cm);
    cholmod_free_dense(&s->Xc, &s->cm);
    cholmod_free_dense(&s->Yc, &s->cm);
    cholmod_free_dense(&s->Ec, &s->cm);
    cholmod_finish(&s->cm);
    free(s->azlen);
    free(s->azcol);
    free(s->azval);
    free(s->entslot);
    free(s->azpos);
    free(s->ztptr);
    free(s->ztrow);
    free(s->ztval);
    free(s->ecount);
    free(s->ecols);
    free(s->mark);
    free(s->crhs);
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

/* E is factorised in its own order, without AMD, when its half bandwidth is
 * at most this. AMD and the analysis around it cost about 0.7 us per
 * coarse row (160 us for 214 rows on the 3.5 mm dam break, more than the
 * factorisation), while a band factor costs about m bw^2 / 2 flops:
 * measured, analysis and factorisation at m = 214 / 817 / 227 / 842 and
 * bw = 14 / 36 / 64 / 94, natural 44 / 306 / 162 / 813 us, AMD 162 / 617 /
 * 139 / 657 us. */
#define NATURAL_MAX_BW 40

/* Adds v to entry `key` of the list being accumulated at keys/vals[0 ..
 * *len): stamp[key] == tag marks a key already in the list, at slot[key].
 * Without a data-dependent branch (whether a key is new follows no pattern
 * a predictor can learn): a key that is not new still writes itself and a
 * zero into the first free slot, which the next new key overwrites, so the
 * list needs room for one entry per call. */
static inline int accumulate(int key, double v, int tag, int *stamp, int *slot, int *keys,
                             double *vals, int *len)
{
    const int fresh = stamp[key] != tag, at = fresh ? *len : slot[key];
    stamp[key] = tag;
    slot[key] = at;
    keys[*len] = key;
    vals[*len] = 0.0;
    vals[at] += v;
    *len += fresh;
    return at;
}

/* Sorts keys (and their values) by key: E's columns are a few tens long. */
static void sort_column(int *keys, double *vals, int len)
{
    for (int q = 1; q < len; q++) {
        int k = keys[q];
        double v = vals[q];
        int t = q - 1;
        for (; t >= 0 && keys[t] > k; t--) {
            keys[t + 1] = keys[t];
            vals[t + 1] = vals[t];
        }
        keys[t + 1] = k;
        vals[t + 1] = v;
    }
}

/* Column a of E's upper triangle into rows/vals (its ecount[a] slots):
 * summed over (A Z)^T's row a in its order, then sorted, so that a column
 * built again from the same values is the same to the bit. stamp, slot: m
 * ints each, no stamp equal to a on entry. */
static void coarse_column(const struct fluid_defl *s, int a, int *stamp, int *slot, int *rows,
                          double *vals)
{
    const int *agg = s->agg;
    int len = 0;
    for (int k = s->ztptr[a]; k < s->ztptr[a + 1]; k++) {
        int b = agg[s->ztrow[k]];
        if (b > a)
            continue;
        if (stamp[b] != a) {   /* branches here: the column has exactly ecount[a] slots */
            stamp[b] = a;
            slot[b] = len;
            rows[len] = b;
            vals[len++] = 0.0;
        }
        vals[slot[b]] += s->ztval[k];
    }
    sort_column(rows, vals, len);
}

/* E's upper triangle in CHOLMOD's CSC from (A Z)^T: column a holds, for each
 * aggregate b <= a, E_ba = sum over the entries of (A Z)^T row a whose row
 * lies in b. A count pass sizes the columns, a second fills them. */
static cholmod_sparse *coarse_matrix(struct fluid_defl *s, int n, struct mps_err *err,
                                     enum mps_status *rc)
{
    const int m = s->nagg, *agg = s->agg, *ztptr = s->ztptr, *ztrow = s->ztrow;
#pragma omp parallel num_threads(s->nthreads) if (n >= s->par_min_rows)
    {
        int *stamp = s->mark + (size_t)omp_get_thread_num() * 3 * (size_t)m;
        for (int b = 0; b < m; b++)
            stamp[b] = -1;
#pragma omp for schedule(static)
        for (int a = 0; a < m; a++) {
            int cnt = 0;
            for (int k = ztptr[a]; k < ztptr[a + 1]; k++) {
                int b = agg[ztrow[k]];
                cnt += b <= a && stamp[b] != a;
                stamp[b] = b <= a ? a : stamp[b];
            }
            s->ecount[a] = cnt;
        }
    }
    size_t nz = 0;
    for (int a = 0; a < m; a++)
        nz += (size_t)s->ecount[a];
    cholmod_sparse *E = cholmod_allocate_sparse((size_t)m, (size_t)m, nz, 1, 1, 1, CHOLMOD_REAL,
                                                &s->cm);
    if (!E) {
        *rc = coarse_fail(s, "cholmod_allocate_sparse", err);
        return NULL;
    }
    int *ep = E->p, *ei = E->i;
    double *ex = E->x;
    ep[0] = 0;
    for (int a = 0; a < m; a++)
        ep[a + 1] = ep[a] + s->ecount[a];
#pragma omp parallel num_threads(s->nthreads) if (n >= s->par_min_rows)
    {
        int *stamp = s->mark + (size_t)omp_get_thread_num() * 3 * (size_t)m, *slot = stamp + m;
        for (int b = 0; b < m; b++)
            stamp[b] = -1;
#pragma omp for schedule(static)
        for (int a = 0; a < m; a++)
            coarse_column(s, a, stamp, slot, ei + ep[a], ex + ep[a]);
    }
    return E;
}

static enum mps_status coarse_factor(struct fluid_defl *s, int n, struct mps_err *err);

/* Row i of A Z from A's row i, summed in the order the full set-up used
 * (entslot), and written to its places in (A Z)^T (azpos). */
static void refill_row(struct fluid_defl *s, const struct fluid_csr *A, int i)
{
    const int base = A->rowptr[i];
    double *v = s->azval + base;
    for (int q = 0; q < s->azlen[i]; q++)
        v[q] = 0.0;
    for (int k = base; k < A->rowptr[i + 1]; k++)
        v[s->entslot[k]] += A->val[k];
    for (int q = 0; q < s->azlen[i]; q++)
        s->ztval[s->azpos[base + q]] = v[q];
}

static enum mps_status coarse_refill(struct fluid_defl *s, const struct fluid_csr *A,
                                     const int *rows, int nrows, struct mps_err *err);

/* A Z (row i's distinct aggregates and the sums of its entries in each,
 * stored from rowptr[i]), (A Z)^T, E = Z^T A Z (upper triangle) and its
 * factor, all but the factor in parallel. The transpose is a counting sort
 * by aggregate over the threads' blocks of rows in order, so the rows of
 * each aggregate come out sorted: the projection's gather then reads the
 * vector in order (unsorted, it waited on the loads: 5.5% of the 80k-particle
 * dam break's samples against 2%). */
enum mps_status fluid_defl_setup(struct fluid_defl *s, const struct fluid_csr *A,
                                 int same_pattern, const int *rows, int nrows,
                                 struct mps_err *err)
{
    const int n = A->n;
    enum mps_status rc = defl_aggregates(s, n, err);
    if (rc)
        return rc;
    const int m = s->nagg, *agg = s->agg;
    const size_t nnz = (size_t)A->rowptr[n], mark_need = (size_t)s->nthreads * 3 * (size_t)m;
    int fail = 0;
    if ((size_t)m + 1 > s->cap_m) {
        size_t c = (size_t)m + (size_t)m / 8 + 2;
        s->ztptr = mps_realloc_or_flag(s->ztptr, c, sizeof *s->ztptr, &fail);
        s->ecount = mps_realloc_or_flag(s->ecount, c, sizeof *s->ecount, &fail);
        s->crhs = mps_realloc_or_flag(s->crhs, c, sizeof *s->crhs, &fail);
        s->ecols = mps_realloc_or_flag(s->ecols, c, sizeof *s->ecols, &fail);
        if (!fail)
            s->cap_m = c;
    }
    if ((size_t)n > s->cap_n) {
        size_t c = (size_t)n + (size_t)n / 8 + 1;
        s->azlen = mps_realloc_or_flag(s->azlen, c, sizeof *s->azlen, &fail);
        if (!fail)
            s->cap_n = c;
    }
    if (nnz > s->cap_az) {
        size_t c = nnz + nnz / 8 + 1;
        s->azcol = mps_realloc_or_flag(s->azcol, c, sizeof *s->azcol, &fail);
        s->azval = mps_realloc_or_flag(s->azval, c, sizeof *s->azval, &fail);
        s->entslot = mps_realloc_or_flag(s->entslot, c, sizeof *s->entslot, &fail);
        s->azpos = mps_realloc_or_flag(s->azpos, c, sizeof *s->azpos, &fail);
        s->pattern_n = -1;
        if (!fail)
            s->cap_az = c;
    }
    if (mark_need > s->cap_mark) {
        s->mark = mps_realloc_or_flag(s->mark, mark_need, sizeof *s->mark, &fail);
        if (!fail)
            s->cap_mark = mark_need;
    }
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "pcg_defl: cannot allocate the coarse space (%d rows, "
                                            "%d aggregates)", n, m);
    int *azlen = s->azlen, *azcol = s->azcol, *ztptr = s->ztptr;
    double *azval = s->azval;
    if (same_pattern && s->pattern_n == n && s->pattern_nnz == nnz && s->pattern_agg == agg &&
        s->pattern_nagg == m) {
        /* the last set-up's lists, refilled in the order it summed them:
         * the same A Z and E, to the bit, as a full set-up would give */
        if (!rows) {
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static)
            for (int i = 0; i < n; i++)
                refill_row(s, A, i);
        } else {
#pragma omp parallel for num_threads(s->nthreads) if (nrows >= s->par_min_rows) schedule(static)
            for (int k = 0; k < nrows; k++)
                refill_row(s, A, rows[k]);
        }
        if (!s->E || !s->Lc)
            return coarse_factor(s, n, err);
        return coarse_refill(s, A, rows, nrows, err);
    }
    s->pattern_n = -1;
#pragma omp parallel num_threads(s->nthreads) if (n >= s->par_min_rows)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        int *stamp = s->mark + (size_t)t * 3 * (size_t)m, *slot = stamp + m, *count = slot + m;
        for (int a = 0; a < m; a++) {
            stamp[a] = -1;
            count[a] = 0;
        }
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        for (int i = lo; i < hi; i++) {
            const int base = A->rowptr[i];
            int len = 0;
            for (int k = base; k < A->rowptr[i + 1]; k++)
                s->entslot[k] = accumulate(agg[A->col[k]], A->val[k], i, stamp, slot,
                                           azcol + base, azval + base, &len);
            azlen[i] = len;
            for (int q = 0; q < len; q++)
                count[azcol[base + q]]++;
        }
#pragma omp barrier
#pragma omp single
        {
            /* aggregate a's rows: thread 0's, then thread 1's, ... */
            int at = 0;
            for (int a = 0; a < m; a++) {
                ztptr[a] = at;
                for (int u = 0; u < nt; u++) {
                    int *cu = s->mark + (size_t)u * 3 * (size_t)m + 2 * (size_t)m;
                    int c = cu[a];
                    cu[a] = at;
                    at += c;
                }
            }
            ztptr[m] = at;
            if ((size_t)at + 1 > s->cap_zt) {
                size_t c = (size_t)at + (size_t)at / 8 + 1;
                s->ztrow = mps_realloc_or_flag(s->ztrow, c, sizeof *s->ztrow, &fail);
                s->ztval = mps_realloc_or_flag(s->ztval, c, sizeof *s->ztval, &fail);
                if (!fail)
                    s->cap_zt = c;
            }
        }
        if (!fail)
            for (int i = lo; i < hi; i++) {
                const int base = A->rowptr[i];
                for (int q = 0; q < azlen[i]; q++) {
                    int to = count[azcol[base + q]]++;
                    s->azpos[base + q] = to;
                    s->ztrow[to] = i;
                    s->ztval[to] = azval[base + q];
                }
            }
    }
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "pcg_defl: cannot allocate (A Z)^T (%d entries)",
                           ztptr[m]);
    s->pattern_n = n;
    s->pattern_nnz = nnz;
    s->pattern_agg = agg;
    s->pattern_nagg = m;
    return coarse_factor(s, n, err);
}

/* E's factor from the values now in s->E, on the symbolic factor s->Lc:
 * CHOLMOD keeps the analysis for a matrix of the same pattern. On failure
 * E and the factor are dropped (the next set-up builds them again). */
static enum mps_status coarse_numeric(struct fluid_defl *s, struct mps_err *err)
{
    cholmod_common *cm = &s->cm;
    enum mps_status rc = MPS_OK;
    int ok = cholmod_factorize(s->E, s->Lc, cm) && cm->status >= CHOLMOD_OK;
    if (ok && cm->status != CHOLMOD_NOT_POSDEF) {
        s->coarse_n = s->nagg;
        return MPS_OK;
    }
    if (cm->status == CHOLMOD_NOT_POSDEF)
        rc = mps_err_set(err, MPS_ESOLVE,
                         "pcg_defl: the coarse matrix Z^T A Z (%d aggregates) is not positive "
                         "definite: A is not, or an aggregate has no row",
                         s->nagg);
    else
        rc = coarse_fail(s, "cholmod_factorize", err);
    cholmod_free_factor(&s->Lc, cm);
    cholmod_free_sparse(&s->E, cm);
    return rc;
}

/* E's columns that the given rows of A Z touch (all of them for rows =
 * NULL) built again in the kept E, and its factor on the kept analysis:
 * E's pattern is the last set-up's. Each column is built as the full
 * set-up builds it, so the factor is the same to the bit. */
static enum mps_status coarse_refill(struct fluid_defl *s, const struct fluid_csr *A,
                                     const int *rows, int nrows, struct mps_err *err)
{
    const int m = s->nagg;
    int *cols = s->ecols, ncols = m;
    if (rows) {
        int *seen = s->mark; /* thread 0's stamps, reset below */
        memset(seen, 0, (size_t)m * sizeof *seen);
        ncols = 0;
        for (int k = 0; k < nrows; k++) {
            const int base = A->rowptr[rows[k]];
            for (int q = 0; q < s->azlen[rows[k]]; q++) {
                const int a = s->azcol[base + q];
                if (!seen[a]) {
                    seen[a] = 1;
                    cols[ncols++] = a;
                }
            }
        }
    }
    const int *ep = s->E->p;
    int *ei = s->E->i;
    double *ex = s->E->x;
#pragma omp parallel num_threads(s->nthreads) if (ncols >= s->par_min_rows)
    {
        int *stamp = s->mark + (size_t)omp_get_thread_num() * 3 * (size_t)m, *slot = stamp + m;
        for (int b = 0; b < m; b++)
            stamp[b] = -1;
#pragma omp for schedule(static)
        for (int c = 0; c < ncols; c++) {
            const int a = rows ? cols[c] : c;
            coarse_column(s, a, stamp, slot, ei + ep[a], ex + ep[a]);
        }
    }
    return coarse_numeric(s, err);
}

/* E from (A Z)^T, its analysis and its factor */
static enum mps_status coarse_factor(struct fluid_defl *s, int n, struct mps_err *err)
{
    enum mps_status rc = MPS_OK;
    const int m = s->nagg;
    cholmod_common *cm = &s->cm;
    cholmod_free_sparse(&s->E, cm);
    cholmod_free_factor(&s->Lc, cm);
    cholmod_sparse *E = coarse_matrix(s, n, err, &rc);
    if (!E)
        return rc;
    int bw = 0; /* E's half bandwidth: column a's rows are sorted, the first is the farthest */
    for (int a = 0; a < m; a++) {
        const int *ep = E->p, *ei = E->i;
        if (ep[a + 1] > ep[a] && a - ei[ep[a]] > bw)
            bw = a - ei[ep[a]];
    }
    cm->method[0].ordering = bw <= NATURAL_MAX_BW ? CHOLMOD_NATURAL : CHOLMOD_AMD;
    s->E = E;
    s->Lc = cholmod_analyze(E, cm);
    if (!s->Lc || cm->status < CHOLMOD_OK) {
        rc = coarse_fail(s, "cholmod_analyze", err);
        cholmod_free_factor(&s->Lc, cm);
        cholmod_free_sparse(&s->E, cm);
        return rc;
    }
    return coarse_numeric(s, err);
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

/* p = z + beta p - Z E^-1 (A Z)^T z in one pass (beta = 0: p = z - ..., p's
 * old content unread) */
enum mps_status fluid_defl_direction(struct fluid_defl *s, const struct fluid_csr *A,
                                     const double *z, double beta, double *p, struct mps_err *err)
{
    const double *mu;
    enum mps_status rc = defl_coarse(s, A, z, 1, &mu, err);
    if (rc)
        return rc;
    const int n = A->n, *agg = s->agg;
    if (beta == 0.0) {
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static)
        for (int i = 0; i < n; i++)
            p[i] = z[i] - mu[agg[i]];
    } else {
#pragma omp parallel for num_threads(s->nthreads) if (n >= s->par_min_rows) schedule(static)
        for (int i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i] - mu[agg[i]];
    }
    return MPS_OK;
}
