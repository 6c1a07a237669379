/* ZAP handler and refused-connection watch of the coupler (guard.h). */
#include "guard.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <zmq.h>

#include "proto_key.h"

#define MAX_DOMAINS 4
#define MAX_ADDRS 16     /* distinct refused addresses named; the rest are counted */
#define MAX_FDS 1024     /* accepted sockets whose peer address is remembered */
#define POLL_MS 100

struct domain {
    char name[16];
    uint8_t key[32];     /* the one client key allowed */
    int has_key;
    void *mon;           /* PAIR connected to the socket's monitor */
    long refused;
    int failed_pending;  /* a failed handshake whose DISCONNECTED names it */
};

struct addr {
    char ip[64];
    long count;
};

struct conn {
    int open, auth;
    long seq;            /* order of acceptance */
    struct domain *domain;
    char ip[64];
};

struct guard {
    void *zctx, *zap;
    struct domain d[MAX_DOMAINS];
    int nd;
    struct addr a[MAX_ADDRS];
    int na;
    long unnamed;        /* refusals whose address was not learnt */
    struct conn conn[MAX_FDS]; /* by fd: the watched sockets' connections */
    long seq;
    FILE *log;
    pthread_t thread;
    int running;
    volatile int stop;
    pthread_mutex_t lock;
};

enum mps_status guard_create(struct guard **gp, void *zctx, struct mps_err *err)
{
    *gp = NULL;
    struct guard *g = calloc(1, sizeof *g);
    if (!g)
        return mps_err_set(err, MPS_ENOMEM, "guard: out of memory");
    g->zctx = zctx;
    pthread_mutex_init(&g->lock, NULL);
    g->zap = zmq_socket(zctx, ZMQ_REP);
    int linger = 0;
    if (!g->zap || zmq_setsockopt(g->zap, ZMQ_LINGER, &linger, sizeof linger) != 0 ||
        zmq_bind(g->zap, "inproc://zeromq.zap.01") != 0) {
        enum mps_status st = mps_err_set(err, MPS_ELIB, "cannot start the ZAP handler: %s",
                                         zmq_strerror(zmq_errno()));
        guard_destroy(&g);
        return st;
    }
    *gp = g;
    return MPS_OK;
}

static struct domain *find_domain(struct guard *g, const char *name, size_t n)
{
    for (int k = 0; k < g->nd; k++)
        if (strlen(g->d[k].name) == n && memcmp(g->d[k].name, name, n) == 0)
            return &g->d[k];
    return NULL;
}

static struct domain *add_domain(struct guard *g, const char *name, struct mps_err *err)
{
    struct domain *d = find_domain(g, name, strlen(name));
    if (d)
        return d;
    if (g->nd == MAX_DOMAINS || strlen(name) >= sizeof d->name) {
        mps_err_set(err, MPS_EINPUT, "guard: cannot add endpoint '%s'", name);
        return NULL;
    }
    d = &g->d[g->nd++];
    snprintf(d->name, sizeof d->name, "%s", name);
    return d;
}

enum mps_status guard_allow(struct guard *g, const char *domain, const char *client_public,
                            struct mps_err *err)
{
    struct domain *d = add_domain(g, domain, err);
    if (!d)
        return MPS_EINPUT;
    if (strlen(client_public) != PROTO_KEY_Z85 || !zmq_z85_decode(d->key, client_public))
        return mps_err_set(err, MPS_EINPUT, "guard: '%s' is not a Z85 key", client_public);
    d->has_key = 1;
    return MPS_OK;
}

enum mps_status guard_watch(struct guard *g, void *sock, const char *domain,
                            struct mps_err *err)
{
    struct domain *d = add_domain(g, domain, err);
    if (!d)
        return MPS_EINPUT;
    char ep[64];
    snprintf(ep, sizeof ep, "inproc://guard-%s", d->name);
    int events = ZMQ_EVENT_ACCEPTED | ZMQ_EVENT_DISCONNECTED | ZMQ_EVENT_HANDSHAKE_SUCCEEDED |
                 ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                 ZMQ_EVENT_HANDSHAKE_FAILED_AUTH;
    if (zmq_socket_monitor(sock, ep, events) != 0)
        return mps_err_set(err, MPS_ELIB, "zmq_socket_monitor: %s", zmq_strerror(zmq_errno()));
    d->mon = zmq_socket(g->zctx, ZMQ_PAIR);
    int linger = 0;
    if (!d->mon || zmq_setsockopt(d->mon, ZMQ_LINGER, &linger, sizeof linger) != 0 ||
        zmq_connect(d->mon, ep) != 0)
        return mps_err_set(err, MPS_ELIB, "cannot watch the %s endpoint: %s", d->name,
                           zmq_strerror(zmq_errno()));
    return MPS_OK;
}

/* ---- the thread ---- */

static void note_refusal(struct guard *g, struct domain *d, const char *ip, const char *why)
{
    pthread_mutex_lock(&g->lock);
    d->refused++;
    int k = 0, first = 0;
    if (!ip[0]) {
        g->unnamed++;
    } else {
        while (k < g->na && strcmp(g->a[k].ip, ip) != 0)
            k++;
        if (k == g->na && g->na < MAX_ADDRS) {
            snprintf(g->a[g->na].ip, sizeof g->a[0].ip, "%s", ip);
            g->na++;
            first = 1;
        }
        if (k < g->na)
            g->a[k].count++;
        else
            g->unnamed++;
    }
    pthread_mutex_unlock(&g->lock);
    if (first && g->log)
        fprintf(g->log,
                "coupler: refused a connection to the %s endpoint from %s (%s); further ones "
                "are counted in summary.json\n",
                d->name, ip, why);
}

/* One ZAP request (RFC 27): accept iff CURVE with the domain's one key. */
static void serve_zap(struct guard *g)
{
    zmq_msg_t part[8];
    int kept = 0, more = 1;
    while (more) {
        zmq_msg_t m;
        zmq_msg_init(&m);
        if (zmq_msg_recv(&m, g->zap, 0) < 0) {
            zmq_msg_close(&m);
            break;
        }
        more = zmq_msg_more(&m);
        if (kept < 8) {
            zmq_msg_init(&part[kept]);
            zmq_msg_move(&part[kept++], &m);
        }
        zmq_msg_close(&m);
    }
    const char *status = "400", *text = "no valid key for this run";
    struct domain *d = NULL;
    if (kept >= 7 && zmq_msg_size(&part[0]) == 3 && memcmp(zmq_msg_data(&part[0]), "1.0", 3) == 0) {
        d = find_domain(g, zmq_msg_data(&part[2]), zmq_msg_size(&part[2]));
        int curve = zmq_msg_size(&part[5]) == 5 && memcmp(zmq_msg_data(&part[5]), "CURVE", 5) == 0;
        if (d && d->has_key && curve && zmq_msg_size(&part[6]) == 32 &&
            memcmp(zmq_msg_data(&part[6]), d->key, 32) == 0)
            status = "200", text = "OK";
    }
    /* the refusal itself is counted from the socket's HANDSHAKE_FAILED_AUTH
     * event; the reply must go out whatever the request held */
    const void *reqid = kept >= 2 ? zmq_msg_data(&part[1]) : "";
    size_t reqlen = kept >= 2 ? zmq_msg_size(&part[1]) : 0;
    zmq_send(g->zap, "1.0", 3, ZMQ_SNDMORE);
    zmq_send(g->zap, reqid, reqlen, ZMQ_SNDMORE);
    zmq_send(g->zap, status, 3, ZMQ_SNDMORE);
    zmq_send(g->zap, text, strlen(text), ZMQ_SNDMORE);
    zmq_send(g->zap, d ? d->name : "", d ? strlen(d->name) : 0, ZMQ_SNDMORE);
    zmq_send(g->zap, "", 0, 0);
    for (int k = 0; k < kept; k++)
        zmq_msg_close(&part[k]);
}

static void peer_ip(int fd, char *out, size_t len)
{
    struct sockaddr_storage sa;
    socklen_t sl = sizeof sa;
    out[0] = '\0';
    if (getpeername(fd, (struct sockaddr *)&sa, &sl) != 0)
        return;
    if (sa.ss_family == AF_INET)
        inet_ntop(AF_INET, &((struct sockaddr_in *)&sa)->sin_addr, out, (socklen_t)len);
    else if (sa.ss_family == AF_INET6)
        inet_ntop(AF_INET6, &((struct sockaddr_in6 *)&sa)->sin6_addr, out, (socklen_t)len);
}

/* One monitor event (libzmq 4.x: frame 1 = u16 event + u32 value, frame 2 =
 * endpoint). A connection is refused when it closes without having been
 * authenticated: after a failed handshake (the engine reports the failure,
 * then the DISCONNECTED of its fd, one after the other) or before any
 * handshake at all (not ZeroMQ: only ACCEPTED and DISCONNECTED). Its peer
 * address is read from the fd at ACCEPTED. A HANDSHAKE_SUCCEEDED carries no
 * fd: it marks the oldest connection of that endpoint still open and
 * unresolved, which is the solver's unless a stranger's handshake was in
 * flight at the same moment (then the two swap; the count stays exact once
 * the solver has gone). */
static void serve_monitor(struct guard *g, struct domain *d)
{
    zmq_msg_t m;
    zmq_msg_init(&m);
    if (zmq_msg_recv(&m, d->mon, 0) < 0) {
        zmq_msg_close(&m);
        return;
    }
    uint16_t ev = 0;
    uint32_t val = 0;
    if (zmq_msg_size(&m) >= 6) {
        memcpy(&ev, zmq_msg_data(&m), 2);
        memcpy(&val, (const char *)zmq_msg_data(&m) + 2, 4);
    }
    int more = zmq_msg_more(&m);
    zmq_msg_close(&m);
    while (more) { /* the endpoint frame */
        zmq_msg_init(&m);
        if (zmq_msg_recv(&m, d->mon, 0) < 0)
            more = 0;
        else
            more = zmq_msg_more(&m);
        zmq_msg_close(&m);
    }
    int fd = (int)val, known = fd >= 0 && fd < MAX_FDS;
    struct conn *cn = known ? &g->conn[fd] : NULL;
    switch (ev) {
    case ZMQ_EVENT_ACCEPTED:
        if (cn) {
            *cn = (struct conn){.open = 1, .seq = ++g->seq, .domain = d};
            peer_ip(fd, cn->ip, sizeof cn->ip);
        }
        break;
    case ZMQ_EVENT_HANDSHAKE_SUCCEEDED: {
        struct conn *oldest = NULL;
        for (int k = 0; k < MAX_FDS; k++) {
            struct conn *o = &g->conn[k];
            if (o->open && !o->auth && o->domain == d && (!oldest || o->seq < oldest->seq))
                oldest = o;
        }
        if (oldest)
            oldest->auth = 1;
        break;
    }
    case ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL:
    case ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL:
    case ZMQ_EVENT_HANDSHAKE_FAILED_AUTH:
        if (d->failed_pending) /* its DISCONNECTED never came: count it unnamed */
            note_refusal(g, d, "", "");
        d->failed_pending = ev;
        break;
    case ZMQ_EVENT_DISCONNECTED: {
        const char *why = d->failed_pending == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH
                              ? "CURVE key not issued for this run"
                          : d->failed_pending ? "no CURVE handshake with this run's server key"
                                              : "closed before a ZeroMQ handshake";
        if (d->failed_pending || !cn || !cn->open || !cn->auth)
            note_refusal(g, d, cn && cn->open ? cn->ip : "", why);
        d->failed_pending = 0;
        if (cn)
            cn->open = 0;
        break;
    }
    default:
        break;
    }
}

static void *guard_main(void *arg)
{
    struct guard *g = arg;
    zmq_pollitem_t items[1 + MAX_DOMAINS];
    int n = 0;
    struct domain *who[1 + MAX_DOMAINS];
    items[n] = (zmq_pollitem_t){g->zap, 0, ZMQ_POLLIN, 0};
    who[n++] = NULL;
    for (int k = 0; k < g->nd; k++)
        if (g->d[k].mon) {
            items[n] = (zmq_pollitem_t){g->d[k].mon, 0, ZMQ_POLLIN, 0};
            who[n++] = &g->d[k];
        }
    int idle_after_stop = 0;
    for (;;) {
        int rc = zmq_poll(items, n, POLL_MS);
        if (rc < 0 && zmq_errno() != EINTR)
            break;
        if (rc > 0) {
            for (int k = 0; k < n; k++)
                if (items[k].revents & ZMQ_POLLIN) {
                    if (who[k])
                        serve_monitor(g, who[k]);
                    else
                        serve_zap(g);
                }
        }
        /* after stop, drain what is queued, then leave */
        if (g->stop && (rc <= 0 || ++idle_after_stop > 1000))
            break;
    }
    for (int k = 0; k < g->nd; k++)
        if (g->d[k].failed_pending) {
            note_refusal(g, &g->d[k], "", "");
            g->d[k].failed_pending = 0;
        }
    return NULL;
}

enum mps_status guard_start(struct guard *g, FILE *log, struct mps_err *err)
{
    g->log = log;
    int e = pthread_create(&g->thread, NULL, guard_main, g);
    if (e)
        return mps_err_set(err, MPS_ELIB, "cannot start the guard thread: %s", strerror(e));
    g->running = 1;
    return MPS_OK;
}

void guard_stop(struct guard *g)
{
    if (!g || !g->running)
        return;
    g->stop = 1;
    pthread_join(g->thread, NULL);
    g->running = 0;
}

long guard_refused(const struct guard *g)
{
    long n = 0;
    for (int k = 0; g && k < g->nd; k++)
        n += g->d[k].refused;
    return n;
}

void guard_describe(const struct guard *g, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    if (!g || guard_refused(g) == 0)
        return;
    for (int k = 0; k < g->nd && used < len; k++)
        if (g->d[k].refused)
            used += (size_t)snprintf(buf + used, len - used, "%s%ld on %s", used ? ", " : "",
                                     g->d[k].refused, g->d[k].name);
    for (int k = 0; k < g->na && used < len; k++)
        used += (size_t)snprintf(buf + used, len - used, "%s%s (%ld)", k ? ", " : ", from ",
                                 g->a[k].ip, g->a[k].count);
    if (g->unnamed && used < len)
        snprintf(buf + used, len - used, "%s%ld whose address was not learnt",
                 g->na ? ", " : ", ", g->unnamed);
}

void guard_json(const struct guard *g, struct mps_json *j)
{
    mps_json_object(j, "refused_connections");
    mps_json_int(j, "count", guard_refused(g));
    mps_json_object(j, "by_endpoint");
    for (int k = 0; g && k < g->nd; k++)
        mps_json_int(j, g->d[k].name, g->d[k].refused);
    mps_json_close(j);
    mps_json_object(j, "by_address");
    for (int k = 0; g && k < g->na; k++)
        mps_json_int(j, g->a[k].ip, g->a[k].count);
    if (g && g->unnamed)
        mps_json_int(j, "unknown", g->unnamed);
    mps_json_close(j);
    mps_json_close(j);
}

void guard_destroy(struct guard **gp)
{
    if (!gp || !*gp)
        return;
    struct guard *g = *gp;
    guard_stop(g);
    for (int k = 0; k < g->nd; k++)
        if (g->d[k].mon)
            zmq_close(g->d[k].mon);
    if (g->zap)
        zmq_close(g->zap);
    pthread_mutex_destroy(&g->lock);
    free(g);
    *gp = NULL;
}
