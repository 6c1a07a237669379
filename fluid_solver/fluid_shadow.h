/* Thin bodies (fluid.body_shadow): the particle pairs that a coupled solid
 * stands between. At 6 mm the dam break's plate is two particles thick and
 * the PPE Laplacian reaches 4 dp: a row on one face took the pressure of the
 * water on the other face and of the other face's particles (dp away,
 * weight 3), and the fluid's pressure gradient (2.1 dp) that of the other
 * face. The plate held still with water 72 mm deep on one side and 24 mm on
 * the other read 18% / 13% less force / moment than hydrostatic
 * (docs/pressure.md). Such pairs are left out of the PPE Laplacian and of
 * the pressure gradient; the number density keeps them (the body fills the
 * space). */
#ifndef FLUID_SHADOW_H
#define FLUID_SHADOW_H

#include "fluid.h"

/* solid surface particles within re_lap of one particle: about 50 in 2-D */
#define FLUID_SHADOW_MAX 128

/* The weighted sum of the offsets from solid particle i to its solid
 * neighbours within re_n, negated: the direction away from the body's
 * particles (not normalised; 0 for a lone particle). The face loads
 * (fluid_coupling.c) and the shadow's normals both use it. */
void fluid_body_outward(const struct fluid *f, size_t i, double out[MPS_DIM]);

/* f->body_n of every solid surface particle, from the solid particles
 * around it (at the current positions; needs f->nl). */
void fluid_shadow_normals(struct fluid *f);

/* A solid surface particle with no water on its side of the body (within
 * re_lap, not shadowed) is dry: P = 0 (f->surface). Its row would
 * otherwise join only the rows of its own face, which the shadow cuts off
 * from the rest: a block of the PPE with no Dirichlet value, singular on
 * the first step (the dry face of tests/coupler/plate_in_water.yml's plate
 * stopped the PCG). Needs fluid_shadow_normals first. */
void fluid_shadow_dry(struct fluid *f);

/* The solid surface particles other than i within re_lap of i, into near
 * (at most FLUID_SHADOW_MAX); returns their number, or -1 if no pair of i
 * can be shadowed (none near and i not one). */
int fluid_shadow_near(const struct fluid *f, size_t i, int *near_out);

/* Whether the line between i and j enters a body; near, nnear from
 * fluid_shadow_near(f, i, ...). Symmetric: (i, j) and (j, i) agree. */
int fluid_shadowed(const struct fluid *f, size_t i, size_t j, const int *near, int nnear);

/* use[k] = 0 for the shadowed pairs of list nl (a sublist of f->nl's
 * rows, as f->nl_n), 1 for the others; rows of particles without a query
 * flag are left as they are. */
void fluid_shadow_mask(const struct fluid *f, const struct mps_nbr_list *nl,
                       const unsigned char *query, unsigned char *use);

#endif
