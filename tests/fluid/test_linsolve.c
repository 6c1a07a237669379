/* fluid_linsolve: every method on a PPE-like matrix (jittered 2D lattice,
 * MPS weight w = re/r - 1 within re = 4 l0, top row free surface), checked
 * with an independent residual, against each other, warm starts, ordering
 * reuse across patterns, and the error paths. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_linsolve.h"
#include "../test_util.h"

static const char *const methods[] = {"pcg_jacobi", "pcg_ic0", "cholmod", "cholmod_reuse", "auto",
                                      "pcg_sic0", "pcg_defl"};
#define NMETHODS 7

struct mat {
    int n, *rowptr, *col;
    double *val;
    double *y;   /* height of each unknown's particle, for a hydrostatic test solution */
    struct fluid_csr csr;
};

static unsigned long long rng_state = 88172645463325252ull;
static double urand(void)   /* xorshift64, uniform in [0, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

/* nx x ny particles, spacing 1, uniform jitter +-jitter, then every particle
 * moved by (drift, 0.5 drift) * sin(...) so a second call with another drift
 * gives the same n but a different pattern. The top lattice row is the free
 * surface (p = 0, no unknown). a_ii = (1 + eps) sum_j w_ij over all
 * neighbours, a_ij = -w_ij between unknowns. */
static void build(struct mat *m, int nx, int ny, double jitter, double drift, double eps)
{
    const double re = 4.0;
    int np = nx * ny;
    double (*x)[2] = malloc((size_t)np * sizeof *x);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double *p = x[j * nx + i];
            p[0] = i + jitter * (2.0 * urand() - 1.0);
            p[1] = j + jitter * (2.0 * urand() - 1.0);
            p[0] += drift * sin(0.3 * p[1]);
            p[1] += 0.5 * drift * sin(0.2 * p[0]);
        }
    int n = nx * (ny - 1);   /* unknowns: all but the top row, numbered row-major */
    m->n = n;
    m->rowptr = malloc((size_t)(n + 1) * sizeof *m->rowptr);
    m->col = malloc((size_t)n * 100 * sizeof *m->col);
    m->val = malloc((size_t)n * 100 * sizeof *m->val);
    m->y = malloc((size_t)n * sizeof *m->y);
    int nz = 0, w = 6;   /* lattice window: re + drift + jitter < 6 */
    m->rowptr[0] = 0;
    for (int a = 0; a < n; a++) {
        int ai = a % nx, aj = a / nx, dpos = -1;
        double sum = 0.0;
        for (int bj = aj - w; bj <= aj + w; bj++)
            for (int bi = ai - w; bi <= ai + w; bi++) {
                if (bi < 0 || bi >= nx || bj < 0 || bj >= ny)
                    continue;
                int b = bj * nx + bi;
                if (b == a) {
                    dpos = nz;
                    m->col[nz] = a;
                    m->val[nz++] = 0.0;
                    continue;
                }
                double dx = x[b][0] - x[a][0], dy = x[b][1] - x[a][1];
                double r = sqrt(dx * dx + dy * dy);
                if (r >= re)
                    continue;
                double wij = re / r - 1.0;
                sum += wij;
                if (bj < ny - 1) {
                    m->col[nz] = b;
                    m->val[nz++] = -wij;
                }
            }
        m->val[dpos] = (1.0 + eps) * sum;
        m->rowptr[a + 1] = nz;
        m->y[a] = x[a][1];
    }
    m->csr = (struct fluid_csr){n, m->rowptr, m->col, m->val};
    free(x);
}

/* dst = src without the off-diagonal couplings weaker than wmin (a pattern
 * subset, as if re had shrunk a little; the matrix stays symmetric). */
static void drop_weak(struct mat *dst, const struct mat *src, double wmin)
{
    size_t nnz = (size_t)src->rowptr[src->n];
    dst->n = src->n;
    dst->rowptr = malloc((size_t)(src->n + 1) * sizeof *dst->rowptr);
    dst->col = malloc(nnz * sizeof *dst->col);
    dst->val = malloc(nnz * sizeof *dst->val);
    dst->y = malloc((size_t)src->n * sizeof *dst->y);
    memcpy(dst->y, src->y, (size_t)src->n * sizeof *dst->y);
    int nz = 0;
    dst->rowptr[0] = 0;
    for (int i = 0; i < src->n; i++) {
        for (int k = src->rowptr[i]; k < src->rowptr[i + 1]; k++)
            if (src->col[k] == i || -src->val[k] >= wmin) {
                dst->col[nz] = src->col[k];
                dst->val[nz++] = src->val[k];
            }
        dst->rowptr[i + 1] = nz;
    }
    dst->csr = (struct fluid_csr){dst->n, dst->rowptr, dst->col, dst->val};
}

static void mat_free(struct mat *m)
{
    free(m->rowptr);
    free(m->col);
    free(m->val);
    free(m->y);
}

static void spmv(const struct fluid_csr *A, const double *x, double *y)
{
    for (int i = 0; i < A->n; i++) {
        double s = 0.0;
        for (int k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            s += A->val[k] * x[A->col[k]];
        y[i] = s;
    }
}

/* ||b - Ax|| / ||b||, computed here, not by the solver */
static double relres(const struct fluid_csr *A, const double *b, const double *x)
{
    double *ax = malloc((size_t)A->n * sizeof *ax), rr = 0.0, bb = 0.0;
    spmv(A, x, ax);
    for (int i = 0; i < A->n; i++) {
        rr += (b[i] - ax[i]) * (b[i] - ax[i]);
        bb += b[i] * b[i];
    }
    free(ax);
    return sqrt(rr / bb);
}

static double reldiff(int n, const double *x, const double *y)
{
    double d = 0.0, s = 0.0;
    for (int i = 0; i < n; i++) {
        d += (x[i] - y[i]) * (x[i] - y[i]);
        s += y[i] * y[i];
    }
    return sqrt(d / s);
}

/* b = A p with p hydrostatic (depth below the surface) plus noise */
static double *make_rhs(const struct mat *m, int ny)
{
    double *p = malloc((size_t)m->n * sizeof *p), *b = malloc((size_t)m->n * sizeof *b);
    for (int i = 0; i < m->n; i++)
        p[i] = (ny - 1 - m->y[i]) + 0.01 * urand();
    spmv(&m->csr, p, b);
    free(p);
    return b;
}

static double *solve_new(const char *method, const struct mat *m, const double *b, double rtol,
                         struct fluid_linsolve_stats *st)
{
    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    double *x = calloc((size_t)m->n, sizeof *x);
    CHECK(fluid_linsolve_create(&s, method, rtol, 10000, 0, &err) == MPS_OK);
    enum mps_status rc = fluid_linsolve_solve(s, &m->csr, b, x, st, &err);
    if (rc)
        fprintf(stderr, "%s: %s\n", method, err.msg);
    CHECK(rc == MPS_OK);
    fluid_linsolve_destroy(&s);
    CHECK(s == NULL);
    return x;
}

static void test_all_methods_solve_and_agree(void)
{
    const int nx = 60, ny = 60;
    const double rtol = 1e-10;
    struct mat m;
    build(&m, nx, ny, 0.1, 0.0, 1e-6);
    double *b = make_rhs(&m, ny);
    printf("PPE test matrix: n = %d, nnz/row = %.1f\n", m.n, (double)m.rowptr[m.n] / m.n);
    double *xs[NMETHODS];
    for (int k = 0; k < NMETHODS; k++) {
        struct fluid_linsolve_stats st;
        xs[k] = solve_new(methods[k], &m, b, rtol, &st);
        double res = relres(&m.csr, b, xs[k]);
        printf("  %-14s iterations %4d  residual %.2e (own check %.2e)\n", methods[k],
               st.iterations, st.residual, res);
        CHECK(res <= rtol);
        CHECK_NEAR(st.residual, res, 1e-3 * rtol);
        if (!strncmp(methods[k], "pcg", 3))
            CHECK(st.iterations > 0);
        else if (strcmp(methods[k], "auto"))
            CHECK(st.iterations == 0);
    }
    /* ||x - x*|| / ||x*|| <= cond(A) rtol; cond(A) is ~1e3 here, so 1e-6 is generous
     * but still catches a solve of the wrong system. */
    for (int k = 1; k < NMETHODS; k++)
        CHECK(reldiff(m.n, xs[k], xs[2]) < 1e-6);

    /* Warm start from the (direct) solution: at most one iteration. */
    for (int k = 0; k < 2; k++) {
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        struct fluid_linsolve_stats st;
        double *x = malloc((size_t)m.n * sizeof *x);
        memcpy(x, xs[2], (size_t)m.n * sizeof *x);
        CHECK(fluid_linsolve_create(&s, methods[k], rtol, 1000, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(st.iterations <= 1);
        CHECK(relres(&m.csr, b, x) <= rtol);
        /* Same solver object, cold start, on the same matrix: state reuse is harmless. */
        memset(x, 0, (size_t)m.n * sizeof *x);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(st.iterations > 1);
        CHECK(relres(&m.csr, b, x) <= rtol);
        fluid_linsolve_destroy(&s);
        free(x);
    }
    for (int k = 0; k < NMETHODS; k++)
        free(xs[k]);
    free(b);
    mat_free(&m);
}

/* P A P^T with a random permutation: a numbering without locality. */
static void scramble(struct mat *m)
{
    int n = m->n, nnz = m->rowptr[n];
    int *perm = malloc((size_t)n * sizeof *perm), *inv = malloc((size_t)n * sizeof *inv);
    for (int i = 0; i < n; i++)
        perm[i] = i;
    for (int i = n - 1; i > 0; i--) {
        int k = (int)(urand() * (i + 1)), t = perm[i];
        perm[i] = perm[k];
        perm[k] = t;
    }
    for (int i = 0; i < n; i++)
        inv[perm[i]] = i;   /* new row perm[i] is old row i */
    int *rp = malloc((size_t)(n + 1) * sizeof *rp), *cl = malloc((size_t)nnz * sizeof *cl);
    double *vl = malloc((size_t)nnz * sizeof *vl), *y = malloc((size_t)n * sizeof *y);
    rp[0] = 0;
    for (int r = 0; r < n; r++) {
        int old = inv[r], lo = rp[r], len = m->rowptr[old + 1] - m->rowptr[old];
        for (int k = 0; k < len; k++) {   /* insertion sort by new column */
            int c = perm[m->col[m->rowptr[old] + k]], q = lo + k;
            double v = m->val[m->rowptr[old] + k];
            while (q > lo && cl[q - 1] > c) {
                cl[q] = cl[q - 1];
                vl[q] = vl[q - 1];
                q--;
            }
            cl[q] = c;
            vl[q] = v;
        }
        rp[r + 1] = lo + len;
        y[r] = m->y[old];
    }
    mat_free(m);
    *m = (struct mat){n, rp, cl, vl, y, {n, rp, cl, vl}};
    free(perm);
    free(inv);
}

/* 1 and 2 threads give the same answer; > 4096 rows, so the kernels run in
 * parallel and pcg_ic0 and pcg_sic0 factorise 2 blocks (natural numbering) or
 * fall back to one (scrambled numbering, the split would drop half the
 * couplings). */
static void test_thread_counts_agree(void)
{
    for (int scr = 0; scr < 2; scr++) {
        struct mat m;
        build(&m, 80, 81, 0.1, 0.0, 1e-4);
        if (scr)
            scramble(&m);
        double *b = make_rhs(&m, 81);
        const int pcgs[] = {0, 1, 5};   /* pcg_jacobi, pcg_ic0, pcg_sic0 */
        for (int kk = 0; kk < 3; kk++) {
            int k = pcgs[kk];
            double *x[2];
            int its[2];
            for (int t = 0; t < 2; t++) {
                struct fluid_linsolve *s = NULL;
                struct mps_err err = {0};
                struct fluid_linsolve_stats st;
                x[t] = calloc((size_t)m.n, sizeof *x[t]);
                CHECK(fluid_linsolve_create(&s, methods[k], 1e-9, 5000, t + 1, &err) == MPS_OK);
                CHECK(fluid_linsolve_solve(s, &m.csr, b, x[t], &st, &err) == MPS_OK);
                CHECK(relres(&m.csr, b, x[t]) <= 1e-9);
                its[t] = st.iterations;
                fluid_linsolve_destroy(&s);
            }
            printf("  %s, %s numbering: %d iterations with 1 thread, %d with 2\n", methods[k],
                   scr ? "scrambled" : "lattice", its[0], its[1]);
            CHECK(reldiff(m.n, x[1], x[0]) < 1e-6);
            if (k == 0 || scr)   /* same preconditioner: same iterations up to rounding */
                CHECK(abs(its[1] - its[0]) <= 2);
            free(x[0]);
            free(x[1]);
        }
        free(b);
        mat_free(&m);
    }
}

/* cholmod_reuse: the old ordering on a pattern subset (kept) and on moved
 * particles (probably rejected as too much fill), the whole analysis kept for
 * the same pattern, a fresh one when n changes; always the right answer. */
static void test_cholmod_reuse_across_matrices(void)
{
    const double rtol = 1e-10;
    struct mat m1, m1b, m2, m3;
    build(&m1, 50, 40, 0.1, 0.0, 1e-6);
    drop_weak(&m1b, &m1, 0.02);
    CHECK(m1b.rowptr[m1b.n] < m1.rowptr[m1.n]);
    build(&m2, 50, 40, 0.1, 0.4, 1e-6);   /* particles moved: same n, other pattern */
    build(&m3, 45, 40, 0.1, 0.0, 1e-6);   /* fewer particles */
    CHECK(m1.n == m2.n);
    CHECK(m1.rowptr[m1.n] != m2.rowptr[m2.n] ||
          memcmp(m1.col, m2.col, (size_t)m1.rowptr[m1.n] * sizeof(int)));
    double *b1 = make_rhs(&m1, 40), *b2 = make_rhs(&m2, 40), *b3 = make_rhs(&m3, 40);
    double *b1b = make_rhs(&m1b, 40);

    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    struct fluid_linsolve_stats st;
    CHECK(fluid_linsolve_create(&s, "cholmod_reuse", rtol, 1, 0, &err) == MPS_OK);
    double *x = calloc((size_t)m1.n, sizeof *x);
    const struct mat *seq[] = {&m1, &m1b, &m2, &m2, &m3, &m1};
    const double *bs[] = {b1, b1b, b2, b2, b3, b1};
    const int same = 3;   /* seq[same] repeats the previous pattern, with new values */
    for (int k = 0; k < 6; k++) {
        const struct mat *m = seq[k];
        double *xref = solve_new("cholmod", m, bs[k], rtol, &st);
        if (k == same)
            for (int i = 0; i < m->rowptr[m->n]; i++)
                m->val[i] *= 2.0;
        CHECK(fluid_linsolve_solve(s, &m->csr, bs[k], x, &st, &err) == MPS_OK);
        CHECK(relres(&m->csr, bs[k], x) <= rtol);
        for (int i = 0; k == same && i < m->n; i++)
            x[i] *= 2.0;   /* (2A) x = b  =>  x = x_ref / 2 */
        CHECK(reldiff(m->n, x, xref) < 1e-8);
        if (k == same)
            CHECK(st.t_analyse == 0.0);
        else
            CHECK(st.t_analyse > 0.0);
        if (k == same)
            for (int i = 0; i < m->rowptr[m->n]; i++)
                m->val[i] *= 0.5;
        free(xref);
    }
    fluid_linsolve_destroy(&s);
    free(x);
    free(b1);
    free(b2);
    free(b3);
    free(b1b);
    mat_free(&m1);
    mat_free(&m1b);
    mat_free(&m2);
    mat_free(&m3);
}

/* Solves with a new solver, drop threshold theta (< 0: the method's default). */
static double *solve_drop(const char *method, double theta, const struct mat *m, const double *b,
                          double rtol, int nthreads, struct fluid_linsolve_stats *st)
{
    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    double *x = calloc((size_t)m->n, sizeof *x);
    CHECK(fluid_linsolve_create(&s, method, rtol, 10000, nthreads, &err) == MPS_OK);
    if (theta >= 0.0)
        CHECK(fluid_linsolve_set_drop(s, theta, &err) == MPS_OK);
    enum mps_status rc = fluid_linsolve_solve(s, &m->csr, b, x, st, &err);
    if (rc)
        fprintf(stderr, "%s, theta %g: %s\n", method, theta, err.msg);
    CHECK(rc == MPS_OK);
    fluid_linsolve_destroy(&s);
    return x;
}

/* pcg_sic0: converges to rtol on the true residual for a range of drop
 * thresholds; theta = 0 drops nothing and is pcg_ic0 exactly (same
 * iterations, same bits), with one block and with two; a threshold that
 * drops couplings changes the iterations; the setter checks its range. */
static void test_sparsified_ic0(void)
{
    const double rtol = 1e-8;
    for (int big = 0; big < 2; big++) {
        /* big: > 4096 rows, so 2 threads factorise 2 blocks */
        int nx = big ? 80 : 50, ny = big ? 81 : 50;
        struct mat m;
        build(&m, nx, ny, 0.1, 0.0, 1e-4);
        double *b = make_rhs(&m, ny);
        for (int t = 1; t <= 1 + big; t++) {
            struct fluid_linsolve_stats st0, st;
            double *x0 = solve_drop("pcg_ic0", -1.0, &m, b, rtol, t, &st0);
            double *xz = solve_drop("pcg_sic0", 0.0, &m, b, rtol, t, &st);
            printf("  n = %d, %d thread(s): pcg_ic0 %d iterations, pcg_sic0 theta 0 %d\n", m.n,
                   t, st0.iterations, st.iterations);
            CHECK(st.iterations == st0.iterations);
            CHECK(!memcmp(xz, x0, (size_t)m.n * sizeof *x0));
            free(xz);
            const double thetas[] = {-1.0, 0.005, 0.01, 0.02, 0.03, 0.05};
            for (int k = 0; k < 6; k++) {
                double *x = solve_drop("pcg_sic0", thetas[k], &m, b, rtol, t, &st);
                double res = relres(&m.csr, b, x);
                char lab[16] = "default";
                if (thetas[k] >= 0.0)
                    snprintf(lab, sizeof lab, "%g", thetas[k]);
                printf("    theta %-7s %4d iterations, residual %.2e\n", lab, st.iterations,
                       res);
                CHECK(res <= rtol);
                CHECK_NEAR(st.residual, res, 1e-3 * rtol);
                CHECK(reldiff(m.n, x, x0) < 1e-5);
                if (thetas[k] >= 0.01)   /* couplings dropped: another preconditioner */
                    CHECK(st.iterations != st0.iterations);
                free(x);
            }
            free(x0);
        }
        free(b);
        mat_free(&m);
    }

    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    CHECK(fluid_linsolve_create(&s, "pcg_sic0", 1e-8, 100, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_drop(s, -0.1, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "theta") != NULL);
    CHECK(fluid_linsolve_set_drop(s, 1.0, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_set_drop(s, NAN, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_set_drop(NULL, 0.1, &err) == MPS_EINPUT);
    fluid_linsolve_destroy(&s);
    /* other methods take it and ignore it */
    CHECK(fluid_linsolve_create(&s, "pcg_ic0", 1e-8, 100, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_drop(s, 0.05, &err) == MPS_OK);
    fluid_linsolve_destroy(&s);

    /* Kershaw's matrix: SPD, but IC(0) meets a negative pivot (-5 in the
     * last row), and theta = 0.5 drops every coupling, which leaves row 2 a
     * diagonal of 3 - 2 - 2 < 0: both need the shifted-IC fallback. */
    int rp[] = {0, 3, 6, 9, 12}, cl[] = {0, 1, 3, 0, 1, 2, 1, 2, 3, 0, 2, 3};
    double vl[] = {3, -2, 2, -2, 3, -2, -2, 3, -2, 2, -2, 3}, bk[] = {1, 2, 3, 4};
    struct fluid_csr ker = {4, rp, cl, vl};
    const double kth[] = {0.0, 0.5};
    for (int k = 0; k < 2; k++) {
        double xk[4] = {0};
        struct fluid_linsolve_stats st;
        CHECK(fluid_linsolve_create(&s, "pcg_sic0", 1e-10, 100, 1, &err) == MPS_OK);
        CHECK(fluid_linsolve_set_drop(s, kth[k], &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &ker, bk, xk, &st, &err) == MPS_OK);
        CHECK(relres(&ker, bk, xk) <= 1e-10);
        fluid_linsolve_destroy(&s);
    }
}

/* Aggregates of the lattice's unknowns (row-major, nx per row): squares of
 * h x h particles. */
static int *square_aggregates(int n, int nx, int h, int *nagg)
{
    int *agg = malloc((size_t)n * sizeof *agg), per_row = (nx + h - 1) / h;
    for (int a = 0; a < n; a++)
        agg[a] = (a / nx / h) * per_row + (a % nx) / h;
    *nagg = agg[n - 1] + 1;
    return agg;
}

/* The same 4 x 4 aggregates of a wide lattice (200 x 21), numbered along its
 * long side (coarse bandwidth 51: E is ordered by AMD) and along its short
 * side (bandwidth 6: E is factorised in its own order, fluid_defl.c): the
 * same coarse space, so the same solution and, up to rounding, the same
 * iterations. */
static void test_deflation_coarse_orders(void)
{
    const int nx = 200, ny = 21, h = 4, per_row = (nx + h - 1) / h;
    struct mat m;
    build(&m, nx, ny, 0.1, 0.0, 1e-4);
    double *b = make_rhs(&m, ny);
    const int rows = m.n / nx, per_col = (rows + h - 1) / h; /* the unknowns' rows */
    CHECK(m.n == rows * nx);
    int its[2] = {0}, nagg = 0;
    double *x[2];
    int *agg = malloc((size_t)m.n * sizeof *agg);
    for (int order = 0; order < 2; order++) {
        for (int a = 0; a < m.n; a++) {
            int cx = (a % nx) / h, cy = (a / nx) / h;
            agg[a] = order == 0 ? cy * per_row + cx : cx * per_col + cy;
        }
        nagg = per_row * per_col;
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        struct fluid_linsolve_stats st;
        x[order] = calloc((size_t)m.n, sizeof *x[order]);
        CHECK(fluid_linsolve_create(&s, "pcg_defl", 1e-8, 1000, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x[order], &st, &err) == MPS_OK);
        CHECK(relres(&m.csr, b, x[order]) <= 1e-8);
        its[order] = st.iterations;
        fluid_linsolve_destroy(&s);
    }
    printf("  %d aggregates on a %d x %d lattice: %d iterations numbered along x, %d along y\n",
           nagg, nx, ny, its[0], its[1]);
    CHECK(abs(its[0] - its[1]) <= 1);
    CHECK(reldiff(m.n, x[0], x[1]) < 1e-6);
    free(x[0]);
    free(x[1]);
    free(agg);
    free(b);
    mat_free(&m);
}

/* pcg_defl: with geometric aggregates the iterations stay flat as the
 * lattice grows (the coarse space takes the smooth modes), while Jacobi
 * PCG's grow like the lattice's width; the solution is right; bad
 * aggregates are named. */
static void test_deflation(void)
{
    const double rtol = 1e-8;
    int its[2][2] = {{0}};   /* [size][jacobi, defl] */
    for (int big = 0; big < 2; big++) {
        int nx = big ? 150 : 50, ny = nx + 1;
        struct mat m;
        build(&m, nx, ny, 0.1, 0.0, 1e-4);
        double *b = make_rhs(&m, ny);
        struct fluid_linsolve_stats st;
        double *xj = solve_new("pcg_jacobi", &m, b, rtol, &st);
        its[big][0] = st.iterations;
        int nagg;
        int *agg = square_aggregates(m.n, nx, 4, &nagg);
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        double *x = calloc((size_t)m.n, sizeof *x);
        CHECK(fluid_linsolve_create(&s, "pcg_defl", rtol, 1000, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_uses_aggregates(s));
        CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        its[big][1] = st.iterations;
        CHECK(fluid_linsolve_coarse_size(s) == nagg);
        double res = relres(&m.csr, b, x);
        printf("  n = %d: pcg_jacobi %d iterations, pcg_defl (%d aggregates of 4 x 4) %d, "
               "residual %.2e\n", m.n, its[big][0], nagg, its[big][1], res);
        CHECK(res <= rtol);
        CHECK(reldiff(m.n, x, xj) < 1e-5);
        /* warm start from the solution: nothing to do */
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(st.iterations <= 1);
        fluid_linsolve_destroy(&s);
        free(x);
        free(xj);
        free(agg);
        free(b);
        mat_free(&m);
    }
    /* 9x the unknowns: Jacobi needs about 3x the iterations (they go as the
     * width); with the coarse space they may grow by a third at most. */
    CHECK(its[1][0] > 2 * its[0][0]);
    CHECK(3 * its[1][1] <= 4 * its[0][1]);
    CHECK(3 * its[1][1] < its[1][0]);

    struct mat m;
    build(&m, 20, 21, 0.1, 0.0, 1e-4);
    double *b = make_rhs(&m, 21), *x = calloc((size_t)m.n, sizeof *x);
    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    int nagg, *agg = square_aggregates(m.n, 20, 4, &nagg);
    CHECK(fluid_linsolve_create(&s, "pcg_defl", 1e-8, 1000, 0, &err) == MPS_OK);
    agg[7] = nagg;
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "row 7") != NULL);
    agg[7] = -1;
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, 0, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_set_aggregates(s, NULL, m.n, nagg, &err) == MPS_EINPUT);
    /* an aggregate with no row makes the coarse matrix singular: named */
    agg[7] = agg[6];
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg + 1, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(s, &m.csr, b, x, NULL, &err) == MPS_ESOLVE);
    CHECK(strstr(err.msg, "no row") != NULL);
    /* aggregates for another row count: the fallback blocks are used */
    memset(x, 0, (size_t)m.n * sizeof *x);
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n - 1, nagg, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(s, &m.csr, b, x, NULL, &err) == MPS_OK);
    CHECK(relres(&m.csr, b, x) <= 1e-8);
    fluid_linsolve_destroy(&s);
    /* other methods do not use them */
    CHECK(fluid_linsolve_create(&s, "pcg_sic0", 1e-8, 1000, 0, &err) == MPS_OK);
    CHECK(!fluid_linsolve_uses_aggregates(s));
    fluid_linsolve_destroy(&s);
    free(agg);
    free(x);
    free(b);
    mat_free(&m);
}

/* Every row its own aggregate: the deflated start solves the system
 * outright and CG has no direction left (p = 0). That must count as
 * converged, not as a breakdown (it stopped the coarse coupled plate at
 * 0.84 s when a few drops of water made the whole PPE). */
static void test_deflation_exact_start(void)
{
    struct mat m;
    build(&m, 6, 7, 0.1, 0.0, 1e-4);
    double *b = make_rhs(&m, 7), *x = calloc((size_t)m.n, sizeof *x);
    int *agg = malloc((size_t)m.n * sizeof *agg);
    for (int i = 0; i < m.n; i++)
        agg[i] = i;
    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    struct fluid_linsolve_stats st;
    CHECK(fluid_linsolve_create(&s, "pcg_defl", 1e-8, 100, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, m.n, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
    if (err.msg[0])
        printf("  %s\n", err.msg);
    CHECK(st.iterations == 0);
    CHECK(relres(&m.csr, b, x) <= 1e-8);
    fluid_linsolve_destroy(&s);
    free(agg);
    free(x);
    free(b);
    mat_free(&m);
}

/* fluid_linsolve_same_pattern: the PPE solved again with some rows held at
 * 0 (their couplings zeroed, the pattern kept, as fluid.tension_solves
 * does). pcg_defl refills its coarse space's lists from the new values; the
 * solve must be, to the bit, what a solver set up from nothing gives for
 * the same matrix and start (a refill that kept the old values, or put a
 * value in the wrong list, gives other iterates). A matrix with another
 * pattern after the call gets a full set-up. */
static void test_deflation_same_pattern(void)
{
    const int nx = 40, ny = 41;
    struct mat m;
    build(&m, nx, ny, 0.1, 0.0, 1e-4);
    double *b = make_rhs(&m, ny), *x1 = calloc((size_t)m.n, sizeof *x1);
    double *x2 = malloc((size_t)m.n * sizeof *x2), *b2 = malloc((size_t)m.n * sizeof *b2);
    int nagg, *agg = square_aggregates(m.n, nx, 4, &nagg);
    struct fluid_linsolve *s = NULL, *fresh = NULL;
    struct mps_err err = {0};
    struct fluid_linsolve_stats st1, st2;
    CHECK(fluid_linsolve_create(&s, "pcg_defl", 1e-8, 1000, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_aggregates(s, agg, m.n, nagg, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(s, &m.csr, b, x1, &st1, &err) == MPS_OK);
    /* hold every 7th row in the lower half at 0 */
    unsigned char *held = calloc((size_t)m.n, 1);
    int nheld = 0;
    for (int i = 0; i < m.n / 2; i += 7)
        held[i] = 1, nheld++;
    for (int i = 0; i < m.n; i++) {
        b2[i] = held[i] ? 0.0 : b[i];
        for (int k = m.rowptr[i]; k < m.rowptr[i + 1]; k++)
            if (m.col[k] != i && (held[i] || held[m.col[k]]))
                m.val[k] = 0.0;
        if (held[i])
            x1[i] = 0.0;
    }
    memcpy(x2, x1, (size_t)m.n * sizeof *x2);
    fluid_linsolve_same_pattern(s);
    CHECK(fluid_linsolve_solve(s, &m.csr, b2, x1, &st1, &err) == MPS_OK);
    CHECK(fluid_linsolve_create(&fresh, "pcg_defl", 1e-8, 1000, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_aggregates(fresh, agg, m.n, nagg, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(fresh, &m.csr, b2, x2, &st2, &err) == MPS_OK);
    printf("  %d rows held: %d iterations after the refill, %d after a full set-up\n", nheld,
           st1.iterations, st2.iterations);
    CHECK(st1.iterations > 0);
    CHECK(st1.iterations == st2.iterations);
    CHECK(memcmp(x1, x2, (size_t)m.n * sizeof *x1) == 0);
    CHECK(relres(&m.csr, b2, x1) <= 1e-8);
    /* the promise is for one solve; a matrix with another pattern after it */
    struct mat m2;
    build(&m2, nx, ny, 0.1, 0.7, 1e-4);
    CHECK(m2.n == m.n && m2.rowptr[m2.n] != m.rowptr[m.n]);
    double *b3 = make_rhs(&m2, ny);
    fluid_linsolve_same_pattern(s);
    CHECK(fluid_linsolve_solve(s, &m2.csr, b3, x1, &st1, &err) == MPS_OK);
    CHECK(relres(&m2.csr, b3, x1) <= 1e-8);
    fluid_linsolve_destroy(&s);
    fluid_linsolve_destroy(&fresh);
    free(held);
    free(agg);
    free(x1);
    free(x2);
    free(b);
    free(b2);
    free(b3);
    mat_free(&m);
    mat_free(&m2);
}

/* The assembled matrix val0 / rhs b0 with the rows flagged in held
 * decoupled (couplings and rhs 0, diagonal kept: fluid.tension_solves), the
 * diagonal of the rows flagged in scale_diag times 1.25, all times `factor`. */
static void hold_rows(struct mat *m, const double *val0, const double *b0,
                      const unsigned char *held, const unsigned char *scale_diag, double factor,
                      double *b)
{
    for (int i = 0; i < m->n; i++) {
        b[i] = factor * (held[i] ? 0.0 : b0[i]);
        for (int k = m->rowptr[i]; k < m->rowptr[i + 1]; k++) {
            const int j = m->col[k];
            double v = (j != i && (held[i] || held[j])) ? 0.0 : val0[k];
            if (j == i && scale_diag && scale_diag[i])
                v *= 1.25;
            m->val[k] = factor * v;
        }
    }
}

/* The rows whose values differ between held sets now and was (NULL: none
 * held): the rows that changed and their neighbours; into list. */
static int touched_rows(const struct mat *m, const unsigned char *now, const unsigned char *was,
                        unsigned char *mark, int *list)
{
    memset(mark, 0, (size_t)m->n);
    for (int i = 0; i < m->n; i++)
        if (now[i] != (was ? was[i] : 0))
            for (int k = m->rowptr[i]; k < m->rowptr[i + 1]; k++)
                mark[i] = mark[m->col[k]] = 1;
    int n = 0;
    for (int i = 0; i < m->n; i++)
        if (mark[i])
            list[n++] = i;
    return n;
}

/* x's held rows set to 0, then (A, b) solved from there by s, told of the
 * nl changed rows in list, and by a solver set up from nothing: the two
 * must be the same to the bit. */
static void resolve_as_fresh(const char *method, struct fluid_linsolve *s, const struct mat *m,
                             const int *agg, int nagg, const double *b,
                             const unsigned char *held, const int *list, int nl, double *x,
                             const char *what)
{
    struct fluid_linsolve *fresh = NULL;
    struct mps_err err = {0};
    struct fluid_linsolve_stats sts, stf;
    double *xf = malloc((size_t)m->n * sizeof *xf);
    for (int i = 0; i < m->n; i++)
        x[i] = held[i] ? 0.0 : x[i];
    memcpy(xf, x, (size_t)m->n * sizeof *xf);
    fluid_linsolve_changed_rows(s, list, nl);
    CHECK(fluid_linsolve_solve(s, &m->csr, b, x, &sts, &err) == MPS_OK);
    CHECK(fluid_linsolve_create(&fresh, method, 1e-8, 1000, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_set_aggregates(fresh, agg, m->n, nagg, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(fresh, &m->csr, b, xf, &stf, &err) == MPS_OK);
    printf("  %s, %s: %d iterations after the partial refill, %d from nothing\n", method, what,
           sts.iterations, stf.iterations);
    CHECK(sts.iterations > 0);
    CHECK(sts.iterations == stf.iterations);
    CHECK(memcmp(x, xf, (size_t)m->n * sizeof *xf) == 0);
    CHECK(relres(&m->csr, b, x) <= 1e-8);
    fluid_linsolve_destroy(&fresh);
    free(xf);
}

/* fluid_linsolve_changed_rows: rows held and let go as the no-tension PPE
 * does, the solver told which rows changed. Each solve must be, to the bit,
 * what a solver set up from nothing gives: a refill that misses a coarse
 * column the rows touch, keeps a stale Jacobi diagonal, or builds on a
 * set-up older than the last solve (one that skipped it, its start being
 * converged) gives other iterates. */
static void test_changed_rows(void)
{
    const int nx = 40, ny = 41;
    const char *kinds[] = {"pcg_defl", "pcg_jacobi"};
    for (int mi = 0; mi < 2; mi++) {
        struct mat m;
        build(&m, nx, ny, 0.1, 0.0, 1e-4);
        const int n = m.n;
        const size_t nnz = (size_t)m.rowptr[n];
        double *b0 = make_rhs(&m, ny), *b = malloc((size_t)n * sizeof *b);
        double *val0 = malloc(nnz * sizeof *val0), *x = calloc((size_t)n, sizeof *x);
        memcpy(val0, m.val, nnz * sizeof *val0);
        unsigned char *h1 = calloc((size_t)n, 1), *h2 = calloc((size_t)n, 1);
        unsigned char *h3 = calloc((size_t)n, 1), *mark = malloc((size_t)n);
        unsigned char *diag1 = malloc((size_t)n);
        int *list = malloc((size_t)n * sizeof *list), nagg;
        int *agg = square_aggregates(n, nx, 4, &nagg);
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        struct fluid_linsolve_stats st;
        CHECK(fluid_linsolve_create(&s, kinds[mi], 1e-8, 1000, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_set_aggregates(s, agg, n, nagg, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &m.csr, b0, x, &st, &err) == MPS_OK);
        /* 1: hold every 7th row of the lower half; the listed rows' diagonal
         * changes too (the promise is only that the other rows stay) */
        for (int i = 0; i < n / 2; i += 7)
            h1[i] = 1;
        int nl = touched_rows(&m, h1, NULL, diag1, list);
        hold_rows(&m, val0, b0, h1, diag1, 1.0, b);
        resolve_as_fresh(kinds[mi], s, &m, agg, nagg, b, h1, list, nl, x, "rows held");
        /* 2: let every other held row go, hold some of the upper half */
        memcpy(h2, h1, (size_t)n);
        for (int i = 0, k = 0; i < n / 2; i += 7, k++)
            h2[i] = k % 2;
        for (int i = n / 2; i < n; i += 11)
            h2[i] = 1;
        nl = touched_rows(&m, h2, h1, mark, list);
        hold_rows(&m, val0, b0, h2, diag1, 1.0, b);
        resolve_as_fresh(kinds[mi], s, &m, agg, nagg, b, h2, list, nl, x,
                         "rows let go and held");
        /* 3: the same system times 2 from its solution: converged at the
         * start, so no set-up; the next changed rows are relative to it */
        hold_rows(&m, val0, b0, h2, diag1, 2.0, b);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(st.iterations == 0);
        memcpy(h3, h2, (size_t)n);
        for (int i = 3; i < n; i += 13)
            h3[i] = 1;
        nl = touched_rows(&m, h3, h2, mark, list);
        hold_rows(&m, val0, b0, h3, diag1, 2.0, b);
        resolve_as_fresh(kinds[mi], s, &m, agg, nagg, b, h3, list, nl, x,
                         "after a solve that skipped its set-up");
        fluid_linsolve_destroy(&s);
        free(b0);
        free(b);
        free(val0);
        free(x);
        free(h1);
        free(h2);
        free(h3);
        free(mark);
        free(diag1);
        free(list);
        free(agg);
        mat_free(&m);
    }
}

static void test_zero_rhs(void)
{
    struct mat m;
    build(&m, 20, 20, 0.1, 0.0, 1e-6);
    double *b = calloc((size_t)m.n, sizeof *b), *x = malloc((size_t)m.n * sizeof *x);
    for (int k = 0; k < NMETHODS; k++) {
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        struct fluid_linsolve_stats st;
        for (int i = 0; i < m.n; i++)
            x[i] = 1.0 + i;
        CHECK(fluid_linsolve_create(&s, methods[k], 1e-8, 100, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(st.iterations == 0);
        double amax = 0.0;
        for (int i = 0; i < m.n; i++)
            amax = fmax(amax, fabs(x[i]));
        CHECK(amax == 0.0);
        fluid_linsolve_destroy(&s);
    }
    free(b);
    free(x);
    mat_free(&m);
}

static void test_errors(void)
{
    struct fluid_linsolve *s = NULL;
    struct mps_err err = {0};
    struct fluid_linsolve_stats st;

    CHECK(fluid_linsolve_create(&s, "pcg_ilu", 1e-8, 100, 0, &err) == MPS_EINPUT);
    CHECK(s == NULL);
    CHECK(strstr(err.msg, "pcg_ilu") && strstr(err.msg, fluid_linsolve_methods()));
    CHECK(fluid_linsolve_create(&s, "pcg_jacobi", 0.0, 100, 0, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_create(&s, "pcg_jacobi", 1e-8, 0, 0, &err) == MPS_EINPUT);
    CHECK(fluid_linsolve_create(&s, "pcg_jacobi", 1e-8, 10, -1, &err) == MPS_EINPUT);
    fluid_linsolve_destroy(&s);   /* NULL is fine */
    fluid_linsolve_destroy(NULL);

    CHECK(fluid_linsolve_create(&s, "auto", 1e-8, 100, 0, &err) == MPS_OK);
    CHECK(strcmp(fluid_linsolve_method(s), "auto") != 0);
    CHECK(strstr(fluid_linsolve_methods(), fluid_linsolve_method(s)) != NULL);
    fluid_linsolve_destroy(&s);

    struct mat m;
    build(&m, 30, 30, 0.1, 0.0, 1e-6);
    double *b = make_rhs(&m, 30), *x = calloc((size_t)m.n, sizeof *x);

    /* Hitting max_iter names the iterations and the residual reached. */
    CHECK(fluid_linsolve_create(&s, "pcg_jacobi", 1e-10, 3, 0, &err) == MPS_OK);
    CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_ESOLVE);
    CHECK(strstr(err.msg, "did not converge in 3 iterations") != NULL);
    CHECK(st.iterations == 3 && st.residual > 1e-10);
    fluid_linsolve_destroy(&s);

    /* each method, then (2 * NMETHODS) each again trusting the structure:
     * the values must still be caught and the row named */
    for (int kk = 0; kk < 2 * NMETHODS; kk++) {
        int k = kk % NMETHODS;
        CHECK(fluid_linsolve_create(&s, methods[k], 1e-8, 1000, 0, &err) == MPS_OK);
        fluid_linsolve_trust_structure(s, kk >= NMETHODS);
        char row[32];
        /* NaN in A (an off-diagonal entry of row 17) */
        int pos = m.rowptr[17];
        double keep = m.val[pos];
        m.val[pos] = NAN;
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_ESOLVE);
        CHECK(strstr(err.msg, "row 17") != NULL);
        m.val[pos] = keep;
        /* Inf in b */
        keep = b[123];
        b[123] = INFINITY;
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_ESOLVE);
        snprintf(row, sizeof row, "row %d", 123);
        CHECK(strstr(err.msg, row) != NULL);
        b[123] = keep;
        /* Still works after the errors */
        memset(x, 0, (size_t)m.n * sizeof *x);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(relres(&m.csr, b, x) <= 1e-8);
        fluid_linsolve_destroy(&s);
    }

    /* Row 1 without its diagonal: malformed input, named. */
    int rpm[] = {0, 2, 4, 6}, clm[] = {0, 1, 0, 2, 1, 2};
    double vlm[] = {2.0, -1.0, -1.0, -1.0, -1.0, 2.0}, bm[] = {1.0, 1.0, 1.0}, xm[3] = {0};
    struct fluid_csr nodiag = {3, rpm, clm, vlm};
    for (int k = 0; k < NMETHODS; k++) {
        CHECK(fluid_linsolve_create(&s, methods[k], 1e-8, 100, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &nodiag, bm, xm, &st, &err) == MPS_EINPUT);
        CHECK(strstr(err.msg, "row 1") && strstr(err.msg, "diagonal"));
        fluid_linsolve_destroy(&s);
    }

    /* Singular matrix [1 1; 1 1]: every method reports it as a solver failure.
     * (CHOLMOD's simplicial LDL' would solve an indefinite but nonsingular
     * matrix without complaint; the PPE is SPD, so that is not checked.) */
    int rp[] = {0, 2, 4}, cl[] = {0, 1, 0, 1};
    double vl[] = {1.0, 1.0, 1.0, 1.0}, b2[] = {1.0, 0.0}, x2[2] = {0.0, 0.0};
    struct fluid_csr sing = {2, rp, cl, vl};
    for (int k = 0; k < NMETHODS; k++) {
        CHECK(fluid_linsolve_create(&s, methods[k], 1e-8, 100, 0, &err) == MPS_OK);
        CHECK(fluid_linsolve_solve(s, &sing, b2, x2, &st, &err) == MPS_ESOLVE);
        CHECK(strstr(err.msg, "not positive definite") != NULL);
        /* and recovers on a good matrix */
        memset(x, 0, (size_t)m.n * sizeof *x);
        CHECK(fluid_linsolve_solve(s, &m.csr, b, x, &st, &err) == MPS_OK);
        CHECK(relres(&m.csr, b, x) <= 1e-8);
        fluid_linsolve_destroy(&s);
    }
    free(b);
    free(x);
    mat_free(&m);
}

int main(void)
{
    test_all_methods_solve_and_agree();
    test_thread_counts_agree();
    test_cholmod_reuse_across_matrices();
    test_sparsified_ic0();
    test_deflation();
    test_deflation_coarse_orders();
    test_deflation_exact_start();
    test_deflation_same_pattern();
    test_changed_rows();
    test_zero_rhs();
    test_errors();
    return test_summary("test_linsolve");
}
