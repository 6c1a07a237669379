#include "mps_nbr.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 256;
    while (c < need)
        c = c * 3 / 2 + 1;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

enum mps_status mps_nbr_grid_build(struct mps_nbr_grid *g, size_t n, const double (*x)[MPS_DIM],
                                   double cell, struct mps_err *err)
{
    double lo[MPS_DIM], hi[MPS_DIM];
    for (int d = 0; d < MPS_DIM; d++) {
        lo[d] = INFINITY;
        hi[d] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            double v = x[i][d];
            if (!isfinite(v))
                return mps_err_set(err, MPS_EDIVERGED,
                                   "particle %zu has a non-finite position (%g)", i, v);
            if (v < lo[d])
                lo[d] = v;
            if (v > hi[d])
                hi[d] = v;
        }
    if (n == 0)
        for (int d = 0; d < MPS_DIM; d++)
            lo[d] = hi[d] = 0.0;
    size_t ncells = 1;
    for (int d = 0; d < MPS_DIM; d++) {
        g->lo[d] = lo[d] - 0.5 * cell;
        double span = hi[d] - g->lo[d] + 0.5 * cell;
        double nd = floor(span / cell) + 1.0;
        if (nd > 1e7)
            return mps_err_set(err, MPS_EDIVERGED,
                               "particles spread over %g m along axis %d (%g cells): "
                               "a particle has flown away",
                               hi[d] - lo[d], d, nd);
        g->dims[d] = (int)nd;
        ncells *= (size_t)g->dims[d];
    }
    if (ncells > 200000000u)
        return mps_err_set(err, MPS_EDIVERGED, "neighbour grid would need %zu cells", ncells);
    g->cell = cell;
    g->ncells = ncells;
    g->n = n;
    if (grow((void **)&g->cell_start, &g->cap_cells, ncells + 1, sizeof(size_t)) ||
        grow((void **)&g->sorted, &g->cap_n, n + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory");
    /* cell_of shares cap_n with sorted; grow it to the same capacity. */
    size_t *co = realloc(g->cell_of, (g->cap_n) * sizeof(size_t));
    if (!co)
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory");
    g->cell_of = co;
    memset(g->cell_start, 0, (ncells + 1) * sizeof(size_t));
    double inv = 1.0 / cell;
    for (size_t i = 0; i < n; i++) {
        size_t c = 0;
        for (int d = MPS_DIM - 1; d >= 0; d--) {
            int k = (int)((x[i][d] - g->lo[d]) * inv);
            c = c * (size_t)g->dims[d] + (size_t)k;
        }
        g->cell_of[i] = c;
        g->cell_start[c + 1]++;
    }
    for (size_t c = 0; c < ncells; c++)
        g->cell_start[c + 1] += g->cell_start[c];
    /* Stable counting sort: particles stay in index order within a cell. */
    for (size_t i = 0; i < n; i++)
        g->sorted[g->cell_start[g->cell_of[i]]++] = i;
    for (size_t c = ncells; c > 0; c--)
        g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    return MPS_OK;
}

void mps_nbr_grid_free(struct mps_nbr_grid *g)
{
    free(g->cell_start);
    free(g->sorted);
    free(g->cell_of);
    memset(g, 0, sizeof *g);
}


/* Visits the neighbours of i; count-only when out is NULL. Returns count. */
static size_t visit(const struct mps_nbr_grid *g, const double (*x)[MPS_DIM], size_t i,
                    double r2max, int *jout, double *r2out)
{
    size_t c = g->cell_of[i];
    int ci[MPS_DIM];
    for (int d = 0; d < MPS_DIM; d++) {
        ci[d] = (int)(c % (size_t)g->dims[d]);
        c /= (size_t)g->dims[d];
    }
    size_t m = 0;
#if MPS_DIM == 2
    for (int b = ci[1] - 1; b <= ci[1] + 1; b++) {
        if (b < 0 || b >= g->dims[1])
            continue;
        int a0 = ci[0] > 0 ? ci[0] - 1 : 0;
        int a1 = ci[0] + 1 < g->dims[0] ? ci[0] + 1 : g->dims[0] - 1;
        size_t row = (size_t)b * (size_t)g->dims[0];
        /* cells a0..a1 of this row are contiguous in sorted[] */
        for (size_t k = g->cell_start[row + (size_t)a0]; k < g->cell_start[row + (size_t)a1 + 1];
             k++) {
            size_t j = g->sorted[k];
            if (j == i)
                continue;
            double dx = x[j][0] - x[i][0], dy = x[j][1] - x[i][1];
            double r2 = dx * dx + dy * dy;
            if (r2 < r2max) {
                if (jout) {
                    jout[m] = (int)j;
                    r2out[m] = r2;
                }
                m++;
            }
        }
    }
#else
#error "mps_nbr: only MPS_DIM == 2 is implemented"
#endif
    return m;
}

enum mps_status mps_nbr_list_build(struct mps_nbr_list *l, const struct mps_nbr_grid *g,
                                   const double (*x)[MPS_DIM], size_t nquery, double radius,
                                   struct mps_err *err)
{
    if (radius > g->cell * (1.0 + 1e-12))
        return mps_err_set(err, MPS_EINPUT, "neighbour radius %g exceeds cell width %g", radius,
                           g->cell);
    if (grow((void **)&l->start, &l->cap_n, nquery + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    double r2max = radius * radius;
    l->n = nquery;
    l->radius = radius;
    l->start[0] = 0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nquery; i++)
        l->start[i + 1] = visit(g, x, i, r2max, NULL, NULL);
    for (size_t i = 0; i < nquery; i++)
        l->start[i + 1] += l->start[i];
    size_t npairs = l->start[nquery];
    size_t cap = l->cap_pairs;
    if (grow((void **)&l->j, &cap, npairs + 1, sizeof(int)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory for %zu pairs", npairs);
    size_t cap2 = l->cap_pairs;
    if (grow((void **)&l->r2, &cap2, npairs + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory for %zu pairs", npairs);
    l->cap_pairs = cap < cap2 ? cap : cap2;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nquery; i++) {
        size_t s = l->start[i];
        size_t m = visit(g, x, i, r2max, l->j + s, l->r2 + s);
        /* sort by j, carrying r2 along (lists are short: insertion sort) */
        for (size_t a = 1; a < m; a++) {
            int jj = l->j[s + a];
            double rr = l->r2[s + a];
            size_t b = a;
            while (b > 0 && l->j[s + b - 1] > jj) {
                l->j[s + b] = l->j[s + b - 1];
                l->r2[s + b] = l->r2[s + b - 1];
                b--;
            }
            l->j[s + b] = jj;
            l->r2[s + b] = rr;
        }
    }
    return MPS_OK;
}

enum mps_status mps_nbr_list_filter(struct mps_nbr_list *dst, const struct mps_nbr_list *src,
                                    const double (*x)[MPS_DIM], double radius,
                                    struct mps_err *err)
{
    const size_t n = src->n;
    const double r2max = radius * radius;
    if (grow((void **)&dst->start, &dst->cap_n, n + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    dst->n = n;
    dst->radius = radius;
    dst->start[0] = 0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        size_t m = 0;
        for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
            int j = src->j[k];
            double r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = x[j][d] - x[i][d];
                r2 += dx * dx;
            }
            m += r2 < r2max;
        }
        dst->start[i + 1] = m;
    }
    for (size_t i = 0; i < n; i++)
        dst->start[i + 1] += dst->start[i];
    size_t npairs = dst->start[n], cap = dst->cap_pairs, cap2 = dst->cap_pairs;
    if (grow((void **)&dst->j, &cap, npairs + 1, sizeof(int)) ||
        grow((void **)&dst->r2, &cap2, npairs + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory for %zu pairs", npairs);
    dst->cap_pairs = cap < cap2 ? cap : cap2;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        size_t m = dst->start[i];
        for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
            int j = src->j[k];
            double r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = x[j][d] - x[i][d];
                r2 += dx * dx;
            }
            if (r2 < r2max) {
                dst->j[m] = j;
                dst->r2[m++] = r2;
            }
        }
    }
    return MPS_OK;
}

void mps_nbr_list_free(struct mps_nbr_list *l)
{
    free(l->start);
    free(l->j);
    free(l->r2);
    memset(l, 0, sizeof *l);
}

void mps_nbr_cell_order(const struct mps_nbr_grid *g, size_t *perm)
{
    memcpy(perm, g->sorted, g->n * sizeof(size_t));
}
