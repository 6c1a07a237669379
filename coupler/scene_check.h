/* Checks across the fluid's and the solid's parts of one case, which no
 * solver sees whole: every solid body inside the tank (or its part in a wall
 * clamped), no body in a water block. Run by the coupler before it launches
 * anything. The coupler does not link the solvers: it reads the few layout
 * keys it needs as raw values (mps_case_text), and a value that is not a
 * finite number, or a rectangle that is not one, is left to the solver that
 * owns the key, which reports it at CONFIG (PROTOCOL.md 8). */
#ifndef SCENE_CHECK_H
#define SCENE_CHECK_H

#include <stdio.h>

#include "mps_case.h"

/* MPS_OK, or an input error naming the body's key and what it hits. */
enum mps_status scene_check_fsi(const struct mps_case *c, struct mps_err *err);

/* Warnings, not errors, to out: a layout that dp does not divide still runs,
 * but not as declared. A body (or water block) fills only whole spacings
 * (lattice points at x0 + (i + 1/2) dp while inside), so a body dp does not
 * divide is built smaller than declared, and water declared against it
 * starts more than one spacing from its particles: at the sloshing case's
 * dp = 0.9 mm the plate is 3.6 mm thick instead of 4 and the oil stands
 * 1.4-1.8 spacings from it, whose pressure beside the plate falls to 0 in
 * the first step (docs/sloshing.md, "Why 0.8 and 0.5 mm"). with_fluid: the
 * water blocks too. Returns the number of warnings. */
int scene_check_lattice(const struct mps_case *c, int with_fluid, FILE *out);

#endif
