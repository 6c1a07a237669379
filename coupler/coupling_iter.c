#include "coupling_iter.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

size_t coupling_iter_len(const struct coupling_iter *it)
{
    return MPS_DIM * it->n;
}

enum mps_status coupling_iter_init(struct coupling_iter *it, const struct proto_msg *ready,
                                   double tol, double atol, struct mps_err *err)
{
    memset(it, 0, sizeof *it);
    const size_t n = ready->count, m = n ? n : 1;
    it->tol = tol;
    it->atol = atol;
    it->id = malloc(m * sizeof *it->id);
    it->surface = malloc(m);
    it->fixed = malloc(m);
    it->x0 = malloc(m * sizeof *it->x0);
    it->x_start = malloc(m * sizeof *it->x_start);
    it->x_prev = malloc(m * sizeof *it->x_prev);
    it->x_send = malloc(m * sizeof *it->x_send);
    it->v_send = malloc(m * sizeof *it->v_send);
    it->in = malloc(m * sizeof *it->in * MPS_DIM);
    it->out = malloc(m * sizeof *it->out * MPS_DIM);
    it->next = malloc(m * sizeof *it->next * MPS_DIM);
    it->best = malloc(m * sizeof *it->best * MPS_DIM);
    it->pred_e = malloc(m * sizeof *it->pred_e * MPS_DIM);
    it->pred_p = malloc(m * sizeof *it->pred_p * MPS_DIM);
    if (!it->id || !it->surface || !it->fixed || !it->x0 || !it->x_start || !it->x_prev ||
        !it->x_send || !it->v_send || !it->in || !it->out || !it->next || !it->best ||
        !it->pred_e || !it->pred_p) {
        coupling_iter_free(it);
        return mps_err_set(err, MPS_ENOMEM, "implicit coupling: out of memory for %zu particles",
                           n);
    }
    it->n = n;
    it->w = 1.0;
    if (n) {
        memcpy(it->id, ready->id, n * sizeof *it->id);
        memcpy(it->surface, ready->surface, n);
        memcpy(it->fixed, ready->fixed, n);
        memcpy(it->x0, ready->x, n * sizeof *it->x0);
    }
    return MPS_OK;
}

void coupling_iter_free(struct coupling_iter *it)
{
    free(it->id);
    free(it->surface);
    free(it->fixed);
    free(it->x0);
    free(it->x_start);
    free(it->x_prev);
    free(it->x_send);
    free(it->v_send);
    free(it->in);
    free(it->out);
    free(it->next);
    free(it->best);
    free(it->pred_e);
    free(it->pred_p);
    memset(it, 0, sizeof *it);
}

/* A STATE from the solid must be READY's interface, in READY's order. */
static enum mps_status same_interface(const struct coupling_iter *it, const struct proto_msg *m,
                                      struct mps_err *err)
{
    if (m->payload != PROTO_STATE || m->count != it->n)
        return mps_err_set(err, MPS_EINPUT,
                           "implicit coupling: the solid's interface has %zu particles, it had "
                           "%zu at READY: an interface that changes (fracture) cannot be "
                           "iterated on",
                           m->count, it->n);
    for (size_t k = 0; k < it->n; k++)
        if (m->id[k] != it->id[k])
            return mps_err_set(err, MPS_EINPUT,
                               "implicit coupling: the solid's interface lists id %d at position "
                               "%zu, READY had id %d there: the implicit coupling needs the "
                               "interface in one order",
                               m->id[k], k, it->id[k]);
    return MPS_OK;
}

/* Positions vec into send, with the step's mean velocity (header). */
static void unpack(struct coupling_iter *it, const double *vec, struct proto_msg *send)
{
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            it->x_send[k][a] = vec[MPS_DIM * k + a];
            it->v_send[k][a] = (vec[MPS_DIM * k + a] - it->x_start[k][a]) / it->dt;
        }
    *send = proto_msg_make(PROTO_ADVANCE);
    send->payload = PROTO_STATE;
    send->count = it->n;
    send->id = it->id;
    send->x = (const double(*)[MPS_DIM])it->x_send;
    send->v = (const double(*)[MPS_DIM])it->v_send;
    send->surface = it->surface;
    send->fixed = it->fixed;
}

enum mps_status coupling_iter_start(struct coupling_iter *it, const struct proto_msg *now,
                                    double dt, struct proto_msg *send, struct mps_err *err)
{
    enum mps_status st = same_interface(it, now, err);
    if (st)
        return st;
    if (!(dt > 0.0))
        return mps_err_set(err, MPS_EINPUT, "implicit coupling: step %g s", dt);
    it->dt = dt;
    memcpy(it->x_start, now->x, it->n * sizeof *it->x_start);
    /* x_n + (x_n - x_(n-1)) dt_n / dt_(n-1); the first step x_0 + v_0 dt.
     * Clamped particles stay put. */
    const double f = it->dt_prev > 0.0 ? dt / it->dt_prev : 0.0;
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            double step = it->fixed[k] ? 0.0
                        : f > 0.0  ? f * (now->x[k][a] - it->x_prev[k][a])
                                   : dt * now->v[k][a];
            it->in[MPS_DIM * k + a] = now->x[k][a] + step;
        }
    memcpy(it->x_prev, now->x, it->n * sizeof *it->x_prev);
    it->dt_prev = dt;
    it->have_pred = 0;
    it->best_change = INFINITY;
    it->best_k = it->last_k = -1;
    unpack(it, it->in, send);
    return MPS_OK;
}

enum mps_status coupling_iter_predicted(struct coupling_iter *it, const struct proto_msg *pred,
                                        struct proto_msg *send, struct mps_err *err)
{
    enum mps_status st = same_interface(it, pred, err);
    if (st)
        return st;
    const size_t len = coupling_iter_len(it);
    memcpy(it->pred_e, it->in, len * sizeof *it->pred_e);
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            size_t q = MPS_DIM * k + (size_t)a;
            /* clamped particles: the extrapolation keeps them where they are */
            it->pred_p[q] = it->fixed[k] ? it->pred_e[q] : pred->x[k][a];
            it->in[q] = it->pred_e[q] + it->w * (it->pred_p[q] - it->pred_e[q]);
        }
    it->have_pred = 1;
    unpack(it, it->in, send);
    return MPS_OK;
}

void coupling_iter_accept(struct coupling_iter *it)
{
    if (!it->have_pred)
        return;
    const double lambda = 0.9; /* memory of about ten steps */
    double pp = 0.0, pr = 0.0;
    for (size_t q = 0; q < coupling_iter_len(it); q++) {
        double d = it->pred_p[q] - it->pred_e[q], r = it->out[q] - it->pred_e[q];
        pp += d * d;
        pr += d * r;
    }
    it->s_pp = lambda * it->s_pp + pp;
    it->s_pr = lambda * it->s_pr + pr;
    double w = it->s_pp > 0.0 ? it->s_pr / it->s_pp : 1.0;
    it->w = w < 0.0 ? 0.0 : w > 1.0 ? 1.0 : w;
    it->have_pred = 0;
}

enum mps_status coupling_iter_result(struct coupling_iter *it, const struct proto_msg *res,
                                     int *converged, struct mps_err *err)
{
    enum mps_status st = same_interface(it, res, err);
    if (st)
        return st;
    double ch = 0.0, disp = 0.0, inc = 0.0;
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            size_t q = MPS_DIM * k + (size_t)a;
            it->out[q] = res->x[k][a];
            double d = it->out[q] - it->in[q], u = res->x[k][a] - it->x0[k][a];
            double s = res->x[k][a] - it->x_start[k][a];
            ch += d * d;
            disp += u * u;
            inc += s * s;
        }
    double inv = it->n ? 1.0 / (double)it->n : 0.0;
    it->change = sqrt(ch * inv);
    it->displacement = sqrt(disp * inv);
    it->increment = sqrt(inc * inv);
    *converged = it->change <= it->tol * it->increment + it->atol * it->dt;
    it->last_k++;
    if (it->change <= it->best_change) { /* ties: the later, already the solvers' state */
        it->best_change = it->change;
        it->best_k = it->last_k;
        memcpy(it->best, it->in, coupling_iter_len(it) * sizeof *it->best);
    }
    return MPS_OK;
}

int coupling_iter_best(struct coupling_iter *it, struct proto_msg *send)
{
    if (it->best_k < 0 || it->best_k == it->last_k)
        return 0;
    memcpy(it->in, it->best, coupling_iter_len(it) * sizeof *it->in);
    unpack(it, it->in, send);
    return 1;
}

enum mps_status coupling_iter_relax(struct coupling_iter *it, struct coupling_accel *a,
                                    struct proto_msg *send, struct mps_err *err)
{
    enum mps_status st = coupling_accel_next(a, it->in, it->out, it->next, err);
    if (st)
        return st;
    /* clamped particles stay where the solid has them, whatever the scheme */
    for (size_t k = 0; k < it->n; k++)
        if (it->fixed[k])
            for (int q = 0; q < MPS_DIM; q++)
                it->next[MPS_DIM * k + q] = it->out[MPS_DIM * k + q];
    double *t = it->in;
    it->in = it->next;
    it->next = t;
    unpack(it, it->in, send);
    return MPS_OK;
}

/* The checkpoint's fixed part (coupling_iter_put). */
struct iter_head {
    int64_t n;
    double dt_prev, s_pp, s_pr, w;
};

enum mps_status coupling_iter_put(const struct coupling_iter *it, struct mps_ckpt *ck,
                                  struct mps_err *err)
{
    struct iter_head h;
    memset(&h, 0, sizeof h);
    h.n = (int64_t)it->n;
    h.dt_prev = it->dt_prev;
    h.s_pp = it->s_pp;
    h.s_pr = it->s_pr;
    h.w = it->w;
    enum mps_status st;
    if ((st = mps_ckpt_put(ck, "iter", &h, sizeof h, err)) ||
        (st = mps_ckpt_put(ck, "iter.id", it->id, it->n * sizeof *it->id, err)) ||
        (st = mps_ckpt_put(ck, "iter.x0", it->x0, it->n * sizeof *it->x0, err)))
        return st;
    return mps_ckpt_put(ck, "iter.x_prev", it->x_prev, it->n * sizeof *it->x_prev, err);
}

enum mps_status coupling_iter_get(struct coupling_iter *it, struct mps_ckpt *ck,
                                  struct mps_err *err)
{
    struct iter_head h;
    const void *ids;
    size_t bytes;
    enum mps_status st;
    if ((st = mps_ckpt_get(ck, "iter", &h, sizeof h, err)) ||
        (st = mps_ckpt_get_any(ck, "iter.id", &ids, &bytes, err)))
        return st;
    if (h.n != (int64_t)it->n || bytes != it->n * sizeof *it->id ||
        (it->n && memcmp(ids, it->id, bytes) != 0))
        return mps_err_set(err, MPS_EINPUT,
                           "checkpoint: the implicit coupling's interface had %lld particles, the "
                           "restarted solid reports %zu%s",
                           (long long)h.n, it->n,
                           h.n == (int64_t)it->n ? " in another order or with other ids" : "");
    if ((st = mps_ckpt_get(ck, "iter.x0", it->x0, it->n * sizeof *it->x0, err)) ||
        (st = mps_ckpt_get(ck, "iter.x_prev", it->x_prev, it->n * sizeof *it->x_prev, err)))
        return st;
    it->dt_prev = h.dt_prev;
    it->s_pp = h.s_pp;
    it->s_pr = h.s_pr;
    it->w = h.w;
    return MPS_OK;
}
