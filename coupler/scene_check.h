/* Checks across the fluid's and the solid's parts of one case, which no
 * solver sees whole: every solid body inside the tank (or its part in a wall
 * clamped), no body in a water block. Run by the coupler before it launches
 * anything. The coupler does not link the solvers: it reads the few layout
 * keys it needs as raw values (mps_case_text), and a value that is not a
 * finite number, or a rectangle that is not one, is left to the solver that
 * owns the key, which reports it at CONFIG (PROTOCOL.md 8). */
#ifndef SCENE_CHECK_H
#define SCENE_CHECK_H

#include "mps_case.h"

/* MPS_OK, or an input error naming the body's key and what it hits. */
enum mps_status scene_check_fsi(const struct mps_case *c, struct mps_err *err);

#endif
