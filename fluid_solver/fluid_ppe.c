#include "fluid_ppe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mps_kernel.h"

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = need + need / 2 + 16;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

/* Pass 1 for row particle i: caches c w_ij in f->wlap for the Laplacian
 * neighbours that carry a pressure (0 for the others), returns the number of
 * unknown neighbours and their summed weight in *diag. */
static int row_weights(struct fluid *f, size_t i, double c, double *diag)
{
    const double re = f->prm.re_lap * f->prm.dp, re2 = re * re;
    int m = 0;
    double dsum = 0.0;
    for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
        int j = f->nl.j[k];
        double cw = 0.0;
        if (f->has_p[j]) {
            double dx = f->x[j][0] - f->x[i][0], dy = f->x[j][1] - f->x[i][1];
            double r2 = dx * dx + dy * dy;
            if (r2 < re2) {
                cw = c * mps_weight(sqrt(r2), re);
                dsum += cw;
                /* same predicate as pass 2: r == re rounds to w = 0 */
                m += cw > 0.0 && f->row[j] >= 0;
            }
        }
        f->wlap[k] = cw;
    }
    *diag = dsum;
    return m;
}

enum mps_status fluid_ppe_assemble(struct fluid *f, double dt, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    const size_t n = f->ps.n;
    int nrows = 0;
    for (size_t i = 0; i < n; i++)
        f->row[i] = (f->has_p[i] && !f->surface[i]) ? nrows++ : -1;
    f->nrows = nrows;

    size_t rcap = f->cap_rows;
    if (grow((void **)&f->rowptr, &rcap, (size_t)nrows + 1, sizeof(int)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows", nrows);
    size_t rcap2 = f->cap_rows, rcap3 = f->cap_rows;
    if (grow((void **)&f->rhs, &rcap2, (size_t)nrows + 1, sizeof(double)) ||
        grow((void **)&f->sol, &rcap3, (size_t)nrows + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows", nrows);
    f->cap_rows = rcap < rcap2 ? (rcap < rcap3 ? rcap : rcap3) : (rcap2 < rcap3 ? rcap2 : rcap3);

    const double c = 2.0 * MPS_DIM / (f->lambda_lap * f->n0_lap);
    const double comp = p->rho * p->alpha / (dt * dt);
    const double src = p->kappa * p->rho / (dt * dt) / f->n0;
    const int mixed = p->mixed_source;
    const double div_coef = p->rho / dt;

    /* pass 1: weights, and entries per row (+1 for the diagonal); the
     * diagonal sum goes to rhs temporarily */
    size_t npairs = f->nl.start[f->nl.n];
    if (grow((void **)&f->wlap, &f->cap_wlap, npairs + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %zu pairs", npairs);
    int *rowptr = f->rowptr;
    rowptr[0] = 0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        if (f->row[i] >= 0)
            rowptr[f->row[i] + 1] = row_weights(f, i, c, &f->rhs[f->row[i]]) + 1;
    for (int r = 0; r < nrows; r++)
        rowptr[r + 1] += rowptr[r];
    size_t nnz = (size_t)rowptr[nrows], ccap = f->cap_nnz, vcap = f->cap_nnz;
    if (grow((void **)&f->col, &ccap, nnz + 1, sizeof(int)) ||
        grow((void **)&f->val, &vcap, nnz + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %zu nonzeros", nnz);
    f->cap_nnz = ccap < vcap ? ccap : vcap;

    /* pass 2: values. Neighbour lists are sorted by particle index and rows
     * follow particle order, so columns come out sorted; the diagonal is
     * inserted in its place. */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        int r = f->row[i];
        if (r < 0)
            continue;
        int s = rowptr[r], m = rowptr[r + 1] - s - 1;
        int *cols = f->col + s;
        double *vals = f->val + s, diag = f->rhs[r];
        int q = 1;
        for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
            int j = f->nl.j[k];
            if (f->wlap[k] != 0.0 && f->row[j] >= 0) {
                cols[q] = f->row[j];
                vals[q++] = -f->wlap[k];
            }
        }
        int k = 0;
        while (k < m && cols[k + 1] < r) {
            cols[k] = cols[k + 1];
            vals[k] = vals[k + 1];
            k++;
        }
        cols[k] = r;
        vals[k] = diag + comp;
        f->rhs[r] = src * (f->nd[i] - f->n0) - (mixed ? f->div[i] * div_coef : 0.0);
        f->sol[r] = f->p[i]; /* warm start */
    }
    return MPS_OK;
}

enum mps_status fluid_ppe_solve(struct fluid *f, struct fluid_linsolve_stats *stats,
                                struct mps_err *err)
{
    struct fluid_csr A = {f->nrows, f->rowptr, f->col, f->val};
    enum mps_status st = MPS_OK;
    if (f->nrows > 0) {
        st = fluid_linsolve_solve(f->ls, &A, f->rhs, f->sol, stats, err);
        if (st)
            return mps_err_prefix(err, "PPE at t = %.6g s (%d unknowns): ", f->time, f->nrows);
    } else {
        *stats = (struct fluid_linsolve_stats){0};
    }
    const int clamp = f->prm.clamp_negative;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->ps.n; i++) {
        int r = f->row[i];
        double pi = r >= 0 ? f->sol[r] : 0.0;
        f->p[i] = (clamp && pi < 0.0) ? 0.0 : pi;
    }
    return st;
}

enum mps_status fluid_ppe_dump(const struct fluid *f, const char *matrix_path,
                               const char *rhs_path, struct mps_err *err)
{
    FILE *m = fopen(matrix_path, "w");
    if (!m)
        return mps_err_set(err, MPS_EIO, "%s: cannot write", matrix_path);
    size_t lower = 0;
    for (int r = 0; r < f->nrows; r++)
        for (int k = f->rowptr[r]; k < f->rowptr[r + 1]; k++)
            lower += f->col[k] <= r;
    fprintf(m, "%%%%MatrixMarket matrix coordinate real symmetric\n%d %d %zu\n", f->nrows,
            f->nrows, lower);
    for (int r = 0; r < f->nrows; r++)
        for (int k = f->rowptr[r]; k < f->rowptr[r + 1]; k++)
            if (f->col[k] <= r)
                fprintf(m, "%d %d %.17g\n", r + 1, f->col[k] + 1, f->val[k]);
    int bad = fclose(m);
    FILE *b = fopen(rhs_path, "w");
    if (bad || !b)
        return mps_err_set(err, MPS_EIO, "%s: cannot write", bad ? matrix_path : rhs_path);
    fprintf(b, "%%%%MatrixMarket matrix array real general\n%d 1\n", f->nrows);
    for (int r = 0; r < f->nrows; r++)
        fprintf(b, "%.17g\n", f->rhs[r]);
    if (fclose(b))
        return mps_err_set(err, MPS_EIO, "%s: cannot write", rhs_path);
    return MPS_OK;
}
