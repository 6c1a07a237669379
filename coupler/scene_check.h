/* Checks across the fluid's and the solid's parts of one case, which no
 * solver sees whole: every solid body inside the tank (but for clamped parts,
 * which may stand in the walls' place), no body in a water block. Run by the coupler before it launches anything. */
#ifndef SCENE_CHECK_H
#define SCENE_CHECK_H

#include "fluid_params.h"
#include "mps_case.h"
#include "solid_scene.h"

/* MPS_OK, or an input error naming the body's key and what it hits. */
enum mps_status scene_check_fsi(const struct fluid_params *fp, const struct solid_scene *sc,
                                const struct mps_case *c, struct mps_err *err);

#endif
