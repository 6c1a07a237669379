/* Deflation of CG on the PPE by a coarse space of aggregates (pcg_defl in
 * fluid_linsolve.h): Z is the n x m indicator matrix of groups of rows close
 * in space, E = Z^T A Z the m x m coarse matrix, factorised with CHOLMOD at
 * every setup. The caller runs Jacobi CG and calls fluid_defl_start() once
 * on its initial residual and fluid_defl_direction() for every new direction.
 * See docs/ppe_solvers.md, "Deflation". */
#ifndef FLUID_DEFL_H
#define FLUID_DEFL_H

#include "fluid_linsolve.h"
#include "mps_err.h"

struct fluid_defl;

/* nthreads > 0; loops over rows run on them from par_min_rows rows on. */
enum mps_status fluid_defl_create(struct fluid_defl **out, int nthreads, int par_min_rows,
                                  struct mps_err *err);
void fluid_defl_destroy(struct fluid_defl **d);

/* The aggregate of each of the n rows, agg[i] in [0, nagg); borrowed until
 * the solves it is meant for are done (fluid_linsolve_set_aggregates). A
 * matrix with another row count, or none given, gets blocks of 16
 * consecutive rows. */
enum mps_status fluid_defl_set_aggregates(struct fluid_defl *d, const int *agg, int n, int nagg,
                                          struct mps_err *err);

/* A Z, E and E's factor for matrix A. An empty aggregate (or an A that is not
 * positive definite) is reported as MPS_ESOLVE. same_pattern: A has the
 * pattern (rowptr, col) of the last set-up's matrix and the aggregates are
 * the same array: A Z's lists are refilled with the new values and E's
 * factor is computed again on its kept analysis (the same numbers a full
 * set-up gives, for a third of its cost); without a last set-up of that
 * size and those aggregates, a full one. rows (with same_pattern; NULL:
 * all): the nrows rows whose values differ from the last set-up's matrix
 * (an entry A_ij that changed lists both i and j); only they, and E's
 * columns they touch, are refilled. */
enum mps_status fluid_defl_setup(struct fluid_defl *d, const struct fluid_csr *A,
                                 int same_pattern, const int *rows, int nrows,
                                 struct mps_err *err);

/* x += Z c, r -= A Z c with c = E^-1 Z^T r, so that Z^T r = 0; r.r in *rr. */
enum mps_status fluid_defl_start(struct fluid_defl *d, const struct fluid_csr *A, double *x,
                                 double *r, double *rr, struct mps_err *err);

/* The next search direction, made A-orthogonal to range(Z):
 * p = z + beta p - Z E^-1 (A Z)^T z (beta = 0: the first, p's content
 * unread). */
enum mps_status fluid_defl_direction(struct fluid_defl *d, const struct fluid_csr *A,
                                     const double *z, double beta, double *p,
                                     struct mps_err *err);

/* m of the last setup (0 before the first). */
int fluid_defl_coarse_size(const struct fluid_defl *d);

#endif
