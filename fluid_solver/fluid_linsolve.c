/* Sparse SPD solves for the PPE: PCG (Jacobi or block IC(0), OpenMP) and
 * CHOLMOD (int version). See fluid_linsolve.h for the contract and
 * docs/ppe_solvers.md for the measurements behind the choices here. */
#include "fluid_linsolve.h"

#include "fluid_defl.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "mps_mem.h"
#include "mps_omp.h"

struct fluid_linsolve;

/* A method is a row of this table (the methods[] below): the solve (PCG or
 * CHOLMOD), its preconditioner for PCG, what it starts at creation, and the
 * options only some methods take. Nothing else in this file asks which
 * method it is. */
struct method_ops {
    const char *name;
    /* at creation, after the common fields (NULL: nothing to start) */
    enum mps_status (*start)(struct fluid_linsolve *s, struct mps_err *err);
    enum mps_status (*solve)(struct fluid_linsolve *s, const struct fluid_csr *A, const double *b,
                             double *x, struct fluid_linsolve_stats *st, struct mps_err *err);
    int iterative;       /* starts from x (warm start), trusts the caller's structure */
    /* PCG: preconditioner set-up (NULL: Jacobi's, part of every PCG) and
     * application z = M^-1 r returning r.z */
    enum mps_status (*precond_setup)(struct fluid_linsolve *s, const struct fluid_csr *A,
                                     struct mps_err *err);
    double (*precond_apply)(struct fluid_linsolve *s, int n, const double *r, double *z);
    int ic0_storage;     /* needs the IC(0) factor's arrays */
    double drop;         /* default drop threshold theta; < 0: set_drop is ignored */
    int reuse_ordering;  /* CHOLMOD: keep the fill-reducing ordering while it serves */
};

/* "auto" = pcg_defl since 2026-11-22: with the fluid's aggregates (cells of
 * 4 spacings) its iterations stay at 11-12 per step from 6k to 80k
 * particles on the dam break, where pcg_sic0's grow 29 -> 51 -> 78, and the
 * PPE solve costs 216 / 671 ns per particle-step at 6k / 80k against 357 /
 * 1807 (2 threads, Courant 0.4, docs/ppe_solvers.md). Without aggregates it deflates
 * blocks of consecutive rows, still a valid (weaker) preconditioner.
 * Before: pcg_sic0, since the real PPE of the 3 mm dam break was measured
 * (docs/ppe_solvers.md): the same iterations' worth of accuracy for 19% less
 * PPE time on one thread, 22% on two (the factor of the pruned matrix costs
 * half). Before that, pcg_ic0, from these synthetic figures. Measured with
 * bench/linsolve_bench on the synthetic PPE (jittered lattice, ~46 nnz/row, rtol 1e-6, min of 3 runs; see
 * docs/ppe_solvers.md), warm-started solve in ms at n = 5k / 20k / 80k:
 *   2 threads, quiet machine: pcg_ic0 4.6 / 22 / 137, pcg_jacobi 4.3 / 24 / 111
 *   1 thread (what 2 threads give, at best, next to another busy process):
 *                             pcg_ic0 6.5 / 37 / 224, pcg_jacobi 8.4 / 55 / 253
 *   cholmod 41 / 213 / 1850, cholmod_reuse 39 / 230 / 1890.
 * Roughly a tie on two free cores (Jacobi 20% ahead at 80k), IC(0) 11-34%
 * ahead when the cores are shared (the usual case for a coupled run here),
 * and 3-4x fewer iterations, which keeps a margin under fluid.ppe_max_iter
 * on harder matrices. */
#define AUTO_METHOD "pcg_defl"

#define METHOD_LIST "pcg_jacobi, pcg_ic0, pcg_sic0, pcg_defl, cholmod, cholmod_reuse, auto"

/* pcg_sic0's default drop threshold theta (fluid_linsolve_set_drop). On the
 * 3 mm dam break (4.5k rows, 1 thread, real warm starts) the PPE cost per
 * step was 6.65 ms with pcg_ic0 and 5.59 / 5.37 / 5.34 / 5.69 ms at theta =
 * 0.01 / 0.015 / 0.02 / 0.025 (iterations 12.5 -> 16.8 / 18.2 / 19.6 /
 * 22.8); on the 80k synthetic matrix 0.015 beat 0.02. It keeps about 9 of
 * the 22 lower-triangle couplings of a row: the neighbours within ~2.2
 * spacings. See docs/ppe_solvers.md. */
#define SIC0_DEFAULT_DROP 0.015

/* Below this many rows a parallel region costs more than it saves. With
 * threads that spin between regions (the coupler sets GOMP_SPINCOUNT) a
 * region costs a few microseconds: at 1,100 rows (plate, 6 mm) two threads
 * already solve 7% faster than one, at 4,300 rows (3 mm) 12% (the blocks of
 * the IC(0) factor add about one iteration in 15). It was 4096, set when
 * the threads slept between regions. */
#define PAR_MIN_ROWS 512
/* Per-thread partial sums, padded to a cache line so threads do not share one. */
#define PAD 8

struct fluid_linsolve {
    const struct method_ops *ops;
    double rtol;
    int max_iter;
    int nthreads;        /* resolved: > 0 */
    int trusted;         /* structure well formed by construction: no check_input */
    int same_pattern;    /* the next solve's A: the last one's pattern (one solve) */
    const int *changed_rows;   /* ... and only these rows' values changed (one solve) */
    int nchanged;
    int setup_current;   /* the last solve set up for its A (diag, dinv, coarse space) */
    int setup_n;         /* ... of this many rows */

    /* PCG work vectors, capacity cap_n */
    size_t cap_n;
    double *r, *z, *p, *q, *dinv;
    int *diag;           /* position of the diagonal in each row of A */
    double *partial;     /* nthreads * PAD reduction slots */

    /* IC(0) factor: lower triangle of A in CSR (diagonal last in each row),
     * restricted to each block, overwritten by L; 1/L_ii in linv. */
    size_t cap_lnz;
    int *lptr, *lcol, *mark;
    double *lval, *linv;
    double *comp;        /* pcg_sic0: sum of the couplings dropped from each row */
    int nblk;            /* blocks of rows factorised independently (one per thread) */
    double drop2;        /* pcg_sic0: theta^2 of the drop rule (0 for pcg_ic0) */

    struct fluid_defl *defl;   /* pcg_defl: the coarse space (fluid_defl.h) */

    /* CHOLMOD */
    int cm_started;
    cholmod_common cm;
    cholmod_factor *L;
    cholmod_dense *X, *Y, *E;   /* cholmod_solve2 workspace, reused */
    /* cholmod_reuse: ordering and pattern of the last analysis */
    int *perm;
    int perm_n;                 /* rows perm is for; -1 = none */
    int *pat_ptr, *pat_col;     /* copy of the pattern the symbolic factor L was built for */
    size_t cap_perm, cap_pat;
    double flops_ref;    /* factorisation flops / nnz(A) of the last fresh ordering */
    int rejected;        /* consecutive times the old ordering was not good enough */
    int skip;            /* calls left before it is tried again */
};

static enum mps_status pcg(struct fluid_linsolve *s, const struct fluid_csr *A, const double *b,
                           double *x, struct fluid_linsolve_stats *st, struct mps_err *err);
static enum mps_status direct(struct fluid_linsolve *s, const struct fluid_csr *A,
                              const double *b, double *x, struct fluid_linsolve_stats *st,
                              struct mps_err *err);
static enum mps_status ic0_setup(struct fluid_linsolve *s, const struct fluid_csr *A,
                                 struct mps_err *err);
static double ic0_apply(struct fluid_linsolve *s, int n, const double *r, double *z);
static double k_jacobi(struct fluid_linsolve *s, int n, const double *r, double *z);
static enum mps_status start_defl(struct fluid_linsolve *s, struct mps_err *err);
static enum mps_status start_cholmod(struct fluid_linsolve *s, struct mps_err *err);

/* The six methods. pcg_ic0 and pcg_sic0 share the IC(0) factor, its storage
 * and its application; they differ only in the matrix factorised (sic0
 * drops weak couplings first). pcg_defl is Jacobi PCG in the deflated space
 * (the deflation works through s->defl, made by its start). */
static const struct method_ops methods[] = {
    {"pcg_jacobi", NULL, pcg, 1, NULL, k_jacobi, 0, -1.0, 0},
    {"pcg_ic0", NULL, pcg, 1, ic0_setup, ic0_apply, 1, -1.0, 0},
    {"pcg_sic0", NULL, pcg, 1, ic0_setup, ic0_apply, 1, SIC0_DEFAULT_DROP, 0},
    {"pcg_defl", start_defl, pcg, 1, NULL, k_jacobi, 0, -1.0, 0},
    {"cholmod", start_cholmod, direct, 0, NULL, NULL, 0, -1.0, 0},
    {"cholmod_reuse", start_cholmod, direct, 0, NULL, NULL, 0, -1.0, 1},
};

static const struct method_ops *find_method(const char *name)
{
    for (size_t i = 0; i < sizeof methods / sizeof *methods; i++)
        if (!strcmp(name, methods[i].name))
            return &methods[i];
    return NULL;
}

/* ---- CHOLMOD error capture: the handler has no user pointer, so the last
 * message goes into a thread-local buffer that the caller copies into err. */
static _Thread_local char cholmod_msg[256];

static void cholmod_error_capture(int status, const char *file, int line, const char *message)
{
    (void)file;
    (void)line;
    snprintf(cholmod_msg, sizeof cholmod_msg, "%s (status %d)", message ? message : "?", status);
}

static const char *cholmod_status_text(int status)
{
    switch (status) {
    case CHOLMOD_OK: return "ok";
    case CHOLMOD_NOT_INSTALLED: return "method not installed";
    case CHOLMOD_OUT_OF_MEMORY: return "out of memory";
    case CHOLMOD_TOO_LARGE: return "integer overflow";
    case CHOLMOD_INVALID: return "invalid input";
    case CHOLMOD_NOT_POSDEF: return "matrix not positive definite";
    case CHOLMOD_DSMALL: return "tiny diagonal in the factor";
    default: return "unknown status";
    }
}

/* A failed CHOLMOD call: MPS_ENOMEM for memory, MPS_ESOLVE when the matrix
 * is not positive definite, MPS_ELIB otherwise. */
static enum mps_status cholmod_fail(struct fluid_linsolve *s, const char *call,
                                    struct mps_err *err)
{
    int st = s->cm.status;
    enum mps_status code = st == CHOLMOD_OUT_OF_MEMORY ? MPS_ENOMEM
                         : st == CHOLMOD_NOT_POSDEF  ? MPS_ESOLVE
                                                     : MPS_ELIB;
    return mps_err_set(err, code, "%s: %s failed: %s%s%s", s->ops->name, call,
                       cholmod_status_text(st), cholmod_msg[0] ? ": " : "", cholmod_msg);
}

/* ---------------------------------------------------------------------- */

const char *fluid_linsolve_methods(void) { return METHOD_LIST; }

const char *fluid_linsolve_method(const struct fluid_linsolve *s)
{
    return s ? s->ops->name : "(none)";
}

static enum mps_status reserve_vectors(struct fluid_linsolve *s, size_t n, struct mps_err *err)
{
    if (n <= s->cap_n)
        return MPS_OK;
    size_t c = n + n / 8;   /* particles come and go: a little slack avoids churn */
    int fail = 0;
    s->r = mps_realloc_or_flag(s->r, c, sizeof *s->r, &fail);
    s->z = mps_realloc_or_flag(s->z, c, sizeof *s->z, &fail);
    s->p = mps_realloc_or_flag(s->p, c, sizeof *s->p, &fail);
    s->q = mps_realloc_or_flag(s->q, c, sizeof *s->q, &fail);
    s->dinv = mps_realloc_or_flag(s->dinv, c, sizeof *s->dinv, &fail);
    s->diag = mps_realloc_or_flag(s->diag, c, sizeof *s->diag, &fail);
    if (s->ops->ic0_storage) {
        s->lptr = mps_realloc_or_flag(s->lptr, c + 1, sizeof *s->lptr, &fail);
        s->mark = mps_realloc_or_flag(s->mark, c, sizeof *s->mark, &fail);
        s->linv = mps_realloc_or_flag(s->linv, c, sizeof *s->linv, &fail);
        s->comp = mps_realloc_or_flag(s->comp, c, sizeof *s->comp, &fail);
    }
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "%s: cannot allocate work vectors for %zu rows",
                           s->ops->name, n);
    s->cap_n = c;
    return MPS_OK;
}

enum mps_status fluid_linsolve_create(struct fluid_linsolve **out, const char *method,
                                      double rtol, int max_iter, int nthreads,
                                      struct mps_err *err)
{
    *out = NULL;
    if (!method)
        return mps_err_set(err, MPS_EINPUT, "linear solver method not given: expected one of %s",
                           METHOD_LIST);
    const struct method_ops *m = find_method(strcmp(method, "auto") ? method : AUTO_METHOD);
    if (!m)
        return mps_err_set(err, MPS_EINPUT,
                           "unknown linear solver method \"%s\": expected one of %s", method,
                           METHOD_LIST);
    if (!(rtol > 0.0 && rtol < 1.0))
        return mps_err_set(err, MPS_EINPUT, "linear solver rtol = %g: must be in (0, 1)", rtol);
    if (max_iter < 1)
        return mps_err_set(err, MPS_EINPUT, "linear solver max_iter = %d: must be >= 1",
                           max_iter);
    if (nthreads < 0)
        return mps_err_set(err, MPS_EINPUT,
                           "linear solver nthreads = %d: must be >= 0 (0 = OpenMP default)",
                           nthreads);

    struct fluid_linsolve *s = calloc(1, sizeof *s);
    if (!s)
        return mps_err_set(err, MPS_ENOMEM, "cannot allocate the linear solver");
    s->ops = m;
    s->rtol = rtol;
    s->max_iter = max_iter;
    s->perm_n = -1;
    s->drop2 = m->drop > 0.0 ? m->drop * m->drop : 0.0;
    s->nthreads = nthreads > 0 ? nthreads : omp_get_max_threads();
    if (s->nthreads < 1)
        s->nthreads = 1;
    s->partial = calloc((size_t)s->nthreads * PAD, sizeof *s->partial);
    if (!s->partial) {
        free(s);
        return mps_err_set(err, MPS_ENOMEM, "cannot allocate the linear solver");
    }
    enum mps_status st = m->start ? m->start(s, err) : MPS_OK;
    if (st) {
        fluid_linsolve_destroy(&s);
        return st;
    }
    *out = s;
    return MPS_OK;
}

/* pcg_defl's start: the coarse space */
static enum mps_status start_defl(struct fluid_linsolve *s, struct mps_err *err)
{
    return fluid_defl_create(&s->defl, s->nthreads, PAR_MIN_ROWS, err);
}

/* cholmod's and cholmod_reuse's start */
static enum mps_status start_cholmod(struct fluid_linsolve *s, struct mps_err *err)
{
    cholmod_msg[0] = '\0';
    if (!cholmod_start(&s->cm))
        return mps_err_set(err, MPS_ELIB, "%s: cholmod_start failed: %s", s->ops->name,
                           cholmod_msg);
    s->cm_started = 1;
    s->cm.print = 0;   /* errors come back through err, not stderr */
    s->cm.error_handler = cholmod_error_capture;
    return MPS_OK;
}

int fluid_linsolve_uses_aggregates(const struct fluid_linsolve *s)
{
    return s && s->defl;
}

enum mps_status fluid_linsolve_set_aggregates(struct fluid_linsolve *s, const int *agg, int n,
                                              int nagg, struct mps_err *err)
{
    if (!s)
        return mps_err_set(err, MPS_EINPUT, "fluid_linsolve_set_aggregates: NULL solver");
    if (!s->defl)
        return MPS_OK; /* other methods ignore them */
    return fluid_defl_set_aggregates(s->defl, agg, n, nagg, err);
}

int fluid_linsolve_coarse_size(const struct fluid_linsolve *s)
{
    return s && s->defl ? fluid_defl_coarse_size(s->defl) : 0;
}

void fluid_linsolve_trust_structure(struct fluid_linsolve *s, int trusted)
{
    s->trusted = trusted;
}

void fluid_linsolve_same_pattern(struct fluid_linsolve *s)
{
    s->same_pattern = 1;
}

void fluid_linsolve_changed_rows(struct fluid_linsolve *s, const int *rows, int nrows)
{
    s->same_pattern = 1;
    s->changed_rows = rows;
    s->nchanged = nrows;
}

enum mps_status fluid_linsolve_set_drop(struct fluid_linsolve *s, double theta,
                                        struct mps_err *err)
{
    if (!s)
        return mps_err_set(err, MPS_EINPUT, "fluid_linsolve_set_drop: NULL solver");
    /* theta >= 1 would drop every coupling of a diagonally dominant matrix
     * (|a_ij| <= min(a_ii, a_jj)) and leave the row sums alone on the
     * diagonal: a much worse preconditioner than Jacobi. */
    if (!(theta >= 0.0 && theta < 1.0))
        return mps_err_set(err, MPS_EINPUT, "%s: drop threshold theta = %g: must be in [0, 1)",
                           s->ops->name, theta);
    if (s->ops->drop >= 0.0)
        s->drop2 = theta * theta;
    return MPS_OK;
}

static void free_cholmod_state(struct fluid_linsolve *s)
{
    if (!s->cm_started)
        return;
    cholmod_free_factor(&s->L, &s->cm);
    cholmod_free_dense(&s->X, &s->cm);
    cholmod_free_dense(&s->Y, &s->cm);
    cholmod_free_dense(&s->E, &s->cm);
}

void fluid_linsolve_destroy(struct fluid_linsolve **sp)
{
    if (!sp || !*sp)
        return;
    struct fluid_linsolve *s = *sp;
    if (s->cm_started) {
        free_cholmod_state(s);
        cholmod_finish(&s->cm);
    }
    free(s->r);
    free(s->z);
    free(s->p);
    free(s->q);
    free(s->dinv);
    free(s->diag);
    free(s->partial);
    free(s->lptr);
    free(s->lcol);
    free(s->mark);
    free(s->lval);
    free(s->linv);
    free(s->comp);
    free(s->perm);
    free(s->pat_ptr);
    free(s->pat_col);
    fluid_defl_destroy(&s->defl);
    free(s);
    *sp = NULL;
}

/* ---------------------------------------------------------------------- */
/* Input checks. Rows are checked in parallel; the first bad row is found with
 * a min-reduction and then described sequentially, so the message is the
 * same whatever the thread count. */

static int row_bad(const struct fluid_csr *A, int i, const double *b, const double *x)
{
    int lo = A->rowptr[i], hi = A->rowptr[i + 1];
    if (hi < lo || lo < 0)
        return 1;
    int seen_diag = 0, prev = -1;
    for (int k = lo; k < hi; k++) {
        int j = A->col[k];
        if (j <= prev || j >= A->n || !isfinite(A->val[k]))
            return 1;
        if (j == i) {
            seen_diag = 1;
            if (!(A->val[k] > 0.0))
                return 1;
        }
        prev = j;
    }
    return !seen_diag || !isfinite(b[i]) || (x && !isfinite(x[i]));
}

static enum mps_status describe_bad_row(const struct fluid_linsolve *s, const struct fluid_csr *A,
                                        int i, const double *b, const double *x,
                                        struct mps_err *err)
{
    const char *mn = s->ops->name;
    int lo = A->rowptr[i], hi = A->rowptr[i + 1];
    if (hi < lo || lo < 0)
        return mps_err_set(err, MPS_EINPUT, "%s: row %d: rowptr %d..%d is not increasing", mn,
                           i, lo, hi);
    int seen_diag = 0, prev = -1;
    for (int k = lo; k < hi; k++) {
        int j = A->col[k];
        if (j >= A->n || j < 0)
            return mps_err_set(err, MPS_EINPUT, "%s: row %d: column %d out of range [0, %d)",
                               mn, i, j, A->n);
        if (j <= prev)
            return mps_err_set(err, MPS_EINPUT,
                               "%s: row %d: columns not sorted or repeated (%d after %d)", mn,
                               i, j, prev);
        if (!isfinite(A->val[k]))
            return mps_err_set(err, MPS_ESOLVE, "%s: row %d: A(%d,%d) = %g is not finite", mn,
                               i, i, j, A->val[k]);
        if (j == i) {
            seen_diag = 1;
            if (!(A->val[k] > 0.0))
                return mps_err_set(err, MPS_ESOLVE,
                                   "%s: row %d: diagonal A(%d,%d) = %g: must be > 0 for an "
                                   "SPD matrix",
                                   mn, i, i, i, A->val[k]);
        }
        prev = j;
    }
    if (!seen_diag)
        return mps_err_set(err, MPS_EINPUT, "%s: row %d: no diagonal entry stored", mn, i);
    if (!isfinite(b[i]))
        return mps_err_set(err, MPS_ESOLVE, "%s: row %d: right-hand side b = %g is not finite",
                           mn, i, b[i]);
    return mps_err_set(err, MPS_ESOLVE, "%s: row %d: initial guess x = %g is not finite", mn, i,
                       x ? x[i] : NAN);
}

/* scan_rows = 0 checks only the arguments, not every row (a trusted
 * caller, fluid_linsolve_trust_structure). */
static enum mps_status check_input(const struct fluid_linsolve *s, const struct fluid_csr *A,
                                   const double *b, const double *x, int scan_rows,
                                   struct mps_err *err)
{
    const char *mn = s->ops->name;
    if (A->n < 0)
        return mps_err_set(err, MPS_EINPUT, "%s: matrix size n = %d: must be >= 0", mn, A->n);
    if (A->n > 0 && (!A->rowptr || !A->col || !A->val || !b))
        return mps_err_set(err, MPS_EINPUT, "%s: matrix or right-hand side array is NULL", mn);
    if (A->n > 0 && A->rowptr[0] != 0)
        return mps_err_set(err, MPS_EINPUT, "%s: rowptr[0] = %d: must be 0", mn, A->rowptr[0]);
    if (!scan_rows)
        return MPS_OK;
    int n = A->n, bad = n;
#pragma omp parallel for num_threads(s->nthreads) if (n >= PAR_MIN_ROWS) schedule(static) \
    reduction(min : bad)
    for (int i = 0; i < n; i++)
        if (i < bad && row_bad(A, i, b, x))
            bad = i;
    if (bad < n)
        return describe_bad_row(s, A, bad, b, x, err);
    return MPS_OK;
}

/* ---------------------------------------------------------------------- */
/* Vector kernels. Each thread works on one contiguous block of rows (the
 * same block in every kernel) and leaves its partial sums in s->partial;
 * they are added in thread order, so results are reproducible for a given
 * thread count. */

/* Four partial sums: with one, a row of ~50 entries is a chain of ~50
 * dependent additions. Measured on the 3 mm dam break, 2 threads: the PPE
 * solve 2.88 to 2.66 ms per step, same iterations. The order is fixed, so
 * results stay reproducible (but differ from a one-sum product in the last
 * bits). */
static inline double row_dot(const struct fluid_csr *A, int i, const double *v)
{
    const int hi = A->rowptr[i + 1];
    const int *col = A->col;
    const double *val = A->val;
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    int k = A->rowptr[i];
    for (; k + 4 <= hi; k += 4) {
        /* A streams from memory at large n. Inline, a fixed distance ahead:
         * a span prefetch of the row 4 ahead (mps_prefetch_span, as the
         * neighbour loops do) made the solve slower, 34.7 to 36.0 ms per
         * step at 80k particles and 1.20 to 1.32 ms at 6.4k. */
        __builtin_prefetch(val + k + 256);
        __builtin_prefetch(col + k + 256);
        a0 += val[k] * v[col[k]];
        a1 += val[k + 1] * v[col[k + 1]];
        a2 += val[k + 2] * v[col[k + 2]];
        a3 += val[k + 3] * v[col[k + 3]];
    }
    for (; k < hi; k++)
        a0 += val[k] * v[col[k]];
    return (a0 + a1) + (a2 + a3);
}

/* Sums slot `which` of the nused threads' partials. */
static double gather(const struct fluid_linsolve *s, int nused, int which)
{
    double sum = 0.0;
    for (int t = 0; t < nused; t++)
        sum += s->partial[t * PAD + which];
    return sum;
}

/* r = b - A x; returns r.r and b.b in out[0], out[1]. nt: threads to use. */
static void k_residual(struct fluid_linsolve *s, int nt, const struct fluid_csr *A,
                       const double *b, const double *x, double *r, double out[2])
{
    int n = A->n, nused = 1;
#pragma omp parallel num_threads(nt) if (n >= PAR_MIN_ROWS)
    {
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        double rr = 0.0, bb = 0.0;
        for (int i = lo; i < hi; i++) {
            double ri = b[i] - row_dot(A, i, x);
            r[i] = ri;
            rr += ri * ri;
            bb += b[i] * b[i];
        }
        int t = omp_get_thread_num();
        s->partial[t * PAD] = rr;
        s->partial[t * PAD + 1] = bb;
        if (t == 0)
            nused = omp_get_num_threads();
    }
    out[0] = gather(s, nused, 0);
    out[1] = gather(s, nused, 1);
}

/* q = A p; returns p.q */
static double k_spmv_dot(struct fluid_linsolve *s, const struct fluid_csr *A, const double *p,
                         double *q)
{
    int n = A->n, nused = 1;
#pragma omp parallel num_threads(s->nthreads) if (n >= PAR_MIN_ROWS)
    {
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        double pq = 0.0;
        for (int i = lo; i < hi; i++) {
            double qi = row_dot(A, i, p);
            q[i] = qi;
            pq += p[i] * qi;
        }
        int t = omp_get_thread_num();
        s->partial[t * PAD] = pq;
        if (t == 0)
            nused = omp_get_num_threads();
    }
    return gather(s, nused, 0);
}

/* x += a p; r -= a q; returns r.r. With dinv (Jacobi) also z = dinv r and
 * r.z in out[1]. */
static void k_update(struct fluid_linsolve *s, int n, double a, const double *p, const double *q,
                     double *x, double *r, const double *dinv, double *z, double out[2])
{
    int nused = 1;
#pragma omp parallel num_threads(s->nthreads) if (n >= PAR_MIN_ROWS)
    {
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        double rr = 0.0, rz = 0.0;
        if (dinv) {
            for (int i = lo; i < hi; i++) {
                x[i] += a * p[i];
                double ri = r[i] - a * q[i];
                double zi = dinv[i] * ri;
                r[i] = ri;
                z[i] = zi;
                rr += ri * ri;
                rz += ri * zi;
            }
        } else {
            for (int i = lo; i < hi; i++) {
                x[i] += a * p[i];
                double ri = r[i] - a * q[i];
                r[i] = ri;
                rr += ri * ri;
            }
        }
        int t = omp_get_thread_num();
        s->partial[t * PAD] = rr;
        s->partial[t * PAD + 1] = rz;
        if (t == 0)
            nused = omp_get_num_threads();
    }
    out[0] = gather(s, nused, 0);
    out[1] = gather(s, nused, 1);
}

/* z = dinv r; returns r.z */
static double k_jacobi(struct fluid_linsolve *s, int n, const double *r, double *z)
{
    int nused = 1;
    const double *dinv = s->dinv;
#pragma omp parallel num_threads(s->nthreads) if (n >= PAR_MIN_ROWS)
    {
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        double rz = 0.0;
        for (int i = lo; i < hi; i++) {
            z[i] = dinv[i] * r[i];
            rz += r[i] * z[i];
        }
        int t = omp_get_thread_num();
        s->partial[t * PAD] = rz;
        if (t == 0)
            nused = omp_get_num_threads();
    }
    return gather(s, nused, 0);
}

/* p = z + beta p */
static void k_direction(struct fluid_linsolve *s, int n, double beta, const double *z, double *p)
{
#pragma omp parallel num_threads(s->nthreads) if (n >= PAR_MIN_ROWS)
    {
        int lo, hi;
        mps_omp_block(n, &lo, &hi);
        for (int i = lo; i < hi; i++)
            p[i] = z[i] + beta * p[i];
    }
}

/* ---------------------------------------------------------------------- */
/* IC(0): L L^T ~= A with L restricted to the lower-triangle pattern of A
 * (Meijerink & van der Vorst 1977; it exists for M-matrices), computed per
 * block of rows: with nblk > 1 the couplings between blocks are dropped
 * (block-Jacobi IC(0)), so each thread factorises and solves its own block.
 * Measured on the synthetic PPE with 2 threads: a few more iterations, but
 * set-up and triangular solves run in parallel (see docs/ppe_solvers.md).
 * Blocks are fixed row ranges, so the result depends on the number of
 * blocks, never on scheduling. */
static inline int blk_lo(int n, int nblk, int b) { return (int)((long long)n * b / nblk); }

/* Sparsified IC(0) (pcg_sic0): the factor is IC(0) of A~, which keeps the
 * couplings with a_ij^2 >= theta^2 a_ii a_jj and adds the others to the
 * diagonal of their row. The MPS Laplacian has ~45 neighbours within 4
 * spacings, most of them weak (w = 4/r - 1: 3 at one spacing, 0.33 at
 * three), and IC(0) costs (nonzeros per row)^2 to build and nonzeros per
 * row to apply; without the weak ones CG needs more iterations, but each is
 * cheaper and the factor much cheaper. Adding them to the diagonal keeps the
 * row sums, so the constant and smooth modes, the slow ones for CG, stay
 * well preconditioned (measured: partial compensation, dropped * omega with
 * omega = 0.9 .. 0, took 5-45% more iterations than omega = 1), and A~ stays
 * a weakly diagonally dominant M-matrix whose IC(0) exists. Compared as
 * (a_ij / a_ii) (a_ij / a_jj), a product of the same two factors for (i, j)
 * and (j, i): the decision is symmetric bit for bit, so A~ is symmetric
 * whenever A is. */
static inline int sic0_weak(const struct fluid_linsolve *s, int i, int j, double aij)
{
    return (aij * s->dinv[i]) * (aij * s->dinv[j]) < s->drop2;
}

/* Rows [lo, hi) of block b. Row-oriented: L_ik = (a_ik - sum_{j<k} L_ij L_kj)
 * / L_kk over the common pattern, found without a branch: mark[j] is the
 * position of L_ij for the columns of row i and otherwise a sentinel
 * position holding 0. Returns -1 on success or the row whose pivot was not
 * positive. */
static int ic0_factor_block(struct fluid_linsolve *s, const struct fluid_csr *A, int lo, int hi,
                            double shift)
{
    int *lptr = s->lptr, *lcol = s->lcol, *mark = s->mark;
    double *lval = s->lval, *linv = s->linv;
    const int zero = lptr[A->n];
    /* The block's lower triangle of A~ (see sic0_weak), the dropped
     * couplings (s->comp, from ic0_setup) added to the diagonal. Every
     * entry is written and the position advances only for kept ones:
     * no branch on a test that is true about as often as false. nz never
     * passes the diagonal's slot, which is written last. The shift scales
     * a_ii, not a~_ii, so that the fallback still reaches positive
     * pivots if the compensation left a~_ii small. pcg_ic0 is this with
     * drop2 = 0: nothing is dropped, comp is 0, the factor is IC(0) of A. */
    for (int i = lo; i < hi; i++) {
        int nz = lptr[i], k = A->rowptr[i];
        while (A->col[k] < lo)
            k++;
        for (; k < s->diag[i]; k++) {
            lcol[nz] = A->col[k];
            lval[nz] = A->val[k];
            nz += !sic0_weak(s, i, A->col[k], A->val[k]);
        }
        lcol[nz] = i;
        lval[nz] = A->val[s->diag[i]] * (1.0 + shift) + s->comp[i];
        mark[i] = zero;
    }
    for (int i = lo; i < hi; i++) {
        int rlo = lptr[i], dpos = lptr[i + 1] - 1;
        for (int p = rlo; p < dpos; p++)
            mark[lcol[p]] = p;
        double dsum = 0.0;
        for (int p = rlo; p < dpos; p++) {
            int k = lcol[p];
            double v = lval[p];
            int kend = lptr[k + 1] - 1;
            for (int q = lptr[k]; q < kend; q++)
                v -= lval[mark[lcol[q]]] * lval[q];
            v *= linv[k];
            lval[p] = v;
            dsum += v * v;
        }
        for (int p = rlo; p < dpos; p++)
            mark[lcol[p]] = zero;
        double d = lval[dpos] - dsum;
        /* A pivot that lost all but 1e-14 of the diagonal is as bad as a negative one. */
        if (!(d > 1e-14 * lval[dpos]))
            return i;
        lval[dpos] = sqrt(d);
        linv[i] = 1.0 / lval[dpos];
    }
    return -1;
}

/* Returns -1 or the first row (over all blocks) whose pivot failed. */
static int ic0_factor(struct fluid_linsolve *s, const struct fluid_csr *A, double shift)
{
    int n = A->n, nblk = s->nblk, bad = n;
#pragma omp parallel for num_threads(nblk) if (nblk > 1) schedule(static, 1) reduction(min : bad)
    for (int b = 0; b < nblk; b++) {
        int row = ic0_factor_block(s, A, blk_lo(n, nblk, b), blk_lo(n, nblk, b + 1), shift);
        if (row >= 0 && row < bad)
            bad = row;
    }
    return bad < n ? bad : -1;
}

static enum mps_status ic0_setup(struct fluid_linsolve *s, const struct fluid_csr *A,
                                 struct mps_err *err)
{
    int n = A->n;
    int *lptr = s->lptr;
    for (s->nblk = n >= PAR_MIN_ROWS ? s->nthreads : 1;; s->nblk = 1) {
        /* Row lengths of L (block-local lower triangle); count what the
         * split drops. */
        int nblk = s->nblk;
        long long dropped = 0, kept = 0;
#pragma omp parallel for num_threads(nblk) if (nblk > 1) schedule(static, 1) \
    reduction(+ : dropped, kept)
        for (int b = 0; b < nblk; b++) {
            int lo = blk_lo(n, nblk, b), hi = blk_lo(n, nblk, b + 1);
            /* Only the couplings A~ keeps count, for the length and the
             * split. The weak ones of each row go to s->comp, read from
             * the lower triangle only (half the traffic of whole rows):
             * a weak a_ij, j < i, counts for row i and, in the same
             * block, for row j; row i's weak couplings to later blocks
             * are read from the end of its row. Branch-free where the
             * test is as often true as false, see ic0_factor_block. */
            double *comp = s->comp;
            for (int i = lo; i < hi; i++)
                comp[i] = 0.0;
            for (int i = lo; i < hi; i++) {
                int len = 1, out = 0;
                double ci = 0.0;
                for (int k = A->rowptr[i]; k < s->diag[i]; k++) {
                    int j = A->col[k], strong = !sic0_weak(s, i, j, A->val[k]);
                    double w = strong ? 0.0 : A->val[k];
                    ci += w;
                    if (j >= lo)
                        comp[j] += w;
                    len += strong & (j >= lo);
                    out += strong & (j < lo);
                }
                for (int k = A->rowptr[i + 1] - 1; A->col[k] >= hi; k--)
                    ci += sic0_weak(s, i, A->col[k], A->val[k]) ? A->val[k] : 0.0;
                comp[i] += ci;
                lptr[i + 1] = len;
                kept += len - 1;
                dropped += out;
            }
        }
        /* Measured (synthetic PPE, 20k rows, 2 blocks): iterations grow 1.3x
         * when 1% of the lower-triangle couplings are dropped, 1.55x at 6%,
         * 1.7x at 10%, 2.2x at 23%, while a 2-block iteration costs 1/1.85 of
         * a sequential one. A row-major lattice numbering, which particles
         * sorted by cell resemble (fluid.c sorts at every list build), drops about
         * 1%; a scrambled numbering drops half. */
        if (nblk == 1 || dropped <= 0.1 * (double)(dropped + kept))
            break;
    }
    lptr[0] = 0;
    for (int i = 0; i < n; i++)
        lptr[i + 1] += lptr[i];
    size_t lnz = (size_t)lptr[n] + 1;   /* + the zero sentinel of ic0_factor_block */
    if (lnz > s->cap_lnz) {
        size_t c = lnz + lnz / 8;
        int fail = 0;
        s->lcol = mps_realloc_or_flag(s->lcol, c, sizeof *s->lcol, &fail);
        s->lval = mps_realloc_or_flag(s->lval, c, sizeof *s->lval, &fail);
        if (fail)
            return mps_err_set(err, MPS_ENOMEM, "%s: cannot allocate the IC(0) factor "
                                                "(%zu entries)", s->ops->name, lnz);
        s->cap_lnz = c;
    }
    s->lval[lptr[n]] = 0.0;
    /* Shifted IC (Manteuffel 1980) as the fallback: scale the diagonal by
     * 1 + shift, shift = 1e-3, 1e-2, ..., until every pivot is positive. */
    double shift = 0.0;
    int row;
    while ((row = ic0_factor(s, A, shift)) >= 0) {
        if (shift >= 10.0)
            return mps_err_set(err, MPS_ESOLVE,
                               "%s: incomplete Cholesky breaks down at row %d even with "
                               "the diagonal scaled by 1 + %g: matrix is not positive definite",
                               s->ops->name, row, shift);
        shift = shift > 0.0 ? 10.0 * shift : 1e-3;
    }
    return MPS_OK;
}

/* z = (L L^T)^{-1} r block by block; returns r.z. Within a block the solves
 * are sequential: each row needs the previous ones. */
static double ic0_apply(struct fluid_linsolve *s, int n, const double *r, double *z)
{
    const int *lptr = s->lptr, *lcol = s->lcol, nblk = s->nblk;
    const double *lval = s->lval, *linv = s->linv;
#pragma omp parallel for num_threads(nblk) if (nblk > 1) schedule(static, 1)
    for (int b = 0; b < nblk; b++) {
        int lo = blk_lo(n, nblk, b), hi = blk_lo(n, nblk, b + 1);
        for (int i = lo; i < hi; i++) {   /* L y = r */
            double v = r[i];
            int dpos = lptr[i + 1] - 1;
            for (int p = lptr[i]; p < dpos; p++)
                v -= lval[p] * z[lcol[p]];
            z[i] = v * linv[i];
        }
        double rz = 0.0;
        for (int i = hi - 1; i >= lo; i--) {   /* L^T z = y, column by column */
            double zi = z[i] * linv[i];
            z[i] = zi;
            rz += r[i] * zi;
            int dpos = lptr[i + 1] - 1;
            for (int p = lptr[i]; p < dpos; p++)
                z[lcol[p]] -= lval[p] * zi;
        }
        s->partial[b * PAD] = rz;
    }
    return gather(s, nblk, 0);
}

static double precond(struct fluid_linsolve *s, int n, const double *r, double *z)
{
    return s->ops->precond_apply(s, n, r, z);
}

/* (Re)starts CG from the residual s->r of x: with deflation first moves x
 * so that Z^T r = 0 (updating *rr = r.r), then z = M^-1 r, p = z (projected
 * with deflation); r.z in *rz. */
static enum mps_status first_direction(struct fluid_linsolve *s, const struct fluid_csr *A,
                                       double *x, double *rr, double *rz, struct mps_err *err)
{
    const int n = A->n;
    enum mps_status rc;
    if (s->defl && (rc = fluid_defl_start(s->defl, A, x, s->r, rr, err)))
        return rc;
    *rz = precond(s, n, s->r, s->z);
    if (s->defl)
        return fluid_defl_direction(s->defl, A, s->z, 0.0, s->p, err);
    memcpy(s->p, s->z, (size_t)n * sizeof *s->p);
    return MPS_OK;
}

static enum mps_status pcg(struct fluid_linsolve *s, const struct fluid_csr *A, const double *b,
                           double *x, struct fluid_linsolve_stats *st, struct mps_err *err)
{
    int n = A->n;
    const char *mn = s->ops->name;
    enum mps_status rc = reserve_vectors(s, (size_t)n, err);
    if (rc)
        return rc;

    double *r = s->r, *z = s->z, *p = s->p, *q = s->q;
    /* Jacobi's z = dinv r is fused into the update (k_update) */
    const double *dinv = s->ops->precond_apply == k_jacobi ? s->dinv : NULL;
    double t0 = omp_get_wtime(), rb[2];
    k_residual(s, s->nthreads, A, b, x, r, rb);
    if (!isfinite(rb[0]) || !isfinite(rb[1])) {
        /* a non-finite value in A, b or x (a trusted caller skipped the
         * check): find and name it */
        enum mps_status bad = check_input(s, A, b, x, 1, err);
        return bad ? bad
                   : mps_err_set(err, MPS_ESOLVE, "%s: initial residual is not finite",
                                 s->ops->name);
    }
    double bnorm = sqrt(rb[1]);
    const int was_current = s->setup_current && s->setup_n == n;
    s->setup_current = 0; /* until this solve's set-up is done */
    if (bnorm == 0.0) {   /* b = 0: x = 0 exactly, no iteration */
        memset(x, 0, (size_t)n * sizeof *x);
        st->residual = 0.0;
        st->t_solve = omp_get_wtime() - t0;
        return MPS_OK;
    }
    double tol2 = s->rtol * bnorm * s->rtol * bnorm;
    if (rb[0] <= tol2) {   /* the warm start is already good enough: no set-up either */
        st->residual = sqrt(rb[0]) / bnorm;
        st->t_solve = omp_get_wtime() - t0;
        return MPS_OK;
    }

    double t1 = omp_get_wtime();
    /* the last solve's set-up, for the rows that changed since (the
     * pattern, so the diagonal's places, is the same) */
    const int *rows = s->same_pattern && was_current && s->changed_rows &&
                              !s->ops->precond_setup
                          ? s->changed_rows
                          : NULL;
    if (rows) {
        for (int k = 0; k < s->nchanged; k++)
            s->dinv[rows[k]] = 1.0 / A->val[s->diag[rows[k]]];
    } else {
#pragma omp parallel for num_threads(s->nthreads) if (n >= PAR_MIN_ROWS) schedule(static)
        for (int i = 0; i < n; i++) {
            int k = A->rowptr[i];
            while (A->col[k] != i) /* check_input guarantees it is there */
                k++;
            s->diag[i] = k;
            s->dinv[i] = 1.0 / A->val[k];
        }
    }
    if (s->ops->precond_setup && (rc = s->ops->precond_setup(s, A, err)))
        return rc;
    if (s->defl && (rc = fluid_defl_setup(s->defl, A, s->same_pattern && was_current,
                                          rows, s->nchanged, err)))
        return rc;
    s->setup_current = 1;
    s->setup_n = n;
    double t2 = omp_get_wtime();
    st->t_factor = t2 - t1;

    double rr = rb[0], rz;
    int it = 0, converged = 0;
    if ((rc = first_direction(s, A, x, &rr, &rz, err)))
        return rc;
    while (it < s->max_iter) {
        if (rr <= tol2) {
            /* the deflated start can solve a small system outright (every
             * row its own aggregate: a few drops of water), leaving p = 0
             * and nothing to iterate on */
            k_residual(s, s->nthreads, A, b, x, r, rb);
            if ((rr = rb[0]) <= tol2) {
                converged = 1;
                break;
            }
        }
        double pq = k_spmv_dot(s, A, p, q);
        it++;
        if (!(pq > 0.0) || !(rz > 0.0)) {
            st->iterations = it;
            st->residual = sqrt(rr) / bnorm;
            st->t_solve = (t1 - t0) + (omp_get_wtime() - t2);
            return mps_err_set(err, MPS_ESOLVE,
                               "%s: matrix or preconditioner not positive definite "
                               "(p.Ap = %g, r.z = %g at iteration %d)",
                               mn, pq, rz, it);
        }
        double alpha = rz / pq, upd[2];
        k_update(s, n, alpha, p, q, x, r, dinv, z, upd);
        rr = upd[0];
        if (rr <= tol2) {
            /* The recursive residual drifts from b - Ax in finite precision:
             * accept only if the true one agrees, else restart from it. */
            k_residual(s, s->nthreads, A, b, x, r, rb);
            rr = rb[0];
            if (rr <= tol2) {
                converged = 1;
                break;
            }
            if ((rc = first_direction(s, A, x, &rr, &rz, err)))
                return rc;
            continue;
        }
        double rz_new = dinv ? upd[1] : precond(s, n, r, z);
        double beta = rz_new / rz;
        rz = rz_new;
        if (!s->defl)
            k_direction(s, n, beta, z, p);
        else if ((rc = fluid_defl_direction(s->defl, A, z, beta, p, err)))
            return rc;
    }
    st->iterations = it;
    st->residual = sqrt(rr) / bnorm;
    st->t_solve = (t1 - t0) + (omp_get_wtime() - t2);
    if (!converged)
        return mps_err_set(err, MPS_ESOLVE,
                           "%s: PCG did not converge in %d iterations (residual %.3g > rtol %.3g)",
                           mn, it, st->residual, s->rtol);
    return MPS_OK;
}

/* ---------------------------------------------------------------------- */
/* CHOLMOD. The CSR arrays are viewed, not copied, as a CSC matrix: for a
 * symmetric matrix row i of the CSR is column i of the CSC. stype = 1 tells
 * CHOLMOD to read the upper triangle only. CHOLMOD does not write to A. */

static int same_pattern(const struct fluid_linsolve *s, const struct fluid_csr *A)
{
    size_t nnz = (size_t)A->rowptr[A->n];
    return s->L && s->perm_n == A->n && (size_t)s->pat_ptr[A->n] == nnz &&
           !memcmp(s->pat_ptr, A->rowptr, (size_t)(A->n + 1) * sizeof *A->rowptr) &&
           !memcmp(s->pat_col, A->col, nnz * sizeof *A->col);
}

/* cholmod_reuse bookkeeping after an analysis: remember the ordering and the
 * pattern. Failing to allocate only turns reuse off for the next call. */
static void remember_analysis(struct fluid_linsolve *s, const struct fluid_csr *A)
{
    size_t n = (size_t)A->n, nnz = (size_t)A->rowptr[n];
    int fail = 0;
    s->perm_n = -1;
    if (n + 1 > s->cap_perm) {
        s->perm = mps_realloc_or_flag(s->perm, n + n / 8 + 1, sizeof *s->perm, &fail);
        s->pat_ptr = mps_realloc_or_flag(s->pat_ptr, n + n / 8 + 1, sizeof *s->pat_ptr, &fail);
        if (fail)
            return;
        s->cap_perm = n + n / 8 + 1;
    }
    if (nnz > s->cap_pat) {
        s->pat_col = mps_realloc_or_flag(s->pat_col, nnz + nnz / 8, sizeof *s->pat_col, &fail);
        if (fail)
            return;
        s->cap_pat = nnz + nnz / 8;
    }
    memcpy(s->perm, s->L->Perm, n * sizeof *s->perm);
    memcpy(s->pat_ptr, A->rowptr, (n + 1) * sizeof *s->pat_ptr);
    memcpy(s->pat_col, A->col, nnz * sizeof *s->pat_col);
    s->perm_n = (int)n;
}

/* Symbolic analysis of A into s->L. cholmod_reuse first tries the ordering
 * of the previous matrix of the same size and keeps it only if the predicted
 * factorisation flops (per nonzero of A) are within 10% of what the last
 * fresh ordering gave. Measured on the synthetic PPE: after a motion of 0.02
 * particle spacings the old ordering needed 4.5x (5k rows) to 9x (80k) the
 * flops, as new edges cross its separators; a fresh ordering costs a quarter
 * of a factorisation at 5k-20k rows and about as much at 80k (METIS). Trying
 * costs a symbolic analysis, so after k rejections in a row the next 2^k
 * calls (at most 64) do not try. */
static enum mps_status analyse(struct fluid_linsolve *s, cholmod_sparse *As,
                               const struct fluid_csr *A, struct mps_err *err)
{
    cholmod_common *cm = &s->cm;
    double nnz = (double)A->rowptr[A->n];
    int reuse = s->ops->reuse_ordering;
    cholmod_free_factor(&s->L, cm);
    int try_old = reuse && s->perm_n == A->n;
    if (try_old && s->skip > 0) {
        s->skip--;
        try_old = 0;
    }
    if (try_old) {
        cm->nmethods = 1;
        cm->method[0].ordering = CHOLMOD_GIVEN;
        cm->postorder = 1;
        s->L = cholmod_analyze_p(As, s->perm, NULL, 0, cm);
        cm->nmethods = 0;   /* back to CHOLMOD's default ordering strategy */
        if (!s->L || cm->status < CHOLMOD_OK) {
            s->perm_n = -1;
            cholmod_free_factor(&s->L, cm);
            return cholmod_fail(s, "cholmod_analyze_p", err);
        }
        if (cm->fl <= 1.1 * s->flops_ref * nnz) {
            s->rejected = 0;
            remember_analysis(s, A);
            return MPS_OK;
        }
        cholmod_free_factor(&s->L, cm);
        if (s->rejected < 6)
            s->rejected++;
        s->skip = 1 << s->rejected;
    }
    s->L = cholmod_analyze(As, cm);
    if (!s->L || cm->status < CHOLMOD_OK) {
        s->perm_n = -1;
        cholmod_free_factor(&s->L, cm);
        return cholmod_fail(s, "cholmod_analyze", err);
    }
    if (reuse) {
        s->flops_ref = cm->fl / nnz;
        remember_analysis(s, A);
    }
    return MPS_OK;
}

static enum mps_status direct(struct fluid_linsolve *s, const struct fluid_csr *A,
                              const double *b, double *x, struct fluid_linsolve_stats *st,
                              struct mps_err *err)
{
    int n = A->n;
    size_t nnz = (size_t)A->rowptr[n];
    cholmod_common *cm = &s->cm;
    cholmod_sparse As = {0};   /* a view of A, see above */
    As.nrow = As.ncol = (size_t)n;
    As.nzmax = nnz;
    As.p = (void *)A->rowptr;
    As.i = (void *)A->col;
    As.x = (void *)A->val;
    As.stype = 1;
    As.itype = CHOLMOD_INT;
    As.xtype = CHOLMOD_REAL;
    As.dtype = CHOLMOD_DOUBLE;
    As.sorted = 1;
    As.packed = 1;
    cholmod_msg[0] = '\0';
    enum mps_status rc = reserve_vectors(s, (size_t)n, err);   /* residual vector */
    if (rc)
        return rc;

    double t0 = omp_get_wtime();
    int reuse = s->ops->reuse_ordering;
    if (!(reuse && same_pattern(s, A))) {   /* else the symbolic factor is still valid */
        if ((rc = analyse(s, &As, A, err)))
            return rc;
        st->t_analyse = omp_get_wtime() - t0;
    }
    double t1 = omp_get_wtime();

    /* Positive status values are warnings; only "not positive definite" matters. */
    if (!cholmod_factorize(&As, s->L, cm) || cm->status < CHOLMOD_OK ||
        cm->status == CHOLMOD_NOT_POSDEF) {
        if (cm->status == CHOLMOD_NOT_POSDEF)
            rc = mps_err_set(err, MPS_ESOLVE,
                             "%s: cholmod_factorize: matrix not positive definite (pivot %zu of "
                             "%d, in the fill-reducing ordering, is not positive)",
                             s->ops->name, (size_t)s->L->minor + 1, n);
        else
            rc = cholmod_fail(s, "cholmod_factorize", err);
        cholmod_free_factor(&s->L, cm);
        s->perm_n = -1;   /* start over next call */
        return rc;
    }
    double t2 = omp_get_wtime();
    st->t_factor = t2 - t1;

    cholmod_dense B = {0};
    B.nrow = (size_t)n;
    B.ncol = 1;
    B.nzmax = (size_t)n;
    B.d = (size_t)n;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    B.x = (void *)b;
    double rb[2];
    /* One or two steps of iterative refinement if the factor was not quite
     * accurate enough for rtol (never needed on well-scaled PPEs). */
    for (int pass = 0; pass < 3; pass++) {
        if (!cholmod_solve2(CHOLMOD_A, s->L, &B, NULL, &s->X, NULL, &s->Y, &s->E, cm) ||
            cm->status < CHOLMOD_OK)
            return cholmod_fail(s, "cholmod_solve2", err);
        const double *xs = s->X->x;
        if (pass == 0)
            memcpy(x, xs, (size_t)n * sizeof *x);
        else
            for (int i = 0; i < n; i++)
                x[i] += xs[i];
        /* Sequential on purpose: OpenBLAS (pthreads build) keeps its workers
         * spinning after a call, and an OpenMP team started now fights them
         * for the cores (measured: the next parallel solve ran 20x slower). */
        k_residual(s, 1, A, b, x, s->r, rb);
        if (rb[0] <= s->rtol * s->rtol * rb[1])
            break;
        B.x = s->r;
    }
    st->residual = rb[1] > 0.0 ? sqrt(rb[0] / rb[1]) : 0.0;
    st->t_solve = omp_get_wtime() - t2;
    return MPS_OK;
}

/* ---------------------------------------------------------------------- */

enum mps_status fluid_linsolve_solve(struct fluid_linsolve *s, const struct fluid_csr *A,
                                     const double *b, double *x,
                                     struct fluid_linsolve_stats *stats, struct mps_err *err)
{
    struct fluid_linsolve_stats local;
    struct fluid_linsolve_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    if (!s || !A || (A->n > 0 && !x))
        return mps_err_set(err, MPS_EINPUT, "fluid_linsolve_solve: NULL solver, matrix or x");
    int iterative = s->ops->iterative;
    enum mps_status rc =
        check_input(s, A, b, iterative ? x : NULL, !(iterative && s->trusted), err);
    if (rc || A->n == 0) {
        s->same_pattern = 0;
        s->changed_rows = NULL;
        s->setup_current = 0;
        return rc;
    }
    rc = s->ops->solve(s, A, b, x, st, err);
    s->same_pattern = 0;
    s->changed_rows = NULL;
    if (rc)
        s->setup_current = 0;
    return rc;
}
