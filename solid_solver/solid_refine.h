/* A solid model run on a lattice finer than the fluid's (solid.refine = k):
 * the model holds k x k particles in each cell of the case's dp lattice, and
 * the fluid meets it on that dp lattice, as it would an unrefined solid.
 *
 * Why: a thin plate two to four fluid particles thick is also two to four
 * solid particles thick, where the MPS solid bends 24-40% more than the plate
 * does (docs/hard_cases.md, docs/sloshing.md); the fluid near the plate does
 * not need the solid's resolution.
 *
 * The map, fixed at creation on the initial lattice (no fracture: a crack
 * would make new surface inside a block):
 *   - coupling particle c is the block of the cell it sits in; its position
 *     and velocity are the means of the block's particles (so the mean of a
 *     rigid motion is the motion, and at the start c sits on the dp lattice);
 *   - c is a surface particle if its block holds one of the model's surface
 *     particles, clamped if all of the block's are;
 *   - the load on c is shared equally by the block's surface particles (the
 *     fluid's pressure acts on the body's surface), by all of its particles
 *     if it has none; the body's total force and moment at the block scale
 *     are those the fluid computed.
 * Snapshots, probes, the stable step and the state (rollback, checkpoints)
 * are the model's own, at its resolution. */
#ifndef SOLID_REFINE_H
#define SOLID_REFINE_H

#include "mps_case.h"
#include "mps_err.h"
#include "solid_model.h"

/* Wraps the model (*ops, *self) built from case c with c's solid.refine > 1:
 * on success *ops is the wrapper's table (named like the model) and *self
 * the wrapper, which owns the model. On failure the model is destroyed and
 * *self is NULL. */
enum mps_status solid_refine_wrap(const struct solid_model_ops **ops, void **self,
                                  const struct mps_case *c, struct mps_err *err);

#endif
