/* Case keys the coupler owns ("coupling."), and the union of every
 * program's keys so the coupler validates a whole case strictly. */
#ifndef COUPLER_KEYS_H
#define COUPLER_KEYS_H

#include "mps_case.h"

extern const struct mps_key_spec coupler_case_keys[];

#endif
