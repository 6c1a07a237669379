/* Case keys the coupler owns ("coupling."), and what it validates a case
 * against: the common keys, its own and the tank's motion. The sections
 * "fluid." and "solid." are the solvers' (PROTOCOL.md 8): each validates its
 * own when it gets CONFIG, so a solver of another make may have keys of its
 * own, and the coupler does not link the solvers. */
#ifndef COUPLER_KEYS_H
#define COUPLER_KEYS_H

#include "mps_case.h"

extern const struct mps_key_spec coupler_case_keys[];

#define COUPLER_NTABLES 3
/* mps_case_common_keys, coupler_case_keys, mps_motion_keys */
extern const struct mps_key_spec *const coupler_case_tables[COUPLER_NTABLES];
/* "fluid.", "solid.", NULL: left to the solvers */
extern const char *const coupler_solver_sections[];

#endif
