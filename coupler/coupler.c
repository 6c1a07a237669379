/* coupler: the program users run, for every case.
 *   coupler CASE.yml --out DIR [--set key=value]... [--quiet]
 *           [--solid "COMMAND"] [--fluid "COMMAND"] [--external fluid|solid]
 * --out is required; --solid, --fluid and --external are refused for a
 * solver the case does not need. The run's record (coupler_record.h) goes
 * into OUT/case_resolved.yml, which the solvers read.
 * It validates the whole case, launches the solvers the scene needs, talks to
 * them over ZeroMQ (proto/PROTOCOL.md) and owns simulation time: each step
 * the fluid advances with the solid's interface as its moving boundary, and
 * the solid sub-cycles over the same interval under the fluid's loads
 * (paper 4.5, partitioned weak coupling). Exit: 0 done, 2 bad input,
 * 1 failure (a solver died, diverged or timed out), 130 interrupted. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zmq.h>

#include "coupler_keys.h"
#include "coupler_record.h"
#include "fluid_params.h"
#include "guard.h"
#include "launch.h"
#include "mps_case.h"
#include "mps_cli.h"
#include "mps_h5.h"
#include "mps_host.h"
#include "mps_json.h"
#include "mps_motion.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_prov.h"
#include "mps_timer.h"
#include "mps_version.h"
#include "proto_link.h"
#include "scene_check.h"
#include "solid_scene.h"

#define MAX_PROBES 64
#define SLICE_MS 200

enum { FLUID = 0, SOLID = 1, NPEERS = 2 };
_Static_assert((int)FLUID == (int)COUPLER_RECORD_FLUID &&
                   (int)SOLID == (int)COUPLER_RECORD_SOLID &&
                   (int)NPEERS == (int)COUPLER_RECORD_PEERS, "peer indices");

struct peer {
    const char *name;
    int needed, external, active;
    int engaged;               /* handshake started: its socket is listened to */
    char endpoint[512];
    char ipc_path[108];        /* a Unix socket path's limit (sun_path) */
    char key_path[300];        /* tcp: its CURVE key file in the run directory */
    void *sock;
    struct child child;
    double dt;                 /* latest stable step it reported */
    int nprobes;
    char probe_names[MAX_PROBES][64];
    double probes[MAX_PROBES];
    double roundtrip_seconds;  /* ADVANCE sent -> RESULT received */
    long exchanges;
    char *bye;                 /* its summary JSON */
    char model[64];            /* as its HELLO announced it */
};

/* the case's key tables: common, fluid, solid, coupler, motion */
#define NTABLES 5

struct coupler {
    struct mps_case *cs;
    struct mps_motion *motion; /* the tank's motion, checked before launching */
    const struct mps_key_spec *const *tables; /* the case's key tables (NTABLES) */
    struct coupler_record rec;
    const char *out;
    struct peer p[NPEERS];
    void *zctx;
    struct guard *guard;       /* tcp: ZAP handler, refused connections */
    struct proto_curve curve;  /* tcp: this run's server key pair */
    char rundir[256];
    char cpu_note[160];    /* what coupling.pin_cpus did, for the summary */
    int quiet;
    double hello_timeout, ready_timeout, step_timeout;
    /* the solid's interface, held between steps (owned decoded message) */
    struct proto_msg state;
    struct proto_msg loads;
    /* fluid force on the solid integrated since the last probe row (N s/m),
     * written as its mean over the interval: the load noise of single steps
     * averages out (columns solid_fx, solid_fy) */
    double impulse[MPS_DIM], impulse_time;
    struct mps_probes *probes;
    double time;
    long step;
    double wall0;
    char failed_peer[16];
};

static volatile int interrupted = 0;

static void on_signal(int sig)
{
    interrupted = sig;
}

/* ---- waiting, with an eye on both children and Ctrl-C ---- */

/* MPS_EPEER naming the first launched solver that has exited, and how, if
 * one has; MPS_OK otherwise. what: what the coupler was doing. */
static enum mps_status peer_gone(struct coupler *c, const char *what, struct mps_err *err)
{
    for (int q = 0; q < NPEERS; q++)
        if (c->p[q].active && launch_poll(&c->p[q].child)) {
            char how[256];
            launch_describe(&c->p[q].child, how, sizeof how);
            snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[q].name);
            c->p[q].active = 0;
            return mps_err_set(err, MPS_EPEER, "%s solver %s while the coupler %s",
                               c->p[q].name, how, what);
        }
    return MPS_OK;
}

/* Sends m to peer k. A PAIR socket only blocks a send while no peer is
 * connected, so the send waits for room in slices, as wait_msg does: a
 * solver that died while idle is then named at once instead of running
 * into the link's send timeout. */
static enum mps_status send_msg(struct coupler *c, int k, const struct proto_msg *m,
                                struct mps_err *err)
{
    char what[64];
    snprintf(what, sizeof what, "was sending %s", proto_type_name(m->type));
    double t0 = mps_wall_seconds();
    for (;;) {
        zmq_pollitem_t item = {c->p[k].sock, 0, ZMQ_POLLOUT, 0};
        int rc = zmq_poll(&item, 1, SLICE_MS);
        /* room, an error proto_link_send will report, or the link's own
         * deadline reached: its send then times out with its message */
        if (rc > 0 || (rc < 0 && zmq_errno() != EINTR) ||
            mps_wall_seconds() - t0 > 1e-3 * PROTO_SEND_TIMEOUT_MS)
            break;
        if (interrupted)
            return mps_err_set(err, MPS_EINTR, "interrupted by signal %d at t = %.6g s",
                               interrupted, c->time);
        enum mps_status st = peer_gone(c, what, err);
        if (st)
            return st;
    }
    return proto_link_send(c->p[k].sock, m, err);
}

/* Waits for a message from peer k within timeout_s. Meanwhile a message from
 * the other peer can only be an unasked ERROR, and a child that exits is
 * reported by name. */
static enum mps_status wait_msg(struct coupler *c, int k, struct proto_msg *m, double timeout_s,
                                const char *what, struct mps_err *err)
{
    double t0 = mps_wall_seconds();
    for (;;) {
        if (interrupted)
            return mps_err_set(err, MPS_EINTR, "interrupted by signal %d at t = %.6g s",
                               interrupted, c->time);
        void *socks[NPEERS];
        int idx[NPEERS], n = 0;
        /* a peer whose turn has not come keeps its HELLO queued */
        for (int q = 0; q < NPEERS; q++)
            if (c->p[q].active && (q == k || c->p[q].engaged)) {
                socks[n] = c->p[q].sock;
                idx[n++] = q;
            }
        int which = -1;
        enum mps_status st = proto_link_poll(socks, n, SLICE_MS, &which, err);
        if (st == MPS_OK) {
            int q = idx[which];
            st = proto_link_recv(c->p[q].sock, m, 0, err);
            if (st == MPS_EPROTO) {
                /* tell it why (a peer of another version reads REJECT too) */
                struct proto_msg r = proto_msg_make(PROTO_REJECT);
                char reason[sizeof err->msg];
                snprintf(reason, sizeof reason, "%s", err->msg);
                r.text = reason;
                struct mps_err ignored;
                proto_link_send(c->p[q].sock, &r, &ignored);
                snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[q].name);
                return mps_err_prefix(err, "%s solver refused: ", c->p[q].name);
            }
            if (st == MPS_ETIMEOUT || st == MPS_EINTR)
                continue;
            if (st)
                return st;
            if (m->type == PROTO_ERROR) {
                const char *msg = "";
                enum mps_status es = proto_error_status(m->text, &msg);
                snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[q].name);
                c->p[q].active = 0; /* it exits after ERROR */
                st = mps_err_set(err, es == MPS_EINPUT ? MPS_EINPUT : (es ? es : MPS_EPEER),
                                 "%s solver: %s: %s", c->p[q].name, mps_status_name(es), msg);
                proto_msg_clear(m);
                return st;
            }
            if (q != k) {
                snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[q].name);
                st = mps_err_set(err, MPS_EPROTO, "%s solver sent %s unasked", c->p[q].name,
                                 proto_type_name(m->type));
                proto_msg_clear(m);
                return st;
            }
            return MPS_OK;
        }
        if (st != MPS_ETIMEOUT && st != MPS_EINTR)
            return st;
        char doing[96];
        snprintf(doing, sizeof doing, "waited for %s", what);
        if ((st = peer_gone(c, doing, err)))
            return st;
        if (mps_wall_seconds() - t0 > timeout_s) {
            snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[k].name);
            return mps_err_set(err, MPS_ETIMEOUT,
                               "%s solver did not answer within %.0f s (waiting for %s at t = "
                               "%.6g s)",
                               c->p[k].name, timeout_s, what, c->time);
        }
    }
}

static enum mps_status expect(struct coupler *c, int k, struct proto_msg *m, enum proto_type type,
                              double timeout_s, struct mps_err *err)
{
    enum mps_status st = wait_msg(c, k, m, timeout_s, proto_type_name(type), err);
    if (st)
        return st;
    if (m->type != type) {
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", c->p[k].name);
        st = mps_err_set(err, MPS_EPROTO, "%s solver sent %s where %s was expected",
                         c->p[k].name, proto_type_name(m->type), proto_type_name(type));
        proto_msg_clear(m);
    }
    return st;
}

/* ---- startup ---- */

/* tcp: CURVE with keys made for this run (PROTOCOL.md section 10). The
 * solver's key file goes into the private run directory; the ZAP handler
 * accepts that solver's public key on its endpoint and nothing else. */
static enum mps_status open_tcp_endpoint(struct coupler *c, int k, struct mps_err *err)
{
    struct peer *p = &c->p[k];
    long port = mps_case_int(c->cs, "coupling.tcp_port") + k;
    const char *bind_host = mps_case_string(c->cs, "coupling.tcp_bind");
    char bind[320];
    snprintf(bind, sizeof bind, "tcp://%s:%ld", bind_host, port);
    snprintf(p->endpoint, sizeof p->endpoint, "tcp://%s:%ld",
             mps_case_string(c->cs, "coupling.tcp_host"), port);
    enum mps_status st;
    if (!c->guard) {
        if ((st = proto_key_pair(c->curve.server_public, c->curve.server_secret, err)) ||
            (st = guard_create(&c->guard, c->zctx, err)))
            return st;
    }
    struct proto_curve ck = c->curve;
    if ((st = proto_key_pair(ck.client_public, ck.client_secret, err)))
        return st;
    snprintf(p->key_path, sizeof p->key_path, "%s/%s.key", c->rundir, p->name);
    st = proto_key_write(p->key_path, &ck, err);
    if (st)
        p->key_path[0] = '\0';
    else
        st = guard_allow(c->guard, p->name, ck.client_public, err);
    memset(&ck, 0, sizeof ck); /* the coupler keeps only the public half */
    if (st)
        return st;
    if ((st = proto_link_open_secure(c->zctx, PROTO_LINK_BIND, bind, &c->curve, p->name,
                                     &p->sock, err)))
        return mps_err_prefix(err, "coupling.tcp_bind = %s, coupling.tcp_port = %ld: ",
                              bind_host, port - k);
    /* from here every connection refused on this socket is counted */
    return guard_watch(c->guard, p->sock, p->name, err);
}

static enum mps_status open_endpoint(struct coupler *c, int k, struct mps_err *err)
{
    struct peer *p = &c->p[k];
    if (strcmp(mps_case_string(c->cs, "coupling.transport"), "tcp") == 0)
        return open_tcp_endpoint(c, k, err);
    int len = snprintf(p->ipc_path, sizeof p->ipc_path, "%s/%s.sock", c->rundir, p->name);
    if (len < 0 || (size_t)len >= sizeof p->ipc_path)
        return mps_err_set(err, MPS_EIO, "coupler: socket path %s/%s.sock is longer than %zu bytes",
                           c->rundir, p->name, sizeof p->ipc_path - 1);
    /* copied, not printed: GCC 12 at -O0 cannot tell the two members apart
     * and warns of an overlap (-Wrestrict) */
    static const char scheme[] = "ipc://";
    _Static_assert(sizeof p->endpoint >= sizeof scheme + sizeof p->ipc_path, "endpoint size");
    memcpy(p->endpoint, scheme, sizeof scheme - 1);
    memcpy(p->endpoint + sizeof scheme - 1, p->ipc_path, (size_t)len + 1);
    return proto_link_open(c->zctx, PROTO_LINK_BIND, p->endpoint, &p->sock, err);
}

static enum mps_status handshake(struct coupler *c, int k, const char *resolved_case,
                                 struct mps_err *err)
{
    struct peer *p = &c->p[k];
    struct proto_msg m = {0};
    p->engaged = 1;
    if (p->external && !c->quiet && p->key_path[0])
        fprintf(stderr,
                "coupler: waiting for the %s solver: copy %s to its host (keep it private: "
                "mode 600) and run it with --connect %s --key FILE\n",
                p->name, p->key_path, p->endpoint);
    else if (p->external && !c->quiet)
        fprintf(stderr, "coupler: waiting for the %s solver: run it with --connect %s\n", p->name,
                p->endpoint);
    enum mps_status st = expect(c, k, &m, PROTO_HELLO,
                                p->external ? 10 * c->hello_timeout : c->hello_timeout, err);
    if (st)
        return st;
    char role[32];
    if (proto_text_get(m.text, ' ', "role", role, sizeof role) != 1 || strcmp(role, p->name)) {
        char reason[256];
        snprintf(reason, sizeof reason, "this endpoint is for the %s solver, not '%s'", p->name,
                 role);
        struct proto_msg r = proto_msg_make(PROTO_REJECT);
        r.text = reason;
        proto_link_send(p->sock, &r, err);
        proto_msg_clear(&m);
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EPROTO, "%s", reason);
    }
    char model[64] = "";
    proto_text_get(m.text, ' ', "model", model, sizeof model);
    snprintf(p->model, sizeof p->model, "%s", model);
    proto_msg_clear(&m);
    /* the file this solver is about to read records its own run */
    enum mps_status rst = coupler_record_hello(
        &c->rec, &c->cs, c->tables, NTABLES, k,
        p->external ? "(external: started by the user)" : p->child.command, p->model, err);
    if (rst)
        return rst;
    char cfg[8192];
    snprintf(cfg, sizeof cfg, "case=%s\nout=%s\nprefix=%s\ntimeout_ms=%.0f\n", resolved_case,
             c->out, p->name, 1000.0 * (2.0 * c->step_timeout + 60.0));
    /* PROTOCOL.md 4: a solver that cannot apply the tank's motion refuses the
     * key instead of running a fixed tank */
    if (mps_motion_moving(c->motion))
        snprintf(cfg + strlen(cfg), sizeof cfg - strlen(cfg), "motion=%s\n",
                 mps_motion_kind_name(c->motion->kind));
    struct proto_msg conf = proto_msg_make(PROTO_CONFIG);
    conf.text = cfg;
    return proto_link_send(p->sock, &conf, err);
}

static enum mps_status await_ready(struct coupler *c, int k, struct mps_err *err)
{
    struct peer *p = &c->p[k];
    struct proto_msg m = {0};
    enum mps_status st = expect(c, k, &m, PROTO_READY, c->ready_timeout, err);
    if (st)
        return st;
    p->dt = m.dt;
    p->nprobes = m.nprobes;
    if (p->nprobes > MAX_PROBES) {
        proto_msg_clear(&m);
        return mps_err_set(err, MPS_EPROTO, "%s solver has %d probes: at most %d", p->name,
                           p->nprobes, MAX_PROBES);
    }
    const char *s = m.text ? m.text : "";
    for (int q = 0; q < p->nprobes; q++) {
        size_t len = strcspn(s, ",");
        snprintf(p->probe_names[q], sizeof p->probe_names[q], "%.*s", (int)len, s);
        s += len + (s[len] == ',');
    }
    if (k == SOLID) {
        if (m.payload != PROTO_STATE) {
            proto_msg_clear(&m);
            return mps_err_set(err, MPS_EPROTO, "solid READY carries no STATE");
        }
        c->state = m; /* keep: it is the fluid's first boundary */
        return MPS_OK;
    }
    proto_msg_clear(&m);
    return MPS_OK;
}

/* ---- the time loop ---- */

static enum mps_status exchange(struct coupler *c, int k, struct proto_msg *adv,
                                struct proto_msg *res, struct mps_err *err)
{
    struct peer *p = &c->p[k];
    double t0 = mps_wall_seconds();
    enum mps_status st = send_msg(c, k, adv, err);
    if (st == MPS_EPEER || st == MPS_EINTR)
        return st;
    if (st)
        return mps_err_prefix(err, "sending ADVANCE to the %s solver: ", p->name);
    if ((st = expect(c, k, res, PROTO_RESULT, c->step_timeout, err)))
        return st;
    p->roundtrip_seconds += mps_wall_seconds() - t0;
    p->exchanges++;
    if (res->step != adv->step || res->time != adv->time + adv->dt) {
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EPROTO,
                           "%s RESULT is for step %lld at t = %.17g, expected step %lld at %.17g",
                           p->name, (long long)res->step, res->time, (long long)adv->step,
                           adv->time + adv->dt);
    }
    if (!(res->dt > 0.0)) {
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EPROTO, "%s reported a stable step of %g s", p->name,
                           res->dt);
    }
    p->dt = res->dt;
    if (adv->flags & PROTO_F_PROBES)
        for (int q = 0; q < p->nprobes && q < res->nprobes; q++)
            p->probes[q] = res->probes[q];
    return MPS_OK;
}

static enum mps_status write_probe_row(struct coupler *c, struct mps_err *err)
{
    double v[2 * MAX_PROBES + MPS_DIM];
    int n = 0;
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].needed)
            for (int q = 0; q < c->p[k].nprobes; q++)
                v[n++] = c->p[k].probes[q];
    if (c->p[FLUID].needed && c->p[SOLID].needed) {
        for (int a = 0; a < MPS_DIM; a++) {
            v[n++] = c->impulse_time > 0.0 ? c->impulse[a] / c->impulse_time : 0.0;
            c->impulse[a] = 0.0;
        }
        c->impulse_time = 0.0;
    }
    return mps_probes_write(c->probes, c->time, v, err);
}

static enum mps_status open_probes(struct coupler *c, struct mps_err *err)
{
    const char *names[2 * MAX_PROBES + MPS_DIM];
    int n = 0;
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].needed)
            for (int q = 0; q < c->p[k].nprobes; q++)
                names[n++] = c->p[k].probe_names[q];
    if (c->p[FLUID].needed && c->p[SOLID].needed) {
        names[n++] = "solid_fx";
        names[n++] = "solid_fy";
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/probes.csv", c->out);
    char *comment = mps_prov_comment(c->cs, "coupler");
    enum mps_status st = mps_probes_open(&c->probes, path, comment, names, n, err);
    free(comment);
    return st;
}

/* The next coupling step: the fluid's CFL step (or, for a solid alone, the
 * probe interval, over which the solid sub-cycles), shortened so t_next is
 * hit exactly with no sliver left before it. With a fluid, t_next is the
 * end of the run only: output and probe times are written at the end of the
 * first step that reaches them, so they never change the solution
 * (docs/pressure.md). */
static double next_dt(const struct coupler *c, double t_next, double probe_interval)
{
    double dt = c->p[FLUID].needed ? c->p[FLUID].dt : probe_interval;
    double left = t_next - c->time;
    if (left <= dt * (1.0 + 1e-9))
        return left;
    if (left < 2.0 * dt)
        return 0.5 * left;
    return dt;
}

static enum mps_status run_loop(struct coupler *c, struct mps_err *err)
{
    const double end = mps_case_double(c->cs, "end_time");
    const double out_iv = mps_case_double(c->cs, "output.interval");
    const double probe_iv = mps_case_double(c->cs, "output.probe_interval");
    const double eps = 1e-9 * end;
    struct mps_progress prog;
    mps_progress_init(&prog, "coupled", end, c->quiet);
    long out_k = 1, probe_k = 1;
    enum mps_status st;
    /* probe values travel with RESULTs, so the first row is at the first
     * probe time, not at t = 0 */
    while (c->time < end - eps) {
        double t_out = out_iv > 0.0 ? out_k * out_iv : INFINITY;
        double t_probe = probe_k * probe_iv;
        double t_next = end;
        if (!c->p[FLUID].needed) /* a lone solid steps from report to report */
            t_next = fmin(fmin(t_out, end), t_probe);
        double dt = next_dt(c, t_next, probe_iv);
        uint32_t flags = 0;
        if (c->time + dt >= t_out - eps)
            flags |= PROTO_F_SNAPSHOT;
        if (c->time + dt >= t_probe - eps || c->time + dt >= end - eps)
            flags |= PROTO_F_PROBES;

        struct proto_msg adv = proto_msg_make(PROTO_ADVANCE), res = {0};
        adv.step = c->step;
        adv.time = c->time;
        adv.dt = dt;
        adv.n_sub = 1;
        adv.flags = flags;
        if (c->p[FLUID].needed) {
            if (c->p[SOLID].needed) {
                adv.payload = PROTO_STATE;
                adv.count = c->state.count;
                adv.id = c->state.id;
                adv.x = c->state.x;
                adv.v = c->state.v;
                adv.surface = c->state.surface;
                adv.fixed = c->state.fixed;
            }
            if ((st = exchange(c, FLUID, &adv, &res, err)))
                return st;
            proto_msg_clear(&c->loads);
            c->loads = res; /* the solid's load for this interval */
            res = (struct proto_msg){0};
            for (size_t q = 0; q < c->loads.count; q++)
                for (int a = 0; a < MPS_DIM; a++)
                    c->impulse[a] += dt * c->loads.force[q][a];
            c->impulse_time += dt;
        }
        if (c->p[SOLID].needed) {
            struct proto_msg sadv = adv;
            sadv.payload = c->p[FLUID].needed ? PROTO_LOADS : PROTO_NONE;
            sadv.count = c->p[FLUID].needed ? c->loads.count : 0;
            sadv.id = c->loads.id;
            sadv.pressure = c->loads.pressure;
            sadv.force = c->loads.force;
            sadv.x = sadv.v = NULL;
            sadv.surface = sadv.fixed = NULL;
            /* Sub-cycles from the solid's own stable step (paper 4.6). */
            double n = ceil(dt / c->p[SOLID].dt * (1.0 - 1e-12));
            sadv.n_sub = n < 1.0 ? 1 : (int)n;
            if ((st = exchange(c, SOLID, &sadv, &res, err)))
                return st;
            proto_msg_clear(&c->state);
            c->state = res;
        }
        c->time = adv.time + adv.dt;
        c->step++;
        if (flags & PROTO_F_PROBES) {
            if ((st = write_probe_row(c, err)))
                return st;
            while (probe_k * probe_iv <= c->time + eps)
                probe_k++;
        }
        if (flags & PROTO_F_SNAPSHOT)
            while (out_k * out_iv <= c->time + eps)
                out_k++;
        mps_progress_update(&prog, c->time, c->step);
    }
    mps_progress_finish(&prog, c->time, c->step);
    return MPS_OK;
}

/* ---- shutdown ---- */

static enum mps_status stop_all(struct coupler *c, struct mps_err *err)
{
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c->p[k];
        if (!p->active)
            continue;
        struct proto_msg s = proto_msg_make(PROTO_STOP), m = {0};
        s.step = c->step;
        s.time = c->time;
        enum mps_status st = send_msg(c, k, &s, err);
        if (!st)
            st = expect(c, k, &m, PROTO_BYE, 60.0, err);
        if (st)
            return st;
        p->bye = m.text ? strdup(m.text) : NULL;
        proto_msg_clear(&m);
        p->active = 0;
    }
    return MPS_OK;
}

static void abort_all(struct coupler *c, const char *reason)
{
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c->p[k];
        if (p->sock && p->active && !launch_poll(&p->child)) {
            int ms = 100; /* the peer may be gone: do not wait on it */
            zmq_setsockopt(p->sock, ZMQ_SNDTIMEO, &ms, sizeof ms);
            struct proto_msg a = proto_msg_make(PROTO_ABORT);
            a.step = c->step;
            a.time = c->time;
            a.text = reason;
            struct mps_err ignored;
            proto_link_send(p->sock, &a, &ignored);
        }
        p->active = 0;
    }
    for (int k = 0; k < NPEERS; k++)
        launch_reap(&c->p[k].child, 5.0);
}

/* The number after "key": in a solver's summary JSON (its BYE), or def. */
static double bye_number(const struct peer *p, const char *key, double def)
{
    char quoted[96];
    snprintf(quoted, sizeof quoted, "\"%s\"", key);
    const char *s = p->bye ? strstr(p->bye, quoted) : NULL;
    if (s && (s = strchr(s + strlen(quoted), ':')))
        return strtod(s + 1, NULL);
    return def;
}

static void write_summary(struct coupler *c, enum mps_status st, const struct mps_err *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/summary.json", c->out);
    FILE *fp = fopen(path, "w");
    if (!fp) {
        fprintf(stderr, "coupler: warning: cannot write %s\n", path);
        return;
    }
    double wall = mps_wall_seconds() - c->wall0;
    struct mps_json j;
    mps_json_begin(&j, fp);
    mps_json_str(&j, "program", "coupler");
    mps_json_str(&j, "version", MPS_VERSION);
    mps_json_str(&j, "git_rev", mps_git_rev);
    char host[256];
    mps_host_describe(host, sizeof host);
    mps_json_str(&j, "host", host);   /* the timings below are this machine's */
    mps_json_str(&j, "case", c->cs ? mps_case_path(c->cs) : "");
    if (c->cs) {
        mps_prov_json(c->cs, &j);
        mps_json_num(&j, "end_time", mps_case_double(c->cs, "end_time"));
    }
    mps_json_str(&j, "status", mps_status_name(st));
    mps_json_str(&j, "message", st ? err->msg : "");
    mps_json_str(&j, "failed_solver", c->failed_peer);
    mps_json_num(&j, "simulated_time", c->time);
    mps_json_int(&j, "coupling_steps", c->step);
    mps_json_num(&j, "wall_seconds", wall);
    /* The split: each solver's compute time is what it measured inside its
     * step; messaging is the rest of the round trips (encode, copy, wake-up). */
    double msg = 0.0, solvers = 0.0;
    mps_json_object(&j, "time_split_seconds");
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c->p[k];
        if (!p->needed)
            continue;
        double compute = bye_number(p, "compute_seconds", 0.0);
        mps_json_num(&j, p->name, compute);
        solvers += compute;
        msg += p->roundtrip_seconds - compute;
    }
    mps_json_num(&j, "messaging", msg);
    mps_json_num(&j, "coupler_other", wall - solvers - msg);
    mps_json_close(&j);
    mps_json_num(&j, "messaging_fraction", wall > 0.0 ? msg / wall : 0.0);
    if (c->p[FLUID].bye) /* from the fluid's summary, as on the terminal */
        mps_json_int(&j, "lost_particles",
                     (long long)bye_number(&c->p[FLUID], "lost_particles", 0.0));
    mps_json_str(&j, "cpu_placement", c->cpu_note);
    if (c->motion) {
        mps_json_object(&j, "motion");
        mps_motion_summary(c->motion, &j);
        mps_json_close(&j);
    }
    mps_json_str(&j, "transport", c->guard ? "tcp+curve" : "ipc");
    guard_json(c->guard, &j); /* strangers turned away below the protocol */
    mps_json_object(&j, "solvers");
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c->p[k];
        if (!p->needed)
            continue;
        mps_json_object(&j, p->name);
        mps_json_str(&j, "command", p->child.command);
        mps_json_str(&j, "model", p->model); /* as its HELLO announced it */
        mps_json_str(&j, "endpoint", p->endpoint);
        mps_json_int(&j, "pid", (long long)p->child.pid);
        mps_json_int(&j, "exchanges", p->exchanges);
        mps_json_num(&j, "roundtrip_seconds", p->roundtrip_seconds);
        mps_json_close(&j);
    }
    mps_json_close(&j);
    mps_json_end(&j);
    fclose(fp);
    /* the solvers' own summaries, verbatim */
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].bye) {
            snprintf(path, sizeof path, "%s/%s_summary.json", c->out, c->p[k].name);
            FILE *f = fopen(path, "w");
            if (f) {
                fputs(c->p[k].bye, f);
                fputc('\n', f);
                fclose(f);
            }
        }
}

static void write_scene(struct coupler *c)
{
    const char *names[NPEERS];
    int n = 0;
    for (int k = 0; k < NPEERS; k++) {
        char path[4200];
        snprintf(path, sizeof path, "%s/%s.xmf", c->out, c->p[k].name);
        if (c->p[k].needed && access(path, R_OK) == 0)
            names[n++] = c->p[k].name; /* a solver that never started has none */
    }
    if (n == 0)
        return;
    struct mps_err e;
    if (mps_h5_write_scene_xdmf(c->out, "scene", names, n, &e))
        fprintf(stderr, "coupler: warning: scene.xmf not written: %s\n", e.msg);
}

static void cleanup(struct coupler *c)
{
    guard_destroy(&c->guard);
    memset(&c->curve, 0, sizeof c->curve);
    for (int k = 0; k < NPEERS; k++) {
        proto_link_close(&c->p[k].sock);
        if (c->p[k].ipc_path[0])
            unlink(c->p[k].ipc_path);
        if (c->p[k].key_path[0])
            unlink(c->p[k].key_path);
        free(c->p[k].bye);
    }
    if (c->zctx)
        zmq_ctx_term(c->zctx);
    if (c->rundir[0])
        rmdir(c->rundir);
    proto_msg_clear(&c->state);
    proto_msg_clear(&c->loads);
    mps_probes_close(&c->probes);
    mps_motion_destroy(&c->motion);
    mps_case_destroy(&c->cs);
}

/* Refuses an option that names a solver the case does not need: it would
 * otherwise be ignored without a word (exit 2). */
static int refuse_unneeded(const struct coupler *c, const char *option, const char *value,
                           int peer, const char *case_path)
{
    if (!value || c->p[peer].needed)
        return 0;
    fprintf(stderr, "coupler: %s %s: %s has no %s (%s), so no %s program runs; drop the option "
                    "or choose a case with a %s\n",
            option, value, case_path, c->p[peer].name,
            peer == FLUID ? "fluid.tank" : "solid.bodies", c->p[peer].name, c->p[peer].name);
    return 1;
}

int main(int argc, char **argv)
{
    mps_prov_init(argc, argv);
    struct mps_err err = {0};
    struct mps_cli cli;
    struct mps_cli_extra extra[] = {
        {"--solid", 1, "solid program command (sets the case key solid_solver; refused "
                       "for a case without a solid)", NULL},
        {"--fluid", 1, "fluid program command (sets the case key fluid_solver; refused "
                       "for a case without a fluid)", NULL},
        {"--external", 1, "fluid|solid: do not launch it; wait for it to connect", NULL},
    };
    const char *usage =
        "usage: coupler CASE.yml --out DIR [--set key=value]... [--quiet]\n"
        "               [--solid \"COMMAND\"] [--fluid \"COMMAND\"] [--external fluid|solid]";
    enum mps_status st = mps_cli_parse(&cli, argc, argv, extra, 3, usage, &err);
    if (st == MPS_EINTR)
        return 0;
    if (st) {
        fprintf(stderr, "coupler: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    signal(SIGPIPE, SIG_IGN);
    struct sigaction sa = {0};
    sa.sa_handler = on_signal; /* no SA_RESTART: waits return on Ctrl-C */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    if (!cli.out_dir) {
        /* no silent ./out: a second run there would mix with the first */
        fprintf(stderr, "coupler: missing --out DIR (see --help)\n");
        return 2;
    }
    struct coupler c = {0};
    c.out = cli.out_dir;
    c.quiet = cli.quiet;
    c.wall0 = mps_wall_seconds();
    c.p[FLUID].name = "fluid";
    c.p[SOLID].name = "solid";
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, fluid_case_keys,
                                                 solid_case_keys, coupler_case_keys,
                                                 mps_motion_keys};
    c.tables = tables;
    coupler_record_init(&c.rec, &cli, extra[0].value, extra[1].value);
    st = mps_case_load(&c.cs, cli.case_path, c.rec.sets, c.rec.nsets, tables, NTABLES, NULL,
                       &err);
    if (st) {
        fprintf(stderr, "coupler: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    c.hello_timeout = mps_case_double(c.cs, "coupling.hello_timeout");
    c.ready_timeout = mps_case_double(c.cs, "coupling.ready_timeout");
    c.step_timeout = mps_case_double(c.cs, "coupling.step_timeout");
    /* Model only what the scene needs: launch a solver only if the case has
     * its part. */
    c.p[FLUID].needed = mps_case_has(c.cs, "fluid.tank.width");
    c.p[SOLID].needed = mps_case_count(c.cs, "solid.bodies") > 0;
    const char *ext = extra[2].value;
    if (ext && strcmp(ext, "fluid") && strcmp(ext, "solid")) {
        fprintf(stderr, "coupler: --external %s: must be fluid or solid\n", ext);
        mps_case_destroy(&c.cs);
        return 2;
    }
    if (!c.p[FLUID].needed && !c.p[SOLID].needed) {
        fprintf(stderr, "coupler: %s: the case has neither a fluid (fluid.tank) nor a solid "
                        "(solid.bodies)\n", cli.case_path);
        mps_case_destroy(&c.cs);
        return 2;
    }
    if (refuse_unneeded(&c, "--solid", extra[0].value, SOLID, cli.case_path) ||
        refuse_unneeded(&c, "--fluid", extra[1].value, FLUID, cli.case_path) ||
        refuse_unneeded(&c, "--external", ext, ext && !strcmp(ext, "solid") ? SOLID : FLUID,
                        cli.case_path)) {
        mps_case_destroy(&c.cs);
        return 2;
    }

    /* The solvers' cross-key checks (a block outside the tank, an empty clamp,
     * ...) run here too, so an error names the user's file or --set, not the
     * resolved copy, and nothing is launched for a case that cannot run. */
    {
        struct fluid_params fp;
        struct solid_scene *sc = c.p[SOLID].needed ? malloc(sizeof *sc) : NULL;
        if (c.p[SOLID].needed && !sc)
            st = mps_err_set(&err, MPS_ENOMEM, "coupler: out of memory");
        else if (c.p[FLUID].needed)
            st = fluid_params_read(&fp, c.cs, &err);
        if (!st && sc)
            st = solid_scene_read(sc, c.cs, &err);
        if (!st && sc && c.p[FLUID].needed)
            st = scene_check_fsi(&fp, sc, c.cs, &err);
        if (!st)
            st = mps_motion_read(&c.motion, c.cs, &err);
        free(sc);
        if (st) {
            fprintf(stderr, "coupler: %s\n", err.msg);
            mps_motion_destroy(&c.motion);
            mps_case_destroy(&c.cs);
            return mps_status_exit_code(st);
        }
    }

    const char *resolved = c.rec.path;
    if ((st = mps_mkdir_p(c.out, &err)))
        goto end;
    {
        char abs_out[4096];
        if (!mps_realpath(c.out, abs_out, sizeof abs_out)) {
            st = mps_err_set(&err, MPS_EIO, "%s: %s", c.out, strerror(errno));
            goto end;
        }
        snprintf(c.rec.path, sizeof c.rec.path, "%s/case_resolved.yml", abs_out);
    }
    /* written now, so a run that fails to start leaves it too; rewritten as
     * each solver says hello (coupler_record_hello) */
    if ((st = coupler_record_write(&c.rec, c.cs, &err)))
        goto end;
    snprintf(c.rundir, sizeof c.rundir, "/tmp/mpsfsi-XXXXXX");
    if (!mkdtemp(c.rundir)) {
        c.rundir[0] = '\0';
        st = mps_err_set(&err, MPS_EIO, "cannot create a run directory in /tmp: %s",
                         strerror(errno));
        goto end;
    }
    /* before the first socket: ZeroMQ's I/O threads inherit the placement */
    launch_share_cpu(strcmp(mps_case_string(c.cs, "coupling.pin_cpus"), "auto") == 0,
                     c.cpu_note, sizeof c.cpu_note);
    c.zctx = zmq_ctx_new();
    if (!c.zctx) {
        st = mps_err_set(&err, MPS_ELIB, "zmq_ctx_new: %s", zmq_strerror(zmq_errno()));
        goto end;
    }
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c.p[k];
        if (!p->needed)
            continue;
        p->external = ext && strcmp(ext, p->name) == 0;
        if ((st = open_endpoint(&c, k, &err)))
            goto end;
        p->active = 1; /* listened to from now on */
    }
    /* every socket holds its copy of the server's secret key now */
    memset(c.curve.server_secret, 0, sizeof c.curve.server_secret);
    /* the ZAP handler answers before any solver is launched */
    if (c.guard && (st = guard_start(c.guard, stderr, &err)))
        goto end;
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c.p[k];
        if (!p->needed)
            continue;
        /* --solid/--fluid are already in the case (coupler_record_init) */
        const char *cmd = mps_case_string(c.cs, k == FLUID ? "fluid_solver" : "solid_solver");
        snprintf(p->child.command, sizeof p->child.command, "%s", cmd);
        if (!p->external && (st = launch_start(&p->child, p->name, cmd, p->endpoint,
                                               p->key_path[0] ? p->key_path : NULL, &err)))
            goto end;
        p->child.name = p->name;
    }
    /* one solver at a time, so the only message that can come unasked is an
     * ERROR; the solid first, so the model its HELLO names is in the case
     * file before the fluid reads it (coupler_record_hello) */
    for (int q = NPEERS - 1; q >= 0; q--)
        if (c.p[q].needed &&
            ((st = handshake(&c, q, resolved, &err)) || (st = await_ready(&c, q, &err))))
            goto end;
    if ((st = open_probes(&c, &err)))
        goto end;
    if (!c.quiet)
        fprintf(stderr, "coupler: %s%s%s, output in %s\n", c.p[FLUID].needed ? "fluid" : "",
                c.p[FLUID].needed && c.p[SOLID].needed ? " + " : "",
                c.p[SOLID].needed ? "solid" : "", c.out);
    if ((st = run_loop(&c, &err)))
        goto end;
    st = stop_all(&c, &err);
end:
    if (st) {
        fprintf(stderr, "\ncoupler: %s: %s\n", mps_status_name(st), err.msg);
        abort_all(&c, err.msg);
    } else {
        for (int k = 0; k < NPEERS; k++)
            launch_reap(&c.p[k].child, 10.0);
    }
    if (c.guard) {
        guard_stop(c.guard);
        char who[512];
        guard_describe(c.guard, who, sizeof who);
        if (who[0])
            fprintf(stderr, "coupler: refused %ld unauthenticated connection%s: %s\n",
                    guard_refused(c.guard), guard_refused(c.guard) == 1 ? "" : "s", who);
    }
    if (c.cs && c.out) {
        write_summary(&c, st, &err);
        write_scene(&c);
        long lost = (long)bye_number(&c.p[FLUID], "lost_particles", 0);
        if (lost > 0) /* a result, not progress: --quiet keeps it */
            fprintf(stderr, "coupler: %ld fluid particle%s left over the open tank walls "
                            "(removed; lost_particles in summary.json)\n",
                    lost, lost == 1 ? "" : "s");
    }
    cleanup(&c);
    return mps_status_exit_code(st);
}
