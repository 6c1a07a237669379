/* Sparse symmetric positive definite solves for the pressure Poisson equation.
 * The PPE matrix changes every step (particles move, neighbours change), so
 * each call gives a new matrix; solvers may keep state between calls (a
 * CHOLMOD symbolic analysis, preconditioner work arrays) and reuse what is
 * still valid. Methods are selectable by name from the case file
 * (fluid.ppe_solver) so their cost can be measured against each other. */
#ifndef FLUID_LINSOLVE_H
#define FLUID_LINSOLVE_H

#include <stddef.h>

#include "mps_err.h"

/* Symmetric matrix in CSR with both triangles stored, rows sorted by column,
 * the diagonal present in every row. Row i has columns col[rowptr[i]..rowptr[i+1]). */
struct fluid_csr {
    int n;
    const int *rowptr;   /* n + 1 */
    const int *col;
    const double *val;
};

struct fluid_linsolve_stats {
    int iterations;      /* 0 for direct methods */
    double residual;     /* final ||b - Ax|| / ||b|| */
    double t_analyse;    /* s: symbolic analysis / ordering (0 when reused) */
    double t_factor;     /* s: numeric factorisation or preconditioner setup */
    double t_solve;      /* s: triangular solves or iterations */
};

struct fluid_linsolve;

/* method: "pcg_jacobi", "pcg_ic0", "pcg_sic0" (IC(0) of a sparsified
 * matrix, see fluid_linsolve_set_drop), "pcg_defl" (Jacobi PCG deflated by
 * aggregates of rows, see fluid_linsolve_set_aggregates), "cholmod",
 * "cholmod_reuse" (keeps the fill-reducing ordering while the matrix size
 * and pattern allow), "auto" (the measured default). rtol: relative residual for iterative methods.
 * max_iter: iteration cap (an iterative solve that hits it fails with
 * MPS_ESOLVE naming the residual reached). */
enum mps_status fluid_linsolve_create(struct fluid_linsolve **out, const char *method,
                                      double rtol, int max_iter, int nthreads,
                                      struct mps_err *err);

/* pcg_sic0's drop threshold theta in [0, 1): the preconditioner is IC(0) of
 * the matrix without the couplings a_ij^2 < theta^2 a_ii a_jj, each dropped
 * one added to the diagonal of its row (row sums kept). 0 drops nothing
 * (pcg_ic0's preconditioner). Takes effect from the next solve. Other
 * methods accept it and ignore it, so a case setting can be passed whatever
 * the method. Fails with MPS_EINPUT outside [0, 1). */
enum mps_status fluid_linsolve_set_drop(struct fluid_linsolve *s, double theta,
                                        struct mps_err *err);

/* pcg_defl: the aggregate of each of the n rows of the next matrix(es),
 * agg[i] in [0, nagg), every aggregate non-empty (groups of rows close in
 * space: the coarse space is their indicator vectors). The array is borrowed:
 * it must stay valid and unchanged through the solves it is meant for. A
 * solve of a matrix with another row count, or with none given, uses blocks
 * of 16 consecutive rows. Fails with MPS_EINPUT naming a bad row. Other
 * methods ignore it. */
enum mps_status fluid_linsolve_set_aggregates(struct fluid_linsolve *s, const int *agg, int n,
                                              int nagg, struct mps_err *err);
/* 1 if the method uses aggregates (pcg_defl). */
int fluid_linsolve_uses_aggregates(const struct fluid_linsolve *s);
/* pcg_defl: size of the last coarse system (0 before the first). */
int fluid_linsolve_coarse_size(const struct fluid_linsolve *s);

/* For a caller whose matrices are well formed by construction (sorted
 * columns in range, the diagonal stored: the fluid's PPE assembly): the
 * iterative methods then skip the row-by-row structure check before each
 * solve (1-2% of a fluid step). Non-finite values are still caught, through
 * the initial residual, and reported row by row as without it. */
void fluid_linsolve_trust_structure(struct fluid_linsolve *s, int trusted);

/* The next solve's matrix has the last solve's pattern (rowptr and col,
 * entry for entry) and, for pcg_defl, the same aggregates: only values
 * changed. pcg_defl then refills its coarse space's lists instead of
 * building them (the same numbers, to the bit). Holds for one solve. */
void fluid_linsolve_same_pattern(struct fluid_linsolve *s);

/* As fluid_linsolve_same_pattern, and the next solve's matrix differs from
 * the last solve's only in the values of these rows (an entry A_ij that
 * changed lists both i and j; the release of held PPE rows changes a
 * handful of rows and their neighbours). The PCG methods without a
 * factored preconditioner then keep Jacobi's diagonal but for those rows,
 * and pcg_defl refills only the coarse entries they touch: the same
 * numbers, to the bit, as a full set-up. If the last solve did not set up
 * (its start was already converged, or it failed), a full set-up. rows:
 * borrowed until that solve. Holds for one solve. */
void fluid_linsolve_changed_rows(struct fluid_linsolve *s, const int *rows, int nrows);

/* Solves A x = b. On entry x holds the initial guess (iterative methods start
 * from it: warm start from the previous step's pressure); on exit the
 * solution. */
enum mps_status fluid_linsolve_solve(struct fluid_linsolve *s, const struct fluid_csr *A,
                                     const double *b, double *x,
                                     struct fluid_linsolve_stats *stats, struct mps_err *err);

const char *fluid_linsolve_method(const struct fluid_linsolve *s);
/* Comma-separated list of the method names, for error messages and docs. */
const char *fluid_linsolve_methods(void);

void fluid_linsolve_destroy(struct fluid_linsolve **s);

#endif
