/* ZeroMQ transport of proto_msg (proto/PROTOCOL.md sections 1, 2, 7). */
#include "proto_link.h"

#include <errno.h>
#include <string.h>
#include <time.h>
#include <zmq.h>

static enum mps_status zfail(struct mps_err *err, const char *what, const char *endpoint)
{
    int e = zmq_errno();
    if (e == EINTR)
        return mps_err_set(err, MPS_EINTR, "%s%s%s: interrupted", what, endpoint ? " " : "",
                           endpoint ? endpoint : "");
    return mps_err_set(err, MPS_ELIB, "%s%s%s: %s", what, endpoint ? " " : "",
                       endpoint ? endpoint : "", zmq_strerror(e));
}

/* CURVE options, set before bind/connect. 0 or -1 (zmq_errno set). */
static int set_curve(void *s, enum proto_link_mode mode, const struct proto_curve *k,
                     const char *zap_domain)
{
    int hs = PROTO_HANDSHAKE_MS;
    if (zmq_setsockopt(s, ZMQ_HANDSHAKE_IVL, &hs, sizeof hs) != 0)
        return -1;
    if (mode == PROTO_LINK_BIND) {
        int on = 1;
        const char *dom = zap_domain ? zap_domain : "";
        return zmq_setsockopt(s, ZMQ_CURVE_SERVER, &on, sizeof on) != 0 ||
                       zmq_setsockopt(s, ZMQ_CURVE_SECRETKEY, k->server_secret,
                                      PROTO_KEY_Z85) != 0 ||
                       zmq_setsockopt(s, ZMQ_ZAP_DOMAIN, dom, strlen(dom)) != 0
                   ? -1
                   : 0;
    }
    return zmq_setsockopt(s, ZMQ_CURVE_SERVERKEY, k->server_public, PROTO_KEY_Z85) != 0 ||
                   zmq_setsockopt(s, ZMQ_CURVE_PUBLICKEY, k->client_public, PROTO_KEY_Z85) !=
                       0 ||
                   zmq_setsockopt(s, ZMQ_CURVE_SECRETKEY, k->client_secret, PROTO_KEY_Z85) != 0
               ? -1
               : 0;
}

enum mps_status proto_link_open(void *zctx, enum proto_link_mode mode, const char *endpoint,
                                void **sock, struct mps_err *err)
{
    return proto_link_open_secure(zctx, mode, endpoint, NULL, NULL, sock, err);
}

enum mps_status proto_link_open_secure(void *zctx, enum proto_link_mode mode,
                                       const char *endpoint, const struct proto_curve *curve,
                                       const char *zap_domain, void **sock,
                                       struct mps_err *err)
{
    *sock = NULL;
    if (!zctx || !endpoint)
        return mps_err_set(err, MPS_EINPUT, "proto_link_open: no context or endpoint");
    if (strncmp(endpoint, "ipc://", 6) == 0 && strlen(endpoint + 6) > PROTO_IPC_PATH_MAX)
        return mps_err_set(err, MPS_EINPUT,
                           "endpoint %s: ipc path is %zu bytes, the system allows %d; use a "
                           "shorter run directory or tcp://",
                           endpoint, strlen(endpoint + 6), PROTO_IPC_PATH_MAX);
    void *s = zmq_socket(zctx, ZMQ_DEALER);
    if (!s)
        return zfail(err, "zmq_socket(DEALER) for", endpoint);
    int linger = PROTO_LINGER_MS, sndtimeo = PROTO_SEND_TIMEOUT_MS;
    if (zmq_setsockopt(s, ZMQ_LINGER, &linger, sizeof linger) != 0 ||
        zmq_setsockopt(s, ZMQ_SNDTIMEO, &sndtimeo, sizeof sndtimeo) != 0) {
        enum mps_status st = zfail(err, "zmq_setsockopt on", endpoint);
        zmq_close(s);
        return st;
    }
    if (curve && set_curve(s, mode, curve, zap_domain) != 0) {
        enum mps_status st = zfail(err, "setting CURVE keys on", endpoint);
        zmq_close(s);
        return st;
    }
    int rc = mode == PROTO_LINK_BIND ? zmq_bind(s, endpoint) : zmq_connect(s, endpoint);
    if (rc != 0) {
        enum mps_status st =
            zfail(err, mode == PROTO_LINK_BIND ? "cannot bind" : "cannot connect to", endpoint);
        zmq_close(s);
        return st;
    }
    *sock = s;
    return MPS_OK;
}

void proto_link_close(void **sock)
{
    if (sock && *sock) {
        zmq_close(*sock);
        *sock = NULL;
    }
}

enum mps_status proto_link_send(void *sock, const struct proto_msg *m, struct mps_err *err)
{
    struct proto_frames fr;
    enum mps_status st = proto_msg_encode(m, &fr, err);
    if (st)
        return st;
    for (int k = 0; k < fr.n; k++) {
        zmq_msg_t part;
        if (zmq_msg_init_size(&part, fr.f[k].len) != 0) {
            st = zfail(err, "zmq_msg_init_size", NULL);
            break;
        }
        if (fr.f[k].len)
            memcpy(zmq_msg_data(&part), fr.f[k].data, fr.f[k].len);
        int flags = k + 1 < fr.n ? ZMQ_SNDMORE : 0;
        int rc;
        /* Only the first part can block (HWM, no peer); once it is queued the
         * rest of a multipart message is accepted, so retry a signal there. */
        while ((rc = zmq_msg_send(&part, sock, flags)) < 0 && zmq_errno() == EINTR && k > 0) {
        }
        if (rc < 0) {
            int e = zmq_errno();
            zmq_msg_close(&part);
            if (e == EAGAIN)
                st = mps_err_set(err, MPS_ETIMEOUT,
                                 "sending %s: not queued within %d ms (peer gone?)",
                                 proto_type_name(m->type), PROTO_SEND_TIMEOUT_MS);
            else
                st = zfail(err, "sending", proto_type_name(m->type));
            break;
        }
    }
    proto_frames_clear(&fr);
    return st;
}

static long long now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

enum mps_status proto_link_poll(void *const *socks, int n, int timeout_ms, int *which,
                                struct mps_err *err)
{
    enum { MAXS = 8 };
    zmq_pollitem_t items[MAXS];
    if (n < 1 || n > MAXS)
        return mps_err_set(err, MPS_EINPUT, "proto_link_poll: %d sockets (1..%d)", n, MAXS);
    for (int k = 0; k < n; k++)
        items[k] = (zmq_pollitem_t){.socket = socks[k], .events = ZMQ_POLLIN};
    long long deadline = timeout_ms >= 0 ? now_ms() + timeout_ms : -1;
    for (;;) {
        long wait = -1;
        if (deadline >= 0) {
            long long left = deadline - now_ms();
            wait = left > 0 ? (long)left : 0;
        }
        int rc = zmq_poll(items, n, wait);
        if (rc < 0)
            return zfail(err, "waiting for a message", NULL);
        for (int k = 0; k < n; k++) {
            if (items[k].revents & ZMQ_POLLIN) {
                *which = k;
                return MPS_OK;
            }
        }
        if (deadline >= 0 && now_ms() >= deadline)
            return mps_err_set(err, MPS_ETIMEOUT, "no message within %d ms", timeout_ms);
    }
}

enum mps_status proto_link_recv(void *sock, struct proto_msg *m, int timeout_ms,
                                struct mps_err *err)
{
    memset(m, 0, sizeof *m);
    long long deadline = timeout_ms >= 0 ? now_ms() + timeout_ms : -1;
    zmq_msg_t parts[PROTO_MAX_FRAMES], extra;
    struct proto_frame frames[PROTO_MAX_FRAMES];
    int kept = 0, total = 0, more = 1;
    enum mps_status st = MPS_OK;
    while (more) {
        if (total == 0) {
            int which, left = -1;
            if (deadline >= 0) {
                long long l = deadline - now_ms();
                left = l > 0 ? (int)l : 0;
            }
            if ((st = proto_link_poll(&sock, 1, left, &which, err)))
                return st;
        }
        zmq_msg_t *part = kept < PROTO_MAX_FRAMES ? &parts[kept] : &extra;
        zmq_msg_init(part);
        int rc;
        /* ZeroMQ delivers a multipart message whole: once the first part is
         * readable all are, so only the first receive can find nothing (a
         * spurious wake-up: poll again). Later parts are retried on a signal
         * so the stream stays in step. */
        while ((rc = zmq_msg_recv(part, sock, total ? 0 : ZMQ_DONTWAIT)) < 0 &&
               zmq_errno() == EINTR && total > 0) {
        }
        if (rc < 0) {
            int e = zmq_errno();
            zmq_msg_close(part);
            if (total == 0 && e == EAGAIN)
                continue;
            st = zfail(err, "receiving a message", NULL);
            break;
        }
        more = zmq_msg_more(part);
        total++;
        if (part == &extra) {
            zmq_msg_close(part);
        } else {
            frames[kept] = (struct proto_frame){zmq_msg_data(part), zmq_msg_size(part)};
            kept++;
        }
    }
    if (st == MPS_OK && total > kept)
        st = mps_err_set(err, MPS_EPROTO, "message of %d frames, at most %d", total,
                         PROTO_MAX_FRAMES);
    if (st == MPS_OK)
        st = proto_msg_decode(m, frames, kept, err);
    for (int k = 0; k < kept; k++)
        zmq_msg_close(&parts[k]);
    return st;
}
