/* The coupling protocol over ZeroMQ: DEALER sockets, one multipart message per
 * proto_msg, every receive with a deadline (proto/PROTOCOL.md sections 1, 7).
 * Sockets come from a caller-owned zmq context; the caller closes them with
 * proto_link_close() before zmq_ctx_term(). */
#ifndef PROTO_LINK_H
#define PROTO_LINK_H

#include "mps_err.h"
#include "proto_key.h"
#include "proto_msg.h"

#define PROTO_LINGER_MS 1000          /* last messages still leave; close never hangs */
#define PROTO_SEND_TIMEOUT_MS 10000   /* a send not queued by then: peer lost */
#define PROTO_IPC_PATH_MAX 107        /* Linux sun_path, without the NUL */

enum proto_link_mode {
    PROTO_LINK_BIND,     /* the coupler, one socket per solver */
    PROTO_LINK_CONNECT   /* a solver */
};

/* Opens a ZMQ_DEALER socket bound or connected to endpoint ("ipc://PATH" or
 * "tcp://HOST:PORT") with ZMQ_LINGER and ZMQ_SNDTIMEO set as above. An ipc
 * path longer than PROTO_IPC_PATH_MAX is MPS_EINPUT; a failing zmq call is
 * MPS_ELIB. *sock is NULL on failure. */
enum mps_status proto_link_open(void *zctx, enum proto_link_mode mode, const char *endpoint,
                                void **sock, struct mps_err *err);

/* The same with CURVE security (PROTOCOL.md section 10) when curve is not
 * NULL. BIND: a CURVE server with curve->server_secret whose connections are
 * authenticated by the ZAP handler under zap_domain (the caller must run one
 * before it binds: without a handler libzmq accepts any client key).
 * CONNECT: a CURVE client with curve->server_public and the client pair.
 * Handshakes that do not finish within PROTO_HANDSHAKE_MS are dropped. */
#define PROTO_HANDSHAKE_MS 5000
enum mps_status proto_link_open_secure(void *zctx, enum proto_link_mode mode,
                                       const char *endpoint, const struct proto_curve *curve,
                                       const char *zap_domain, void **sock,
                                       struct mps_err *err);

/* Closes the socket (linger applies) and sets *sock = NULL; NULL ok. */
void proto_link_close(void **sock);

/* Encodes and sends m as one multipart message. MPS_EPROTO if m breaks a
 * rule (nothing is sent), MPS_ETIMEOUT if it cannot be queued within
 * PROTO_SEND_TIMEOUT_MS, MPS_EINTR on a signal, MPS_ELIB otherwise. */
enum mps_status proto_link_send(void *sock, const struct proto_msg *m, struct mps_err *err);

/* Waits up to timeout_ms (< 0: forever) for one message and decodes it into
 * m, which then owns its data (proto_msg_clear() it). Returns MPS_ETIMEOUT
 * after the deadline, MPS_EINTR if a signal interrupted the wait (m empty in
 * both cases, nothing consumed), MPS_EPROTO if the message was malformed (it
 * is consumed and dropped), MPS_ELIB if zmq failed. */
enum mps_status proto_link_recv(void *sock, struct proto_msg *m, int timeout_ms,
                                struct mps_err *err);

/* Waits up to timeout_ms for any of n sockets to have a message; *which is
 * the index of the first readable one. Same MPS_ETIMEOUT / MPS_EINTR /
 * MPS_ELIB rules as proto_link_recv. For a coupler watching both solvers. */
enum mps_status proto_link_poll(void *const *socks, int n, int timeout_ms, int *which,
                                struct mps_err *err);

#endif
