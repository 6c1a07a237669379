/* Memory a scene will need, checked before anything is allocated: a case
 * that cannot fit in this machine is refused at once, with the estimate,
 * rather than failing (or swapping) halfway through its setup. */
#ifndef MPS_BUDGET_H
#define MPS_BUDGET_H

#include "mps_case.h"
#include "mps_err.h"

/* Resident bytes per particle, measured (peak RSS less the ~20 MB a process
 * starts with, over the particle count; docs/security.md): the fluid with
 * its neighbour lists and PPE matrix, 2.2-2.5 kB from 13k to 53k particles
 * (dam break, dp 2 and 1 mm); the MPS solid with its bonds, 1.23 kB at 824k
 * particles (cantilever, dp 0.5 mm). */
#define MPS_BUDGET_FLUID_BYTES 2500.0
#define MPS_BUDGET_SOLID_BYTES 1250.0

/* Physical memory of this machine in bytes (0 if unknown). */
double mps_budget_physical_bytes(void);

/* MPS_OK if particles x bytes_each fits in physical memory (or it is
 * unknown); else an input error on key (normally "dp") that says how many
 * particles, how many bytes, and how much the machine has. */
enum mps_status mps_budget_check(const struct mps_case *c, const char *key, const char *what,
                                 double particles, double bytes_each, struct mps_err *err);

#endif
