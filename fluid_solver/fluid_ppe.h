/* Assembly and solution of the weakly compressible pressure Poisson equation
 * (Eq. 23). Unknowns are the particles that carry a pressure (fluid, wall,
 * solid surface) and are not on the free surface (P = 0 there). With the
 * Laplacian of Eq. 12 the system reads, for each unknown i,
 *   c sum_j w_ij (P_i - P_j) + (rho alpha / dt^2) P_i = kappa rho/dt^2 (n*_i - n0)/n0
 * with c = 2d/(lambda n0): symmetric, positive definite, diagonally dominant.
 * We read Eq. 23's alpha term as (rho/dt^2) alpha P, the form that follows
 * from Eq. 22; taken literally (alpha P alone) it would be ~1e-11 of the
 * diagonal and change nothing. */
#ifndef FLUID_PPE_H
#define FLUID_PPE_H

#include "fluid.h"

enum mps_status fluid_ppe_assemble(struct fluid *f, double dt, struct mps_err *err);
/* Solves (warm-started from the previous pressure) and writes f->p. */
enum mps_status fluid_ppe_solve(struct fluid *f, struct fluid_linsolve_stats *stats,
                                struct mps_err *err);

/* Writes the last assembled system as Matrix Market files (A: lower triangle,
 * b: array), for the solver benchmarks. */
enum mps_status fluid_ppe_dump(const struct fluid *f, const char *matrix_path,
                               const char *rhs_path, struct mps_err *err);

#endif
