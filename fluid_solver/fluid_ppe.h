/* Assembly and solution of the weakly compressible pressure Poisson equation
 * (Eq. 23). Unknowns are the particles that carry a pressure and are not on
 * the free surface (P = 0 there): fluid only with Neumann walls
 * (fluid.wall_bc = neumann), fluid, wall and solid surface particles with the
 * paper's walls (ppe), fluid and solid surface with solid_ppe (Neumann tank
 * walls, the paper's coupling to the solid). With the Laplacian of Eq. 12 the system reads, for
 * each unknown i,
 *   c sum_j w_ij (P_i - P_j) + (rho alpha / dt^2) P_i = rhs_i,  c = 2d/(lambda n0),
 * symmetric, positive definite, diagonally dominant.
 * rhs_i, density source (Eq. 23): kappa rho/dt^2 (n*_i - n0)/n0.
 * rhs_i, mixed source: the same plus -(rho/dt) div v*_i (Eq. 10 on the
 *   Laplacian's neighbours by default, fluid.divergence_stencil), and with Neumann
 *   walls (also solid_ppe) + (rho alpha/dt^2) P^n_i: continuity with the equation of state
 *   (Eq. 21) over one step, alpha (P^{n+1} - P^n)/dt = -div v^{n+1}, so
 *   compressibility acts on the change of pressure and still water keeps its
 *   pressure from step to step. With the density source alone (and with the
 *   paper's walls, as before) alpha P^{n+1} stands for the compression
 *   itself, as in Eq. 22-23.
 * We read Eq. 23's alpha term as (rho/dt^2) alpha P, the form that follows
 * from Eq. 22; taken literally (alpha P alone) it would be ~1e-11 of the
 * diagonal and change nothing.
 * Neumann walls add to rhs_i the known sum c w_ij rho g.(x_j - x_i) over
 * boundary neighbours j, and particles near the free surface get a diagonal
 * term closing the truncated Laplacian (fluid.surface_laplacian); see
 * fluid_ppe.c and docs/fluid.md. */
#ifndef FLUID_PPE_H
#define FLUID_PPE_H

#include "fluid.h"

enum mps_status fluid_ppe_assemble(struct fluid *f, double dt, struct mps_err *err);
/* Solves (warm-started from the previous pressure) and writes f->p. */
enum mps_status fluid_ppe_solve(struct fluid *f, struct fluid_linsolve_stats *stats,
                                struct mps_err *err);

/* Neumann walls: sets the pressure of every boundary particle (wall, dummy,
 * solid) from the fluid pressures around it, extrapolated hydrostatically.
 * Needs f->nl (solid particles) and f->nl_tank (tank particles). */
void fluid_ppe_boundary_pressure(struct fluid *f);
/* Sets negative boundary pressures to zero (if fluid.clamp_negative), after
 * the gradient has used them: for output and the loads on a solid. */
void fluid_ppe_boundary_clamp(struct fluid *f);

/* The rhs of a PPE row is the sum of four parts, kept per row when
 * f->keep_ppe_terms is set: the walls' hydrostatic extrapolation (ghost),
 * Eq. 23's density error, the compressibility's memory of the last
 * pressure, and the mixed source's divergence. The PPE is linear, so the
 * pressure is the sum of the pressures each part alone asks for
 * (bench/ppe_terms.py; docs/pressure.md, "The two halves of the mixed
 * source"). A record is the row particle's position, then the four. */
enum { FLUID_PPE_TERMS = MPS_DIM + 4 };

/* Writes the last assembled system as Matrix Market files (A: lower triangle,
 * b: array), for the solver benchmarks; with terms_path (and
 * f->keep_ppe_terms) also the rhs's parts per row as CSV. */
enum mps_status fluid_ppe_dump(const struct fluid *f, const char *matrix_path,
                               const char *rhs_path, const char *terms_path,
                               struct mps_err *err);

#endif
