#include "proto_solver.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zmq.h>

#include "mps_timer.h"
#include "proto_link.h"

/* The wait for the next message is cut into slices so a signal or the
 * parent's death is noticed within a second. */
#define SLICE_MS 1000

static enum mps_status recv_sliced(void *sock, struct proto_msg *m, long timeout_ms,
                                   volatile const int *stop_flag, pid_t parent,
                                   struct mps_err *err)
{
    long waited = 0;
    for (;;) {
        if (stop_flag && *stop_flag)
            return mps_err_set(err, MPS_EINTR, "interrupted: signal %d", *stop_flag);
        if (getppid() != parent)
            return mps_err_set(err, MPS_EPEER, "the coupler (pid %d) is gone", (int)parent);
        int slice = timeout_ms < 0 || timeout_ms - waited > SLICE_MS ? SLICE_MS
                                                                     : (int)(timeout_ms - waited);
        enum mps_status st = proto_link_recv(sock, m, slice, err);
        if (st == MPS_ETIMEOUT) {
            waited += slice;
            if (timeout_ms >= 0 && waited >= timeout_ms)
                return mps_err_set(err, MPS_ETIMEOUT,
                                   "no message from the coupler within %ld ms", timeout_ms);
            continue;
        }
        if (st == MPS_EINTR)
            continue; /* the flag check above decides */
        return st;
    }
}

/* Implicit coupling (PROTOCOL.md 6): an ADVANCE of iteration 0 starts a
 * step, saved first when rollback is on; iteration k > 0 repeats the step of
 * iteration k - 1 (same step, time, dt and n_sub) from its start. last holds
 * the header of the previous ADVANCE. */
static enum mps_status rollback(const struct proto_solver_ops *ops, void *self,
                                const struct proto_msg *in, struct proto_msg *last,
                                struct proto_solver_stats *stats, struct mps_err *err)
{
    enum mps_status st = MPS_OK;
    if (in->iteration == 0) {
        if (stats->rollback)
            st = ops->save(self, err);
    } else if (!stats->rollback) {
        return mps_err_set(err, MPS_EPROTO,
                           "ADVANCE step %lld iteration %d: a repeated step needs rollback=on "
                           "in CONFIG",
                           (long long)in->step, in->iteration);
    } else if (in->step != last->step || in->iteration != last->iteration + 1 ||
               in->time != last->time || in->dt != last->dt || in->n_sub != last->n_sub) {
        return mps_err_set(err, MPS_EPROTO,
                           "ADVANCE step %lld iteration %d at t = %.17g, dt = %.17g, n_sub %d "
                           "does not repeat step %lld iteration %d at t = %.17g, dt = %.17g, "
                           "n_sub %d",
                           (long long)in->step, in->iteration, in->time, in->dt, in->n_sub,
                           (long long)last->step, last->iteration, last->time, last->dt,
                           last->n_sub);
    } else {
        st = ops->restore(self, err);
        stats->repeats++;
    }
    last->step = in->step;
    last->iteration = in->iteration;
    last->time = in->time;
    last->dt = in->dt;
    last->n_sub = in->n_sub;
    return st;
}

/* Best effort: tell the coupler why we stop. MPS_OK if the ERROR went out. */
static enum mps_status send_error(void *sock, const struct proto_msg *last, enum mps_status st,
                                  const struct mps_err *err)
{
    char text[1200];
    snprintf(text, sizeof text, "%s: %s", mps_status_name(st), err->msg);
    struct proto_msg e = proto_msg_make(PROTO_ERROR);
    e.text = text;
    if (last) {
        e.step = last->step;
        e.time = last->time;
    }
    struct mps_err ignored;
    return proto_link_send(sock, &e, &ignored);
}

enum mps_status proto_solver_case_error(enum mps_status st, struct mps_err *err)
{
    if (st == MPS_EINPUT && strncmp(err->msg, PROTO_CASE_ERROR, strlen(PROTO_CASE_ERROR)) != 0)
        mps_err_prefix(err, "%s", PROTO_CASE_ERROR);
    return st;
}

enum mps_status proto_solver_run(const char *endpoint, const struct proto_solver_ops *ops,
                                 void *self, int hello_timeout_ms,
                                 volatile const int *stop_flag, struct proto_solver_stats *stats,
                                 struct mps_err *err)
{
    struct proto_solver_stats local = {0};
    if (!stats)
        stats = &local;
    memset(stats, 0, sizeof *stats);
    void *ctx = zmq_ctx_new();
    if (!ctx)
        return mps_err_set(err, MPS_ELIB, "zmq_ctx_new failed: %s", zmq_strerror(zmq_errno()));
    void *sock = NULL;
    pid_t parent = getppid();
    struct proto_msg in = {0}, reply, last = {0};
    last.iteration = -1; /* no ADVANCE yet */
    int configured = 0, said_error = 0;
    long timeout_ms = 1800000;
    /* tcp is authenticated with CURVE (PROTOCOL.md section 10); ipc lives in
     * the coupler's private run directory */
    struct proto_curve keys, *curve = NULL;
    enum mps_status st = MPS_OK;
    if (strncmp(endpoint, "tcp://", 6) == 0) {
        const char *kf = getenv(PROTO_KEY_ENV);
        if (!kf || !kf[0]) {
            st = mps_err_set(err, MPS_EINPUT,
                             "%s: a tcp endpoint needs the run's key: --key FILE (or %s=FILE "
                             "in the environment; PROTOCOL.md section 10)",
                             endpoint, PROTO_KEY_ENV);
            goto done;
        }
        if ((st = proto_key_read(kf, &keys, err)))
            goto done;
        curve = &keys;
    }
    st = proto_link_open_secure(ctx, PROTO_LINK_CONNECT, endpoint, curve, NULL, &sock, err);
    memset(&keys, 0, sizeof keys); /* the socket holds its copy */
    if (st)
        goto done;

    char hello[512];
    const int can_roll = ops->save && ops->restore;
    const int can_ckpt = ops->checkpoint && ops->resume;
    snprintf(hello, sizeof hello, "role=%s model=%s pid=%d build=%s%s%s%s", ops->role, ops->model,
             (int)getpid(), MPS_VERSION,
             can_roll && can_ckpt ? " caps=rollback,checkpoint"
             : can_roll           ? " caps=rollback"
             : can_ckpt           ? " caps=checkpoint"
                                  : "",
             ops->sets ? " sets=" : "", ops->sets ? ops->sets : "");
    reply = proto_msg_make(PROTO_HELLO);
    reply.text = hello;
    if ((st = proto_link_send(sock, &reply, err)))
        goto done;

    if ((st = recv_sliced(sock, &in, hello_timeout_ms, stop_flag, parent, err)))
        goto fail;
    if (in.type == PROTO_REJECT) {
        st = mps_err_set(err, MPS_EPROTO, "the coupler refused this solver: %s",
                         in.text ? in.text : "(no reason)");
        said_error = 1; /* no reply to a REJECT */
        goto done;
    }
    if (in.type == PROTO_ABORT) { /* another solver's error ends the run before it began */
        st = mps_err_set(err, MPS_EPEER, "aborted by the coupler: %s",
                         in.text ? in.text : "(no reason)");
        said_error = stats->coupler_reports = 1; /* no reply to ABORT */
        goto done;
    }
    if (in.type != PROTO_CONFIG) {
        st = mps_err_set(err, MPS_EPROTO, "expected CONFIG or REJECT after HELLO, got %s",
                         proto_type_name(in.type));
        goto fail;
    }
    {
        char case_path[4096], out[4096], prefix[64], tms[64], roll[16];
        if (proto_text_get(in.text, '\n', "case", case_path, sizeof case_path) != 1 ||
            proto_text_get(in.text, '\n', "out", out, sizeof out) != 1 ||
            proto_text_get(in.text, '\n', "prefix", prefix, sizeof prefix) != 1) {
            st = mps_err_set(err, MPS_EPROTO, "CONFIG lacks case, out or prefix");
            goto fail;
        }
        if (proto_text_get(in.text, '\n', "timeout_ms", tms, sizeof tms) == 1)
            timeout_ms = atol(tms);
        /* PROTOCOL.md 4: a key this solver does not know is an input error, not
         * something to skip (a newer coupler may rely on it); rollback is known
         * only to a solver that can roll back */
        for (const char *line = in.text; line && *line;) {
            const char *end = strchr(line, '\n'), *eq = strchr(line, '=');
            size_t len = end ? (size_t)(end - line) : strlen(line);
            size_t klen = eq && (size_t)(eq - line) < len ? (size_t)(eq - line) : len;
            static const char *const known[] = {"case", "out", "prefix", "timeout_ms",
                                                "rollback", "restart"};
            int ok = len == 0;
            for (int k = 0; k < 6 && !ok; k++)
                ok = (k < 4 || (k == 4 && can_roll) || (k == 5 && can_ckpt)) &&
                     strlen(known[k]) == klen && strncmp(line, known[k], klen) == 0;
            if (!ok && klen == 6 && strncmp(line, "motion", 6) == 0) {
                /* PROTOCOL.md 4: the case's tank moves; a solver that cannot
                 * apply the moving frame says so rather than run a fixed tank */
                if (!ops->moving_frame) {
                    st = mps_err_set(err, MPS_EINPUT,
                                     "CONFIG %.*s: this %s solver (%s) cannot apply a moving "
                                     "tank frame (the case's motion block)",
                                     (int)len, line, ops->role, ops->model);
                    goto fail;
                }
                ok = 1;
            }
            if (!ok) {
                st = mps_err_set(err, MPS_EINPUT, "CONFIG key '%.*s' unknown", (int)klen, line);
                goto fail;
            }
            line = end ? end + 1 : NULL;
        }
        if (can_roll && proto_text_get(in.text, '\n', "rollback", roll, sizeof roll) != 0) {
            if (strcmp(roll, "on") && strcmp(roll, "off")) {
                st = mps_err_set(err, MPS_EINPUT, "CONFIG rollback=%.15s: must be on or off",
                                 roll);
                goto fail;
            }
            stats->rollback = strcmp(roll, "on") == 0;
        }
        char rs[32];
        if (can_ckpt && proto_text_get(in.text, '\n', "restart", rs, sizeof rs) != 0) {
            char *e = NULL;
            long n = strtol(rs, &e, 10);
            if (e == rs || *e || n < 1) {
                st = mps_err_set(err, MPS_EINPUT, "CONFIG restart=%.20s: must be a checkpoint "
                                 "number >= 1", rs);
                goto fail;
            }
            stats->restart = stats->checkpoints = n;
        }
        double t0 = mps_wall_seconds();
        st = ops->configure(self, case_path, out, prefix, err);
        configured = 1;
        if (!st && stats->restart)
            st = ops->resume(self, stats->restart, err);
        /* the first save refuses a scene the solver cannot roll back, before READY */
        if (!st && stats->rollback)
            st = ops->save(self, err);
        if (st)
            goto fail;
        reply = proto_msg_make(PROTO_READY);
        st = ops->ready(self, &reply, err);
        stats->setup_seconds += mps_wall_seconds() - t0;
        if (st || (st = proto_link_send(sock, &reply, err)))
            goto fail;
    }

    for (;;) {
        proto_msg_clear(&in);
        double t0 = mps_wall_seconds();
        st = recv_sliced(sock, &in, timeout_ms, stop_flag, parent, err);
        stats->wait_seconds += mps_wall_seconds() - t0;
        if (st)
            goto fail;
        if (in.type == PROTO_ABORT) {
            st = mps_err_set(err, MPS_EPEER, "aborted by the coupler: %s",
                             in.text ? in.text : "(no reason)");
            said_error = stats->coupler_reports = 1; /* no reply to ABORT */
            goto done;
        }
        if (in.type == PROTO_STOP) {
            char *json = ops->finish(self, MPS_OK, err);
            configured = 0;
            reply = proto_msg_make(PROTO_BYE);
            reply.step = in.step;
            reply.time = in.time;
            reply.text = json ? json : "{}";
            st = proto_link_send(sock, &reply, err);
            free(json);
            goto done;
        }
        if (in.type != PROTO_ADVANCE) {
            st = mps_err_set(err, MPS_EPROTO, "expected ADVANCE, STOP or ABORT, got %s",
                             proto_type_name(in.type));
            goto fail;
        }
        t0 = mps_wall_seconds();
        if ((st = rollback(ops, self, &in, &last, stats, err)))
            goto fail;
        double t1 = mps_wall_seconds();
        stats->rollback_seconds += t1 - t0;
        reply = proto_msg_make(PROTO_RESULT);
        st = ops->advance(self, &in, &reply, err);
        if (!st && (in.flags & PROTO_F_CHECKPOINT)) {
            if (!can_ckpt) {
                st = mps_err_set(err, MPS_EPROTO, "ADVANCE step %lld asks for a checkpoint: "
                                 "this solver declared no caps=checkpoint", (long long)in.step);
                goto fail;
            }
            /* a repeated iteration rewrites the step's checkpoint */
            if (in.iteration == 0)
                stats->checkpoints++;
            double t2 = mps_wall_seconds();
            st = ops->checkpoint(self, stats->checkpoints, in.time + in.dt, err);
            stats->checkpoint_seconds += mps_wall_seconds() - t2;
        }
        stats->compute_seconds += mps_wall_seconds() - t0;
        stats->advances++;
        if (st)
            goto fail;
        reply.type = PROTO_RESULT;
        reply.step = in.step;
        reply.iteration = in.iteration;
        reply.time = in.time + in.dt; /* one addition, as PROTOCOL.md 6 asks */
        reply.flags = in.flags & PROTO_F_PROBES;
        if ((st = proto_link_send(sock, &reply, err)))
            goto fail;
    }

fail:
    if (sock && !said_error && st != MPS_EPEER && send_error(sock, &in, st, err) == MPS_OK &&
        st == MPS_EINPUT && strncmp(err->msg, PROTO_CASE_ERROR, strlen(PROTO_CASE_ERROR)) == 0)
        stats->coupler_reports = 1; /* the coupler prints it as its own */
    /* stopped by a signal before CONFIG: it has done nothing, and the run's
     * end (the other solver's error, Ctrl-C) is the coupler's to tell */
    if (st == MPS_EINTR && !configured)
        stats->coupler_reports = 1;
done:
    if (configured) {
        char *json = ops->finish(self, st, err);
        free(json);
    }
    proto_msg_clear(&in);
    proto_link_close(&sock);
    zmq_ctx_term(ctx);
    return st;
}

int proto_solver_args(int argc, char **argv, const char **endpoint, int *hello_timeout_ms,
                      struct mps_err *err)
{
    int found = 0;
    *hello_timeout_ms = 60000;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--connect") == 0) {
            if (i + 1 >= argc) {
                mps_err_set(err, MPS_EINPUT, "--connect needs an endpoint (ipc://... or tcp://...)");
                return -1;
            }
            *endpoint = argv[++i];
            found = 1;
        } else if (strcmp(argv[i], "--timeout") == 0) {
            char *end;
            double s = i + 1 < argc ? strtod(argv[i + 1], &end) : 0.0;
            if (i + 1 >= argc || *end || !(s > 0.0) || s > 1e6) {
                mps_err_set(err, MPS_EINPUT, "--timeout needs seconds > 0");
                return -1;
            }
            *hello_timeout_ms = (int)(s * 1000.0);
            i++;
        } else if (strcmp(argv[i], "--key") == 0) {
            if (i + 1 >= argc || !argv[i + 1][0]) {
                mps_err_set(err, MPS_EINPUT, "--key needs a key file (PROTOCOL.md section 10)");
                return -1;
            }
            /* one way in for the key file, whoever started us: the
             * environment variable the coupler sets for the solvers it
             * launches (the key itself never goes on a command line) */
            if (setenv(PROTO_KEY_ENV, argv[++i], 1) != 0) {
                mps_err_set(err, MPS_ENOMEM, "--key: cannot set %s", PROTO_KEY_ENV);
                return -1;
            }
        } else if (strcmp(argv[i], "--quiet") == 0) {
            continue;
        } else if (found) {
            mps_err_set(err, MPS_EINPUT,
                        "'%s': a coupled solver takes only --connect, --key, --timeout and "
                        "--quiet "
                        "(the case comes from the coupler)",
                        argv[i]);
            return -1;
        }
    }
    return found;
}

char *proto_join_names(const char *const *names, int n, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int k = 0; k < n && used < len; k++)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", k ? "," : "", names[k]);
    return buf;
}
