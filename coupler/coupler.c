/* coupler: the program users run, for every case.
 *   coupler CASE.yml --out DIR [--set key=value]... [--quiet]
 *           [--solid "COMMAND"] [--fluid "COMMAND"] [--external fluid|solid]
 * --out is required; --solid, --fluid and --external are refused for a
 * solver the case does not need. The run's record (coupler_record.h) goes
 * into OUT/case_resolved.yml, which the solvers read.
 * It validates its own and the common keys and the scene's layout (each solver
 * validates its own keys when it gets CONFIG and answers a case error, which
 * the coupler prints as its own: PROTOCOL.md 8), launches the solvers the
 * scene needs, talks to
 * them over ZeroMQ (proto/PROTOCOL.md) and owns simulation time: each step
 * the fluid advances with the solid's interface as its moving boundary, and
 * the solid sub-cycles over the same interval under the fluid's loads
 * (paper 4.5, partitioned weak coupling; with coupling.scheme: implicit the
 * step is repeated from its start until the interface converges,
 * coupling_iter.h). Exit: 0 done, 2 bad input, 1 failure (a solver died,
 * diverged or timed out), 130 interrupted. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zmq.h>

#include "coupler_keys.h"
#include "coupler_record.h"
#include "coupling_accel.h"
#include "coupling_iter.h"
#include "guard.h"
#include "launch.h"
#include "mps_case.h"
#include "mps_cli.h"
#include "mps_h5.h"
#include "mps_host.h"
#include "mps_json.h"
#include "mps_json_read.h"
#include "mps_motion.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_prov.h"
#include "mps_restart.h"
#include "mps_timer.h"
#include "mps_utf8.h"
#include "mps_version.h"
#include "proto_link.h"
#include "scene_check.h"

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
    double repeat_seconds;     /* the part of it in repeated iterations (implicit) */
    long exchanges;
    int can_rollback;          /* HELLO declared caps=rollback */
    int can_checkpoint;        /* HELLO declared caps=checkpoint */
    char *bye;                 /* its summary JSON */
    char model[64];            /* as its HELLO announced it */
};

struct coupler {
    struct mps_case *cs;
    struct mps_motion *motion; /* the tank's motion, checked before launching */
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
    int case_error;            /* a case error ended the run: a solver's (PROTOCOL.md 8),
                                * or a solid step the case makes impossible */
    /* implicit coupling (coupling.scheme: implicit) */
    int implicit;
    struct coupling_iter iter;
    struct coupling_accel *accel;
    int max_iter, on_max_error;
    int predict_solid;         /* coupling.implicit.predictor: solid */
    long predictions;          /* the solid's solves alone, as predictors */
    long iterations;           /* fluid and solid solve pairs, all steps */
    int iter_max;              /* most in one step */
    long limit_hits;           /* steps accepted at max_iterations */
    long iter_hist[8];         /* steps that took 1, 2, 3-4, 5-8, 9-16, 17-32, 33-64, more */
    double accel_seconds;      /* in the coupler's own vector work */
    double change_max;         /* largest converged rms change / step's displacement */
    long iter_probe_sum, iter_probe_steps; /* for the probe column */
    FILE *iter_log;            /* coupling.implicit.log: OUT/iterations.csv */
    /* checkpoints (docs/restart.md): every solver writes its own, with the
     * same number, in the ADVANCE asking for it; the coupler writes its
     * part after their RESULTs, so a coupler checkpoint N implies theirs */
    double ck_interval;        /* 0: none */
    int ck_asked;              /* the user's case or --set gives the interval */
    const char *ck_note;       /* why checkpoints are off although the default asks */
    struct mps_ckpt disk;
    struct mps_run_mark mark;
    char *case_yaml;           /* the resolved case the checkpoints carry */
    long restart;              /* --restart: the checkpoint number continued, else 0 */
    char restart_path[4400];
    double restart_time;
    double stop_at;            /* --stop-at */
    double stopped_at;         /* -1: not stopped */
    long checkpoints;
    double t_checkpoint;
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
                /* one of its keys: said as the coupler says its own */
                if ((c->case_error = proto_case_error(m->text, &msg)))
                    st = mps_err_set(err, MPS_EINPUT, "%s", msg);
                else
                    st = mps_err_set(err, es == MPS_EINPUT ? MPS_EINPUT : (es ? es : MPS_EPEER),
                                     "%s solver: %s: %s", c->p[q].name, mps_status_name(es),
                                     msg);
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
    /* PROTOCOL.md 4: caps=a,b,... (absent: none) */
    char caps[256];
    p->can_rollback = p->can_checkpoint = 0;
    if (proto_text_get(m.text, ' ', "caps", caps, sizeof caps) == 1)
        for (char *tok = strtok(caps, ","); tok; tok = strtok(NULL, ",")) {
            p->can_rollback |= strcmp(tok, "rollback") == 0;
            p->can_checkpoint |= strcmp(tok, "checkpoint") == 0;
        }
    char model[64] = "", sets[256] = "";
    proto_text_get(m.text, ' ', "model", model, sizeof model);
    snprintf(p->model, sizeof p->model, "%s", model);
    if (proto_text_get(m.text, ' ', "sets", sets, sizeof sets) < 0)
        sets[0] = '\0'; /* too long for any key we would record: ignored */
    proto_msg_clear(&m);
    if (c->implicit && !p->can_rollback) {
        char reason[512];
        snprintf(reason, sizeof reason,
                 "coupling.scheme is implicit, which repeats steps, and this %s solver cannot "
                 "(its HELLO declares no caps=rollback): run it with coupling.scheme: explicit "
                 "(PROTOCOL.md 4, 6)",
                 p->name);
        struct proto_msg r = proto_msg_make(PROTO_REJECT);
        r.text = reason;
        proto_link_send(p->sock, &r, err);
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EINPUT, "%s", reason);
    }
    /* PROTOCOL.md 4, 6: a restart or checkpoints the case asks for need the
     * solver to write and read its state; the default interval is dropped
     * with a note instead (a solver without the capability still runs) */
    if (!p->can_checkpoint && (c->restart || (c->ck_interval > 0.0 && c->ck_asked))) {
        char reason[512];
        snprintf(reason, sizeof reason,
                 "%s, and this %s solver cannot checkpoint (its HELLO declares no "
                 "caps=checkpoint): %s (PROTOCOL.md 4, 6)",
                 c->restart ? "the run restarts from a checkpoint"
                            : "the case asks for checkpoints (output.checkpoint_interval)",
                 p->name,
                 c->restart ? "it cannot restart this run" : "set output.checkpoint_interval: 0");
        struct proto_msg r = proto_msg_make(PROTO_REJECT);
        r.text = reason;
        proto_link_send(p->sock, &r, err);
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EINPUT, "%s", reason);
    }
    if (!p->can_checkpoint && c->ck_interval > 0.0) {
        c->ck_interval = 0.0;
        c->ck_note = p->name[0] == 'f' ? "off: the fluid solver cannot checkpoint"
                                       : "off: the solid solver cannot checkpoint";
        if (!c->quiet)
            fprintf(stderr, "coupler: note: no checkpoints: the %s solver (%s) declares no "
                            "caps=checkpoint\n", p->name, model);
    }
    /* the file this solver is about to read records its own run */
    enum mps_status rst = coupler_record_hello(
        &c->rec, &c->cs, k, p->external ? "(external: started by the user)" : p->child.command,
        p->model, sets, err);
    if (rst)
        return rst;
    char cfg[8192];
    snprintf(cfg, sizeof cfg, "case=%s\nout=%s\nprefix=%s\ntimeout_ms=%.0f\n%s", resolved_case,
             c->out, p->name, 1000.0 * (2.0 * c->step_timeout + 60.0),
             c->implicit ? "rollback=on\n" : "");
    if (c->restart) /* PROTOCOL.md 4: start from checkpoint N */
        snprintf(cfg + strlen(cfg), sizeof cfg - strlen(cfg), "restart=%ld\n", c->restart);
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
        if (c->implicit)
            return coupling_iter_init(&c->iter, &m,
                                      mps_case_double(c->cs, "coupling.implicit.tolerance"),
                                      mps_case_double(c->cs, "coupling.implicit.abs_tolerance"),
                                      err);
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
    if (adv->iteration > 0)
        p->repeat_seconds += mps_wall_seconds() - t0;
    p->exchanges++;
    if (res->step != adv->step || res->iteration != adv->iteration ||
        res->time != adv->time + adv->dt) {
        snprintf(c->failed_peer, sizeof c->failed_peer, "%s", p->name);
        return mps_err_set(err, MPS_EPROTO,
                           "%s RESULT is for step %lld iteration %d at t = %.17g, expected step "
                           "%lld iteration %d at %.17g",
                           p->name, (long long)res->step, res->iteration, res->time,
                           (long long)adv->step, adv->iteration, adv->time + adv->dt);
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
    double v[2 * MAX_PROBES + MPS_DIM + 1];
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
    if (c->implicit) { /* mean iterations per step since the last row */
        v[n++] = c->iter_probe_steps ? (double)c->iter_probe_sum / c->iter_probe_steps : 0.0;
        c->iter_probe_sum = c->iter_probe_steps = 0;
    }
    return mps_probes_write(c->probes, c->time, v, err);
}

static enum mps_status open_probes(struct coupler *c, struct mps_err *err)
{
    const char *names[2 * MAX_PROBES + MPS_DIM + 1];
    int n = 0;
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].needed)
            for (int q = 0; q < c->p[k].nprobes; q++)
                names[n++] = c->p[k].probe_names[q];
    if (c->p[FLUID].needed && c->p[SOLID].needed) {
        names[n++] = "solid_fx";
        names[n++] = "solid_fy";
    }
    if (c->implicit)
        names[n++] = "coupling_iterations";
    enum mps_status st = mps_probes_check_names(names, n, c->cs ? mps_case_path(c->cs) : NULL, err);
    if (st)
        return st;
    char path[4200];
    snprintf(path, sizeof path, "%s/probes.csv", c->out);
    if (c->restart)
        return mps_probes_resume(&c->probes, path, c->mark.table_bytes[0], n, err);
    char *comment = mps_prov_comment(c->cs, "coupler");
    st = mps_probes_open(&c->probes, path, comment, names, n, err);
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

/* The solid's sub-cycles for a coupling step of dt at its own stable step
 * (paper 4.6; the step READY reported).
 * A solid whose stable step is absurdly short (E = 1e30 Pa) needs more than
 * an ADVANCE's int32 carries: said here, naming the cause, where before the
 * count wrapped to a negative n_sub that the solid refused as a protocol
 * error. */
static enum mps_status solid_substeps(struct coupler *c, double dt, int *n_sub,
                                      struct mps_err *err)
{
    double n = ceil(dt / c->p[SOLID].dt * (1.0 - 1e-12));
    if (!(n <= (double)INT32_MAX)) {
        c->case_error = 1; /* said in one line, as a key's error */
        return mps_err_set(err, MPS_EINPUT,
                           "%s: the solid's stable step %.3g s needs %.3g sub-steps for a "
                           "coupling step of %.3g s, more than an ADVANCE carries (%d): check "
                           "the solid's E, rho and dp",
                           c->cs ? mps_case_path(c->cs) : "case", c->p[SOLID].dt, n, dt,
                           (int)INT32_MAX);
    }
    *n_sub = n < 1.0 ? 1 : (int)n;
    return MPS_OK;
}

/* The fluid's loads for the solid's ADVANCE, as built from adv. */
static struct proto_msg solid_advance(const struct coupler *c, const struct proto_msg *adv,
                                      int n_sub)
{
    struct proto_msg sadv = *adv;
    sadv.payload = c->p[FLUID].needed ? PROTO_LOADS : PROTO_NONE;
    sadv.count = c->p[FLUID].needed ? c->loads.count : 0;
    sadv.id = c->loads.id;
    sadv.pressure = c->loads.pressure;
    sadv.force = c->loads.force;
    sadv.x = sadv.v = NULL;
    sadv.surface = sadv.fixed = NULL;
    sadv.n_sub = n_sub;
    return sadv;
}

static void count_iterations(struct coupler *c, int k)
{
    c->iterations += k;
    c->iter_probe_sum += k;
    c->iter_probe_steps++;
    if (k > c->iter_max)
        c->iter_max = k;
    int b = 0;
    while (b < 7 && k > (1 << b))
        b++;
    c->iter_hist[b]++;
}

/* The solid's prediction for the first iterate (coupling.implicit.predictor:
 * solid; blended with the extrapolation by coupling_iter_predicted): the
 * solid takes the step under the last step's loads, which c->loads still
 * holds, as iteration 0 of its own; the iterations with the fluid
 * then repeat the step from its start as the solid's iterations 1, 2, ...
 * (PROTOCOL.md 6: each solver numbers the iterations it is sent). Before
 * the first step there are no loads, and that step extrapolates. */
static enum mps_status solid_prediction(struct coupler *c, struct proto_msg *adv, int n_sub,
                                        struct proto_msg *send, int *ahead, struct mps_err *err)
{
    *ahead = 0;
    if (!c->predict_solid || c->loads.payload != PROTO_LOADS)
        return MPS_OK;
    adv->iteration = 0;
    struct proto_msg sadv = solid_advance(c, adv, n_sub), res = {0};
    enum mps_status st = exchange(c, SOLID, &sadv, &res, err);
    if (!st)
        st = coupling_iter_predicted(&c->iter, &res, send, err);
    proto_msg_clear(&res);
    if (st)
        return mps_err_prefix(err, "step %ld at t = %.6g s, the solid's prediction: ", c->step,
                              c->time);
    c->predictions++;
    *ahead = 1;
    return MPS_OK;
}

/* One step of implicit coupling (coupling_iter.h): the fluid and the solid
 * repeat the step from its start, the coupler choosing the solid state the
 * fluid sees, until the solid's answer agrees with it. The solid's last
 * answer and the fluid's last loads (those it answered) are kept; the
 * solvers are then at that iteration's end. dt, the solid's sub-steps and
 * the flags stay those of the first iteration, so a repeat is the same step. */
static enum mps_status implicit_step(struct coupler *c, struct proto_msg *adv,
                                     struct mps_err *err)
{
    int n_sub = 1;
    struct proto_msg send;
    double a0 = mps_wall_seconds();
    enum mps_status st = solid_substeps(c, adv->dt, &n_sub, err);
    if (!st)
        st = coupling_iter_start(&c->iter, &c->state, adv->dt, &send, err);
    if (!st)
        st = coupling_accel_begin(c->accel, coupling_iter_len(&c->iter), err);
    c->accel_seconds += mps_wall_seconds() - a0;
    int ahead = 0; /* the solid's iteration numbers lead the fluid's by this */
    if (!st)
        st = solid_prediction(c, adv, n_sub, &send, &ahead, err);
    if (st)
        return st;
    int k = 0, converged = 0, rerun = 0;
    for (;;) {
        adv->iteration = k;
        adv->payload = PROTO_STATE;
        adv->count = send.count;
        adv->id = send.id;
        adv->x = send.x;
        adv->v = send.v;
        adv->surface = send.surface;
        adv->fixed = send.fixed;
        struct proto_msg res = {0};
        if ((st = exchange(c, FLUID, adv, &res, err)))
            return st;
        proto_msg_clear(&c->loads);
        c->loads = res;
        struct proto_msg sadv = solid_advance(c, adv, n_sub);
        sadv.iteration = k + ahead;
        res = (struct proto_msg){0};
        if ((st = exchange(c, SOLID, &sadv, &res, err)))
            return st;
        proto_msg_clear(&c->state);
        c->state = res;
        k++;
        a0 = mps_wall_seconds();
        st = coupling_iter_result(&c->iter, &c->state, &converged, err);
        if (!st && !converged && k < c->max_iter)
            st = coupling_iter_relax(&c->iter, c->accel, &send, err);
        c->accel_seconds += mps_wall_seconds() - a0;
        if (!st && !converged && k >= c->max_iter && !rerun && !c->on_max_error)
            rerun = coupling_iter_best(&c->iter, &send); /* once more with the best */
        if (c->iter_log)
            fprintf(c->iter_log, "%ld,%.9g,%d,%.6e,%.6e,%.6e,%.6g\n", c->step, c->time, k - 1,
                    c->iter.change, c->iter.increment, c->iter.displacement,
                    converged || k >= c->max_iter ? 0.0 : coupling_accel_last(c->accel));
        if (st)
            return mps_err_prefix(err, "step %ld at t = %.6g s, iteration %d: ", c->step,
                                  c->time, k - 1);
        if (converged || (k >= c->max_iter && rerun != 1))
            break;
        if (rerun == 1)
            rerun = 2; /* the repeat of the best is sent now; accepted whatever it gives */
    }
    coupling_accel_end(c->accel);
    coupling_iter_accept(&c->iter);
    count_iterations(c, k);
    double rel = c->iter.increment > 0.0 ? c->iter.change / c->iter.increment : 0.0;
    if (!converged) {
        if (c->on_max_error)
            return mps_err_set(err, MPS_EDIVERGED,
                               "implicit coupling did not converge in %d iterations at step %ld, "
                               "t = %.6g s: rms change of the interface %.3g m against a "
                               "displacement of %.3g m over the step (coupling.implicit.tolerance "
                               "%g, abs_tolerance %g m/s; coupling.implicit.on_max: error)",
                               k, c->step, c->time, c->iter.change, c->iter.increment,
                               c->iter.tol, c->iter.atol);
        if (c->limit_hits++ == 0 && !c->quiet)
            fprintf(stderr,
                    "\ncoupler: warning: step %ld at t = %.6g s not converged in %d iterations "
                    "(rms change %.3g m, displacement over the step %.3g m): accepted "
                    "(coupling.implicit.on_max: accept); such steps are counted in "
                    "summary.json\n",
                    c->step, c->time, k, c->iter.change, c->iter.increment);
    } else if (rel > c->change_max) {
        c->change_max = rel;
    }
    for (size_t q = 0; q < c->loads.count; q++)
        for (int a = 0; a < MPS_DIM; a++)
            c->impulse[a] += adv->dt * c->loads.force[q][a];
    c->impulse_time += adv->dt;
    return MPS_OK;
}

/* What the coupler holds between steps, besides the solid's interface (the
 * restored solid reports it again in READY) and the fluid's loads (sent
 * again by the fluid in the next step before the solid uses them): the
 * clock, the solvers' last stable steps (the next dt), the load integral of
 * the current probe interval and the counters. */
struct coupler_scalars {
    double time, dt[NPEERS], impulse[MPS_DIM], impulse_time;
    int64_t step;
};

/* Implicit coupling's counters: summary.json's "iterations" and the probe
 * column coupling_iterations (a mean since the last row, which a checkpoint
 * may fall inside). */
struct implicit_counters {
    int64_t iterations, iter_max, limit_hits, hist[8], probe_sum, probe_steps, predictions;
    double change_max;
};
_Static_assert(sizeof ((struct coupler *)0)->iter_hist == 8 * sizeof(long), "histogram bins");

/* Implicit coupling's history, after the coupler's scalars: the counters,
 * the interface iteration's (coupling_iter_put: the displacement reference,
 * the predictor) and the acceleration's (coupling_accel_put: Aitken's
 * factor, IQN-ILS's reused columns), and with the solid predictor the last
 * step's loads ("implicit.loads": the fluid sends them again only after the
 * next step's first solve). Without it the next steps would start from
 * another predictor and factor or without the columns: the same physics
 * within the tolerance, not the same bits. */
static enum mps_status put_loads(const struct proto_msg *l, struct mps_ckpt *ck,
                                 struct mps_err *err)
{
    int64_t count = l->payload == PROTO_LOADS ? (int64_t)l->count : -1;
    size_t n = count > 0 ? (size_t)count : 0;
    enum mps_status st;
    if ((st = mps_ckpt_put(ck, "implicit.loads", &count, sizeof count, err)) || !n)
        return st;
    if ((st = mps_ckpt_put(ck, "implicit.loads.id", l->id, n * sizeof *l->id, err)) ||
        (st = mps_ckpt_put(ck, "implicit.loads.pressure", l->pressure, n * sizeof *l->pressure,
                           err)))
        return st;
    return mps_ckpt_put(ck, "implicit.loads.force", l->force, n * sizeof *l->force, err);
}

/* The loads put_loads saved, into l (which then owns their storage). */
static enum mps_status get_loads(struct mps_ckpt *ck, struct proto_msg *l, struct mps_err *err)
{
    int64_t count;
    enum mps_status st = mps_ckpt_get(ck, "implicit.loads", &count, sizeof count, err);
    if (st || count < 0)
        return st;
    const size_t n = (size_t)count;
    const void *id, *pr, *fo;
    size_t bi, bp, bf;
    if (n && ((st = mps_ckpt_get_any(ck, "implicit.loads.id", &id, &bi, err)) ||
              (st = mps_ckpt_get_any(ck, "implicit.loads.pressure", &pr, &bp, err)) ||
              (st = mps_ckpt_get_any(ck, "implicit.loads.force", &fo, &bf, err))))
        return st;
    const size_t want_i = n * sizeof(int), want_p = n * sizeof(double),
                 want_f = n * sizeof(double[MPS_DIM]);
    if (n && (bi != want_i || bp != want_p || bf != want_f))
        return mps_err_set(err, MPS_EINPUT,
                           "the last step's loads hold %zu / %zu / %zu bytes of ids, pressures "
                           "and forces for %zu particles",
                           bi, bp, bf, n);
    unsigned char *own = malloc(want_f + want_p + want_i + 1);
    if (!own)
        return mps_err_set(err, MPS_ENOMEM, "out of memory for the last step's loads");
    proto_msg_clear(l);
    *l = proto_msg_make(PROTO_RESULT);
    l->payload = PROTO_LOADS;
    l->count = n;
    l->own_ = own;
    if (n) { /* the doubles first: the block from malloc is aligned for them */
        memcpy(own, fo, want_f);
        memcpy(own + want_f, pr, want_p);
        memcpy(own + want_f + want_p, id, want_i);
        l->force = (const double(*)[MPS_DIM])own;
        l->pressure = (const double *)(own + want_f);
        l->id = (const int *)(own + want_f + want_p);
    }
    return MPS_OK;
}

static enum mps_status put_implicit(const struct coupler *c, struct mps_ckpt *ck,
                                    struct mps_err *err)
{
    struct implicit_counters ic;
    memset(&ic, 0, sizeof ic);
    ic.iterations = c->iterations;
    ic.iter_max = c->iter_max;
    ic.limit_hits = c->limit_hits;
    for (int b = 0; b < 8; b++)
        ic.hist[b] = c->iter_hist[b];
    ic.probe_sum = c->iter_probe_sum;
    ic.probe_steps = c->iter_probe_steps;
    ic.change_max = c->change_max;
    ic.predictions = c->predictions;
    enum mps_status st;
    if ((st = mps_ckpt_put(ck, "implicit", &ic, sizeof ic, err)) ||
        (st = coupling_iter_put(&c->iter, ck, err)) ||
        (st = coupling_accel_put(c->accel, ck, err)))
        return st;
    return c->predict_solid ? put_loads(&c->loads, ck, err) : MPS_OK;
}

static enum mps_status get_implicit(struct coupler *c, struct mps_err *err)
{
    struct implicit_counters ic;
    enum mps_status st;
    if ((st = mps_ckpt_get(&c->disk, "implicit", &ic, sizeof ic, err)) ||
        (st = coupling_iter_get(&c->iter, &c->disk, err)) ||
        (st = coupling_accel_get(c->accel, &c->disk, err)))
        return mps_err_prefix(err, "%s: ", c->restart_path);
    if (c->predict_solid && (st = get_loads(&c->disk, &c->loads, err)))
        return mps_err_prefix(err, "%s: ", c->restart_path);
    c->iterations = (long)ic.iterations;
    c->iter_max = (int)ic.iter_max;
    c->limit_hits = (long)ic.limit_hits;
    for (int b = 0; b < 8; b++)
        c->iter_hist[b] = (long)ic.hist[b];
    c->iter_probe_sum = (long)ic.probe_sum;
    c->iter_probe_steps = (long)ic.probe_steps;
    c->change_max = ic.change_max;
    c->predictions = (long)ic.predictions;
    return MPS_OK;
}

static enum mps_status put_coupler(const void *self, struct mps_ckpt *ck, struct mps_err *err)
{
    const struct coupler *c = self;
    struct coupler_scalars sc;
    memset(&sc, 0, sizeof sc);
    sc.time = c->time;
    sc.step = c->step;
    sc.impulse_time = c->impulse_time;
    for (int k = 0; k < NPEERS; k++)
        sc.dt[k] = c->p[k].dt;
    for (int a = 0; a < MPS_DIM; a++)
        sc.impulse[a] = c->impulse[a];
    enum mps_status st = mps_ckpt_put(ck, "coupler", &sc, sizeof sc, err);
    return st || !c->implicit ? st : put_implicit(c, ck, err);
}

static enum mps_status get_coupler(struct coupler *c, struct mps_err *err)
{
    struct coupler_scalars sc;
    enum mps_status st = mps_ckpt_get(&c->disk, "coupler", &sc, sizeof sc, err);
    if (st)
        return st;
    c->time = sc.time;
    c->step = (long)sc.step;
    c->impulse_time = sc.impulse_time;
    for (int k = 0; k < NPEERS; k++)
        c->p[k].dt = sc.dt[k];
    for (int a = 0; a < MPS_DIM; a++)
        c->impulse[a] = sc.impulse[a];
    return c->implicit ? get_implicit(c, err) : MPS_OK;
}

/* The coupler's part of checkpoint number ++mark.number, written after the
 * solvers wrote theirs in the step's ADVANCE. */
static enum mps_status write_checkpoint(struct coupler *c, struct mps_err *err)
{
    double t0 = mps_wall_seconds();
    c->mark.number++;
    c->mark.steps = c->step;
    c->mark.table_bytes[0] = mps_probes_bytes(c->probes);
    /* iterations.csv is cut there at a restart, as probes.csv is */
    if (c->iter_log) {
        if (fflush(c->iter_log) != 0)
            return mps_err_set(err, MPS_EIO, "%s/iterations.csv: cannot write: %s", c->out,
                               strerror(errno));
        c->mark.table_bytes[1] = ftell(c->iter_log);
    }
    enum mps_status st = mps_run_checkpoint(&c->disk, c->out, "coupler", c->case_yaml, &c->mark,
                                            NULL, c->time, put_coupler, c, err);
    c->checkpoints += st == MPS_OK;
    c->t_checkpoint += mps_wall_seconds() - t0;
    return st;
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
    if (c->restart) { /* where the checkpointed run was (start_run read it) */
        out_k = c->mark.out_k;
        probe_k = c->mark.probe_k;
    } else {
        c->mark.ck_k = 1;
    }
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
        /* like a snapshot: at the end of the first step reaching its time */
        if (c->ck_interval > 0.0 && c->time + dt >= c->mark.ck_k * c->ck_interval - eps &&
            c->time + dt < end - eps)
            flags |= PROTO_F_CHECKPOINT;

        struct proto_msg adv = proto_msg_make(PROTO_ADVANCE), res = {0};
        adv.step = c->step;
        adv.time = c->time;
        adv.dt = dt;
        adv.n_sub = 1;
        adv.flags = flags;
        if (c->implicit) {
            if ((st = implicit_step(c, &adv, err)))
                return st;
        } else if (c->p[FLUID].needed) {
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
        if (!c->implicit && c->p[SOLID].needed) {
            int n_sub = 1;
            if ((st = solid_substeps(c, dt, &n_sub, err)))
                return st;
            struct proto_msg sadv = solid_advance(c, &adv, n_sub);
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
        if (flags & PROTO_F_CHECKPOINT) {
            mps_run_due(&c->mark.ck_k, c->ck_interval, c->time, eps);
            c->mark.out_k = out_k;
            c->mark.probe_k = probe_k;
            if ((st = write_checkpoint(c, err)))
                return st;
            if (c->time >= c->stop_at - eps) {
                c->stopped_at = c->time;
                break;
            }
        }
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
        /* a BYE without text (PROTOCOL.md 4 asks for a JSON object, the codec
         * checks only UTF-8) is an empty summary, not a failure */
        p->bye = strdup(m.text ? m.text : "{}");
        proto_msg_clear(&m);
        if (!p->bye)
            return mps_err_set(err, MPS_ENOMEM, "no memory to keep the %s solver's summary",
                               p->name);
        p->active = 0;
    }
    return MPS_OK;
}

/* Sends ABORT to the solvers still running and waits for them together: 5 s
 * for each to act on it, except a solver that missed its deadline (hung: it
 * is not reading), which gets SIGTERM at once; SIGKILL 2 s after SIGTERM. A
 * hang is then over within about 2 s of its deadline, not 7-12 s (one grace
 * after the other, measured by coupler_solid_hang). */
static void abort_all(struct coupler *c, const char *reason, int hung)
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
    struct child *kids[NPEERS];
    double grace[NPEERS];
    for (int k = 0; k < NPEERS; k++) {
        kids[k] = &c->p[k].child;
        grace[k] = k == hung ? 0.0 : 5.0;
    }
    launch_reap_all(kids, grace, NPEERS);
}

/* The top-level member key of a solver's summary JSON (its BYE), or def
 * when it has none (a third-party solver need not report it). */
static double bye_number(const struct peer *p, const char *key, double def)
{
    double v;
    return p->bye && mps_json_top_number(p->bye, key, &v) == 1 ? v : def;
}

/* Writes text and a newline to path: MPS_EIO naming it if it cannot. */
static enum mps_status write_text(const char *path, const char *text, struct mps_err *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return mps_err_set(err, MPS_EIO, "%s: cannot open for writing: %s", path,
                           strerror(errno));
    int bad = fputs(text, f) < 0 || fputc('\n', f) == EOF;
    bad |= fclose(f) != 0;
    if (bad)
        return mps_err_set(err, MPS_EIO, "%s: cannot write: %s", path, strerror(errno));
    return MPS_OK;
}

static void write_summary_json(struct coupler *c, enum mps_status st, const struct mps_err *err,
                               FILE *fp)
{
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
    /* checkpoints: the coupler's own cost (each solver's is in its summary)
     * and where a restarted run came from */
    mps_json_object(&j, "checkpoints");
    mps_json_num(&j, "interval", c->ck_interval);
    if (c->ck_note)
        mps_json_str(&j, "note", c->ck_note);
    mps_json_int(&j, "written", c->checkpoints);
    mps_json_num(&j, "coupler_seconds", c->t_checkpoint);
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].needed && c->p[k].bye) {
            char key[64];
            snprintf(key, sizeof key, "%s_seconds", c->p[k].name);
            mps_json_num(&j, key, bye_number(&c->p[k], "checkpoint_seconds", 0.0));
            snprintf(key, sizeof key, "%s_bytes", c->p[k].name);
            mps_json_int(&j, key, (long long)bye_number(&c->p[k], "checkpoint_bytes", 0.0));
        }
    mps_json_close(&j);
    if (c->stopped_at >= 0.0)
        mps_json_num(&j, "stopped_at", c->stopped_at);
    if (c->restart) {
        mps_json_object(&j, "restart");
        mps_json_str(&j, "checkpoint", c->restart_path);
        mps_json_num(&j, "time", c->restart_time);
        mps_json_close(&j);
    }
    /* iterations per step: 1 for the explicit scheme */
    mps_json_object(&j, "iterations");
    mps_json_str(&j, "scheme", c->implicit ? "implicit" : "explicit");
    if (c->implicit) {
        mps_json_str(&j, "acceleration", c->accel ? coupling_accel_name(c->accel) : "");
        mps_json_str(&j, "predictor", c->predict_solid ? "solid" : "extrapolate");
        mps_json_int(&j, "solid_predictions", c->predictions);
        if (c->predict_solid) /* the prediction's weight at the end (coupling_iter.h) */
            mps_json_num(&j, "prediction_weight", c->iter.w);
        mps_json_int(&j, "steps", c->step);
        mps_json_int(&j, "total", c->iterations);
        mps_json_num(&j, "mean", c->step ? (double)c->iterations / c->step : 0.0);
        mps_json_int(&j, "max", c->iter_max);
        mps_json_int(&j, "limit_hits", c->limit_hits);
        mps_json_num(&j, "max_converged_change_over_step", c->change_max);
        /* steps that took 1, 2, 3-4, 5-8, 9-16, 17-32, 33-64, more iterations */
        mps_json_array(&j, "histogram");
        for (int b = 0; b < 8; b++)
            mps_json_int(&j, NULL, c->iter_hist[b]);
        mps_json_close(&j);
        mps_json_num(&j, "acceleration_seconds", c->accel_seconds);
        for (int k = 0; k < NPEERS; k++)
            if (c->p[k].needed) {
                char key[64];
                snprintf(key, sizeof key, "%s_repeat_roundtrip_seconds", c->p[k].name);
                mps_json_num(&j, key, c->p[k].repeat_seconds);
            }
    } else {
        mps_json_int(&j, "steps", c->step);
        mps_json_num(&j, "mean", 1.0);
        mps_json_int(&j, "max", c->step ? 1 : 0);
    }
    mps_json_close(&j);
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
}

/* OUT/summary.json (the run's status st with its message err) and each
 * solver's own summary verbatim beside it. A file that cannot be written is
 * an MPS_EIO in werr (the first one), the others are still tried. */
static enum mps_status write_summary(struct coupler *c, enum mps_status st,
                                     const struct mps_err *err, struct mps_err *werr)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/summary.json", c->out);
    enum mps_status wst = MPS_OK;
    FILE *fp = fopen(path, "w");
    if (!fp)
        wst = mps_err_set(werr, MPS_EIO, "%s: cannot open for writing: %s", path,
                          strerror(errno));
    else
        write_summary_json(c, st, err, fp);
    if (fp) {
        int bad = ferror(fp);
        bad |= fclose(fp) != 0;
        if (bad)
            wst = mps_err_set(werr, MPS_EIO, "%s: cannot write: %s", path, strerror(errno));
    }
    /* the solvers' own summaries, verbatim */
    for (int k = 0; k < NPEERS; k++)
        if (c->p[k].bye) {
            struct mps_err e;
            snprintf(path, sizeof path, "%s/%s_summary.json", c->out, c->p[k].name);
            if (write_text(path, c->p[k].bye, &e) && !wst)
                wst = mps_err_set(werr, MPS_EIO, "%s", e.msg);
        }
    return wst;
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
    coupling_iter_free(&c->iter);
    coupling_accel_destroy(&c->accel);
    if (c->iter_log) /* closed by finish_run; here only when the run never got there */
        fclose(c->iter_log);
    mps_probes_close(&c->probes);
    mps_motion_destroy(&c->motion);
    mps_case_destroy(&c->cs);
    mps_ckpt_free(&c->disk);
    free(c->case_yaml);
}

/* Refuses an option that names a solver the case does not need: it would
 * otherwise be ignored without a word (input error). */
static enum mps_status refuse_unneeded(const struct coupler *c, const char *option,
                                       const char *value, int peer, const char *case_path,
                                       struct mps_err *err)
{
    if (!value || c->p[peer].needed)
        return MPS_OK;
    return mps_err_set(err, MPS_EINPUT, "%s %s: %s has no %s (%s), so no %s program runs; drop "
                       "the option or choose a case with a %s", option, value, case_path,
                       c->p[peer].name, peer == FLUID ? "fluid.tank" : "solid.bodies",
                       c->p[peer].name, c->p[peer].name);
}

enum { OPT_SOLID, OPT_FLUID, OPT_EXTERNAL, NOPTS };

/* The command line into cli and opt (--solid, --fluid, --external). Returns
 * -1 to go on, or the exit status (--help, --version, a usage error). */
static int read_command_line(int argc, char **argv, struct mps_cli *cli,
                             struct mps_cli_extra opt[NOPTS])
{
    const char *usage =
        "usage: coupler CASE.yml --out DIR [--set key=value]... [--quiet]\n"
        "               [--solid \"COMMAND\"] [--fluid \"COMMAND\"] [--external fluid|solid]\n"
        "       coupler --restart DIR [--from TIME] [--set end_time=T] [--quiet]";
    struct mps_err err = {0};
    enum mps_status st = mps_cli_parse(cli, argc, argv, opt, NOPTS, usage, &err);
    if (st == MPS_EINTR) {
        if (cli->keys) {
            const char *const titles[COUPLER_NTABLES] = {
                MPS_CASE_COMMON_KEYS_TITLE, "coupler: `coupling.*`", MPS_MOTION_KEYS_TITLE};
            mps_case_print_keys(stdout, coupler_case_tables, titles, COUPLER_NTABLES);
        }
        return 0; /* --help, --version, --keys */
    }
    if (st) {
        fprintf(stderr, "coupler: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    if (!cli->out_dir) {
        /* no silent ./out: a second run there would mix with the first */
        fprintf(stderr, "coupler: missing --out DIR (see --help)\n");
        return 2;
    }
    return -1;
}

/* Loads and checks the case (the common keys, the coupler's and the motion;
 * the scene's layout across the solvers' sections) and decides which solvers
 * run, before anything is written or launched. The solvers' keys are theirs
 * to check, at CONFIG. */
static enum mps_status load_case(struct coupler *c, const struct mps_cli *cli,
                                 const struct mps_cli_extra opt[NOPTS], struct mps_err *err)
{
    enum mps_status st =
        mps_case_load(&c->cs, cli->case_path, c->rec.sets, c->rec.nsets, coupler_case_tables,
                      COUPLER_NTABLES, coupler_solver_sections, err);
    if (st)
        return st;
    c->hello_timeout = mps_case_double(c->cs, "coupling.hello_timeout");
    c->ready_timeout = mps_case_double(c->cs, "coupling.ready_timeout");
    c->step_timeout = mps_case_double(c->cs, "coupling.step_timeout");
    /* Model only what the scene needs: launch a solver only if the case has
     * its part. */
    c->p[FLUID].needed = mps_case_has(c->cs, "fluid.tank.width");
    c->p[SOLID].needed = mps_case_count(c->cs, "solid.bodies") > 0;
    c->implicit = strcmp(mps_case_string(c->cs, "coupling.scheme"), "implicit") == 0;
    c->max_iter = (int)mps_case_int(c->cs, "coupling.implicit.max_iterations");
    c->on_max_error = strcmp(mps_case_string(c->cs, "coupling.implicit.on_max"), "error") == 0;
    c->predict_solid =
        strcmp(mps_case_string(c->cs, "coupling.implicit.predictor"), "solid") == 0;
    const char *ext = opt[OPT_EXTERNAL].value;
    if (ext && strcmp(ext, "fluid") && strcmp(ext, "solid"))
        return mps_err_set(err, MPS_EINPUT, "--external %s: must be fluid or solid", ext);
    if (!c->p[FLUID].needed && !c->p[SOLID].needed)
        return mps_err_set(err, MPS_EINPUT, "%s: the case has neither a fluid (fluid.tank) nor "
                           "a solid (solid.bodies)", cli->case_path);
    if ((st = refuse_unneeded(c, "--solid", opt[OPT_SOLID].value, SOLID, cli->case_path, err)) ||
        (st = refuse_unneeded(c, "--fluid", opt[OPT_FLUID].value, FLUID, cli->case_path, err)) ||
        (st = refuse_unneeded(c, "--external", ext, ext && !strcmp(ext, "solid") ? SOLID : FLUID,
                              cli->case_path, err)))
        return st;
    for (int k = 0; k < NPEERS; k++)
        c->p[k].external = ext && strcmp(ext, c->p[k].name) == 0;

    /* The layout across the solvers' parts (a body outside the tank or in
     * the water) is the coupler's to check, as no solver sees both; here, so
     * nothing is launched for a scene that cannot run. */
    if (c->p[FLUID].needed && c->p[SOLID].needed && (st = scene_check_fsi(c->cs, err)))
        return st;
    if ((st = mps_motion_read(&c->motion, c->cs, err)))
        return st;
    /* implicit coupling iterates on a fixed interface (coupling_iter.h); a
     * solid that cannot roll its scene back (fracture) refuses rollback=on */
    if (c->implicit && !(c->p[FLUID].needed && c->p[SOLID].needed))
        return mps_case_fail(c->cs, err, "coupling.scheme",
                             "implicit coupling needs a fluid and a solid");
    c->ck_interval = mps_case_double(c->cs, "output.checkpoint_interval");
    c->ck_asked = strcmp(mps_case_where(c->cs, "output.checkpoint_interval"), "default") != 0;
    /* versioning: the implicit scheme's history is a section of its own
     * (get_implicit), which builds before it did not write: refused before
     * anything is launched */
    if (c->implicit && c->restart && !mps_ckpt_has(&c->disk, "implicit"))
        return mps_err_set(err, MPS_EINPUT,
                           "%s: holds no history of the implicit coupling (section 'implicit': "
                           "written by a build that did not checkpoint implicit runs); it cannot "
                           "continue this implicit run bit for bit: run it again from the start",
                           c->restart_path);
    /* and the solid predictor's last loads (get_loads) one of its own */
    if (c->implicit && c->restart && c->predict_solid &&
        !mps_ckpt_has(&c->disk, "implicit.loads"))
        return mps_err_set(err, MPS_EINPUT,
                           "%s: holds no loads of the last step for the solid predictor "
                           "(section 'implicit.loads': written by a build before "
                           "coupling.implicit.predictor); it cannot continue this run bit for "
                           "bit: run it again from the start",
                           c->restart_path);
    return MPS_OK;
}

/* Writes the run's record, opens the endpoints, launches the solvers and
 * takes each through HELLO, CONFIG and READY; opens the probes. */
static enum mps_status start_run(struct coupler *c, struct mps_err *err)
{
    const char *resolved = c->rec.path;
    enum mps_status st;
    if (c->implicit &&
        (st = coupling_accel_create(&c->accel,
                                    mps_case_string(c->cs, "coupling.implicit.acceleration"),
                                    mps_case_double(c->cs, "coupling.implicit.relaxation"),
                                    (int)mps_case_int(c->cs, "coupling.implicit.reuse"),
                                    mps_case_double(c->cs, "coupling.implicit.filter"), err)))
        return st;
    if ((st = mps_mkdir_p(c->out, err)))
        return st;
    char abs_out[4096];
    if (!mps_realpath(c->out, abs_out, sizeof abs_out))
        return mps_err_set(err, MPS_EIO, "%s: %s", c->out, strerror(errno));
    /* the solvers are sent it in CONFIG, whose text frame is UTF-8
     * (PROTOCOL.md); the path as given was checked in main, this is the
     * working directory's part */
    char shown[1024];
    if (!mps_utf8_valid(abs_out))
        return mps_err_set(err, MPS_EINPUT, "--out %s: the output directory's absolute path "
                           "%s must be UTF-8 text (the solvers are sent it in the protocol's "
                           "text)", c->out, mps_utf8_escaped(abs_out, shown, sizeof shown));
    snprintf(c->rec.path, sizeof c->rec.path, "%s/case_resolved.yml", abs_out);
    /* written now, so a run that fails to start leaves it too; rewritten as
     * each solver says hello (coupler_record_hello) */
    if ((st = coupler_record_write(&c->rec, c->cs, err)))
        return st;
    snprintf(c->rundir, sizeof c->rundir, "/tmp/mpsfsi-XXXXXX");
    if (!mkdtemp(c->rundir)) {
        c->rundir[0] = '\0';
        return mps_err_set(err, MPS_EIO, "cannot create a run directory in /tmp: %s",
                           strerror(errno));
    }
    /* before the first socket: ZeroMQ's I/O threads inherit the placement */
    launch_share_cpu(strcmp(mps_case_string(c->cs, "coupling.pin_cpus"), "auto") == 0,
                     c->cpu_note, sizeof c->cpu_note);
    c->zctx = zmq_ctx_new();
    if (!c->zctx)
        return mps_err_set(err, MPS_ELIB, "zmq_ctx_new: %s", zmq_strerror(zmq_errno()));
    for (int k = 0; k < NPEERS; k++) {
        if (!c->p[k].needed)
            continue;
        if ((st = open_endpoint(c, k, err)))
            return st;
        c->p[k].active = 1; /* listened to from now on */
    }
    /* every socket holds its copy of the server's secret key now */
    memset(c->curve.server_secret, 0, sizeof c->curve.server_secret);
    /* the ZAP handler answers before any solver is launched */
    if (c->guard && (st = guard_start(c->guard, stderr, err)))
        return st;
    for (int k = 0; k < NPEERS; k++) {
        struct peer *p = &c->p[k];
        if (!p->needed)
            continue;
        /* --solid/--fluid are already in the case (coupler_record_init) */
        const char *cmd = mps_case_string(c->cs, k == FLUID ? "fluid_solver" : "solid_solver");
        snprintf(p->child.command, sizeof p->child.command, "%s", cmd);
        if (!p->external && (st = launch_start(&p->child, p->name, cmd, p->endpoint,
                                               p->key_path[0] ? p->key_path : NULL, err)))
            return st;
        p->child.name = p->name;
    }
    /* one solver at a time, so the only message that can come unasked is an
     * ERROR; the solid first, so the model its HELLO names is in the case
     * file before the fluid reads it (coupler_record_hello) */
    for (int q = NPEERS - 1; q >= 0; q--)
        if (c->p[q].needed &&
            ((st = handshake(c, q, resolved, err)) || (st = await_ready(c, q, err))))
            return st;
    if ((st = open_probes(c, err)))
        return st;
    if (!(c->case_yaml = mps_case_resolved_yaml(c->cs)))
        return mps_err_set(err, MPS_ENOMEM, "coupler: no memory for the resolved case");
    /* --restart: the solvers restored theirs before READY; now the coupler */
    if (c->restart && (st = mps_run_get_rest(&c->disk, NULL, err)) == MPS_OK &&
        (st = get_coupler(c, err)) == MPS_OK && !c->quiet)
        fprintf(stderr, "coupler: restarting at t = %.9g s (step %ld) from %s\n", c->time,
                c->step, c->restart_path);
    if (st)
        return st;
    if (c->implicit && mps_case_bool(c->cs, "coupling.implicit.log")) {
        char path[4200];
        snprintf(path, sizeof path, "%s/iterations.csv", c->out);
        if (c->restart) { /* where it stood at the checkpoint (write_checkpoint) */
            if ((st = mps_table_continue(&c->iter_log, path, c->mark.table_bytes[1], err)))
                return st;
        } else if (!(c->iter_log = fopen(path, "w"))) {
            return mps_err_set(err, MPS_EIO, "cannot create %s: %s", path, strerror(errno));
        } else {
            /* factor: the relaxation factor (constant, aitken) or the columns
             * (iqn_ils) that chose the next iterate; 0 on the step's last */
            fputs("step,time,iteration,change_rms_m,step_displacement_rms_m,displacement_rms_m,"
                  "factor\n",
                  c->iter_log);
        }
    }
    /* once every program has taken the case (an input error stays the one
     * line it is); not under --quiet: they say the model is not the one
     * declared */
    if (c->p[SOLID].needed && !c->restart)
        scene_check_lattice(c->cs, c->p[FLUID].needed, stderr);
    if (!c->quiet)
        fprintf(stderr, "coupler: %s%s%s, output in %s\n", c->p[FLUID].needed ? "fluid" : "",
                c->p[FLUID].needed && c->p[SOLID].needed ? " + " : "",
                c->p[SOLID].needed ? "solid" : "", c->out);
    return MPS_OK;
}

/* After the run (st: how it went, err its message): aborts or reaps the
 * solvers, reports refused connections, writes the summaries and the
 * scene. Returns the run's status, or MPS_EIO if the run went well but its
 * summary could not be written (err says which file). */
static enum mps_status finish_run(struct coupler *c, enum mps_status st, struct mps_err *err)
{
    if (st && c->case_error) {
        /* one line, as for the coupler's own keys; the solvers are stopped
         * without a word (they print nothing on ABORT) */
        fprintf(stderr, "coupler: %s\n", err->msg);
        /* a solver whose handshake has not begun (the fluid, when the solid
         * found the problem) has nothing to flush, and may not be connected
         * yet to read ABORT: SIGTERM at once, not after the grace */
        int idle = -1;
        for (int k = 0; k < NPEERS; k++)
            if (c->p[k].active && !c->p[k].engaged)
                idle = k;
        abort_all(c, err->msg, idle);
    } else if (st) {
        fprintf(stderr, "\ncoupler: %s: %s\n", mps_status_name(st), err->msg);
        int hung = -1; /* the solver that missed a deadline, if that was the failure */
        for (int k = 0; k < NPEERS && st == MPS_ETIMEOUT; k++)
            if (strcmp(c->failed_peer, c->p[k].name) == 0)
                hung = k;
        abort_all(c, err->msg, hung);
    } else {
        struct child *kids[NPEERS];
        double grace[NPEERS];
        for (int k = 0; k < NPEERS; k++) {
            kids[k] = &c->p[k].child;
            grace[k] = 10.0;
        }
        launch_reap_all(kids, grace, NPEERS);
    }
    if (c->guard) {
        guard_stop(c->guard);
        char who[512];
        guard_describe(c->guard, who, sizeof who);
        if (who[0])
            fprintf(stderr, "coupler: refused %ld unauthenticated connection%s: %s\n",
                    guard_refused(c->guard), guard_refused(c->guard) == 1 ? "" : "s", who);
    }
    struct mps_err werr;
    /* iterations.csv is part of the record: a write lost on close is said */
    if (c->iter_log) {
        int bad = ferror(c->iter_log);
        bad |= fclose(c->iter_log) != 0;
        c->iter_log = NULL;
        if (bad) {
            fprintf(stderr, "coupler: %s%s/iterations.csv: cannot write: %s\n",
                    st ? "also: " : "io: ", c->out, strerror(errno));
            if (!st)
                st = mps_err_set(err, MPS_EIO, "%s/iterations.csv: cannot write", c->out);
        }
    }
    if (write_summary(c, st, err, &werr)) {
        /* a failed run keeps its own status; a finished one fails here, since
         * its record is incomplete */
        fprintf(stderr, "coupler: %s%s\n", st ? "also: " : "io: ", werr.msg);
        if (!st)
            st = mps_err_set(err, MPS_EIO, "%s", werr.msg);
    }
    write_scene(c);
    long lost = (long)bye_number(&c->p[FLUID], "lost_particles", 0);
    if (lost > 0) /* a result, not progress: --quiet keeps it */
        fprintf(stderr, "coupler: %ld fluid particle%s left over the open tank walls "
                        "(removed; lost_particles in summary.json)\n",
                lost, lost == 1 ? "" : "s");
    return st;
}

int main(int argc, char **argv)
{
    mps_prov_init(argc, argv);
    struct mps_cli cli;
    struct mps_cli_extra opt[NOPTS] = {
        [OPT_SOLID] = {"--solid", 1, "solid program command (sets the case key solid_solver; "
                                     "refused for a case without a solid)", NULL},
        [OPT_FLUID] = {"--fluid", 1, "fluid program command (sets the case key fluid_solver; "
                                     "refused for a case without a fluid)", NULL},
        [OPT_EXTERNAL] = {"--external", 1, "fluid|solid: do not launch it; wait for it to "
                                           "connect", NULL},
    };
    int rc = read_command_line(argc, argv, &cli, opt);
    if (rc >= 0)
        return rc;
    signal(SIGPIPE, SIG_IGN);
    struct sigaction sa = {0};
    sa.sa_handler = on_signal; /* no SA_RESTART: waits return on Ctrl-C */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    struct coupler c = {.stopped_at = -1.0, .stop_at = cli.stop_at};
    struct mps_err err = {0};
    char restart_case[4400];
    if (cli.restart_dir) {
        /* the case the checkpoint holds, with --set end_time (mps_restart.h) */
        enum mps_status rst = mps_run_restart_open(&c.disk, &cli, "coupler", restart_case,
                                                   sizeof restart_case, &c.mark, &err);
        if (rst) {
            fprintf(stderr, "coupler: %s\n", err.msg);
            mps_ckpt_free(&c.disk);
            return mps_status_exit_code(rst);
        }
        cli.case_path = restart_case;
        c.restart = c.mark.number;
        c.restart_time = c.disk.time;
        mps_ckpt_path(c.restart_path, sizeof c.restart_path, cli.restart_dir, "coupler",
                      c.restart);
    }
    c.out = cli.out_dir;
    if (c.out && !mps_utf8_valid(c.out)) {
        /* refused before anything is made or written there: the solvers
         * are sent it in CONFIG, whose text frame is UTF-8 (PROTOCOL.md) */
        char shown[1024];
        fprintf(stderr, "coupler: --out %s: the output directory's path must be UTF-8 text "
                "(the solvers are sent it in the protocol's text)\n",
                mps_utf8_escaped(c.out, shown, sizeof shown));
        mps_ckpt_free(&c.disk);
        return mps_status_exit_code(MPS_EINPUT);
    }
    c.quiet = cli.quiet;
    c.wall0 = mps_wall_seconds();
    c.p[FLUID].name = "fluid";
    c.p[SOLID].name = "solid";
    coupler_record_init(&c.rec, &cli, opt[OPT_SOLID].value, opt[OPT_FLUID].value);
    enum mps_status st = load_case(&c, &cli, opt, &err);
    if (st) {
        fprintf(stderr, "coupler: %s\n", err.msg);
        mps_motion_destroy(&c.motion);
        mps_case_destroy(&c.cs);
        mps_ckpt_free(&c.disk);
        return mps_status_exit_code(st);
    }
    if (!(st = start_run(&c, &err)) && !(st = run_loop(&c, &err)))
        st = stop_all(&c, &err);
    st = finish_run(&c, st, &err);
    cleanup(&c);
    return mps_status_exit_code(st);
}
