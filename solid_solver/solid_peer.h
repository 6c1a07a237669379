/* The solid program under the coupler (proto/PROTOCOL.md): any solid model
 * behind struct solid_model_ops, driven by the protocol loop. */
#ifndef SOLID_PEER_H
#define SOLID_PEER_H

#include "solid_model.h"

/* Runs the conversation on endpoint; returns the process exit code. */
int solid_peer_run(const char *endpoint, const struct solid_model_ops *ops, int hello_timeout_ms,
                   volatile const int *stop_flag);

#endif
