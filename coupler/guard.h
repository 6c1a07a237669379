/* The coupler's door on tcp (proto/PROTOCOL.md section 10): a ZAP handler
 * that lets a connection through only with the CURVE public key issued for
 * that endpoint this run, and a watch on the endpoints that counts and names
 * every connection refused below the protocol (a stranger never reaches the
 * coupler's message loop). It runs in its own thread, so a handshake never
 * waits for the coupler's loop.
 *
 * Use: guard_create() before any CURVE socket is bound; guard_allow() and
 * guard_watch() per endpoint (watch right after the bind, before any solver
 * is launched); guard_start(); at the end guard_stop() (before the watched
 * sockets close), then read the counts and guard_destroy(). */
#ifndef GUARD_H
#define GUARD_H

#include <stdio.h>

#include "mps_err.h"
#include "mps_json.h"

struct guard;

/* Binds the ZAP handler's socket in zctx (inproc://zeromq.zap.01). */
enum mps_status guard_create(struct guard **g, void *zctx, struct mps_err *err);

/* Accepts client_public (Z85) on the endpoint whose ZAP domain is domain
 * ("fluid", "solid"), and nothing else there. */
enum mps_status guard_allow(struct guard *g, const char *domain, const char *client_public,
                            struct mps_err *err);

/* Watches sock (a bound CURVE server with ZAP domain `domain`) for refused
 * connections. Events before this call are not seen (they are still refused,
 * only not counted), so call it right after the bind. */
enum mps_status guard_watch(struct guard *g, void *sock, const char *domain,
                            struct mps_err *err);

/* Starts the thread; from here on it owns the guard's sockets. With log set,
 * the first refusal from each address on each endpoint is one line there. */
enum mps_status guard_start(struct guard *g, FILE *log, struct mps_err *err);

/* Stops the thread after it has drained what is queued (up to ~0.5 s). */
void guard_stop(struct guard *g);

/* Refused connections so far (all endpoints). */
long guard_refused(const struct guard *g);

/* "12 on fluid, 3 on solid, from 127.0.0.1 (15)"; "" if none. */
void guard_describe(const struct guard *g, char *buf, size_t len);

/* Writes "refused_connections": {...} (count, per endpoint, per address). */
void guard_json(const struct guard *g, struct mps_json *j);

/* Closes the guard's sockets and frees it; NULL ok; *g = NULL. */
void guard_destroy(struct guard **g);

#endif
