#include "coupling_iter.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t coupling_iter_len(const struct coupling_iter *it)
{
    return 2 * MPS_DIM * it->n;
}

enum mps_status coupling_iter_init(struct coupling_iter *it, const struct proto_msg *ready,
                                   double tol, double atol, int predictor, struct mps_err *err)
{
    memset(it, 0, sizeof *it);
    const size_t n = ready->count, m = n ? n : 1, len = 2 * MPS_DIM * m;
    it->tol = tol;
    it->atol = atol;
    it->predictor = predictor;
    it->id = malloc(m * sizeof *it->id);
    it->surface = malloc(m);
    it->fixed = malloc(m);
    it->x0 = malloc(m * sizeof *it->x0);
    it->x_last = malloc(m * sizeof *it->x_last);
    it->v_last = malloc(m * sizeof *it->v_last);
    it->x_send = malloc(m * sizeof *it->x_send);
    it->v_send = malloc(m * sizeof *it->v_send);
    it->in = malloc(len * sizeof *it->in);
    it->out = malloc(len * sizeof *it->out);
    it->next = malloc(len * sizeof *it->next);
    if (!it->id || !it->surface || !it->fixed || !it->x0 || !it->x_last || !it->v_last ||
        !it->x_send || !it->v_send || !it->in || !it->out || !it->next) {
        coupling_iter_free(it);
        return mps_err_set(err, MPS_ENOMEM, "implicit coupling: out of memory for %zu particles",
                           n);
    }
    it->n = n;
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
    free(it->x_last);
    free(it->v_last);
    free(it->x_send);
    free(it->v_send);
    free(it->in);
    free(it->out);
    free(it->next);
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

static void pack(const struct coupling_iter *it, const double (*x)[MPS_DIM],
                 const double (*v)[MPS_DIM], double *vec)
{
    const size_t nd = MPS_DIM * it->n;
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            vec[MPS_DIM * k + a] = x[k][a];
            vec[nd + MPS_DIM * k + a] = v[k][a] * it->dt;
        }
}

/* vec into the arrays of send; fixed particles keep their given state. */
static void unpack(struct coupling_iter *it, const double *vec, struct proto_msg *send)
{
    const size_t nd = MPS_DIM * it->n;
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            it->x_send[k][a] = vec[MPS_DIM * k + a];
            it->v_send[k][a] = vec[nd + MPS_DIM * k + a] / it->dt;
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
    pack(it, now->x, now->v, it->in);
    if (it->predictor && it->have_last && it->dt_last > 0.0) {
        /* s_n + (s_n - s_(n-1)) dt_n / dt_(n-1), x and v alike */
        const double f = dt / it->dt_last;
        for (size_t k = 0; k < it->n; k++)
            for (int a = 0; a < MPS_DIM; a++) {
                if (it->fixed[k])
                    continue;
                size_t q = MPS_DIM * k + (size_t)a, qv = MPS_DIM * it->n + q;
                it->in[q] += f * (now->x[k][a] - it->x_last[k][a]);
                it->in[qv] += f * (now->v[k][a] - it->v_last[k][a]) * dt;
            }
    }
    memcpy(it->x_last, now->x, it->n * sizeof *it->x_last);
    memcpy(it->v_last, now->v, it->n * sizeof *it->v_last);
    it->dt_last = dt;
    it->have_last = 1;
    unpack(it, it->in, send);
    return MPS_OK;
}

enum mps_status coupling_iter_result(struct coupling_iter *it, const struct proto_msg *res,
                                     int *converged, struct mps_err *err)
{
    enum mps_status st = same_interface(it, res, err);
    if (st)
        return st;
    pack(it, res->x, res->v, it->out);
    double ch = 0.0, disp = 0.0;
    for (size_t k = 0; k < it->n; k++)
        for (int a = 0; a < MPS_DIM; a++) {
            double d = it->out[MPS_DIM * k + a] - it->in[MPS_DIM * k + a];
            double u = res->x[k][a] - it->x0[k][a];
            ch += d * d;
            disp += u * u;
        }
    double inv = it->n ? 1.0 / (double)it->n : 0.0;
    it->change = sqrt(ch * inv);
    it->displacement = sqrt(disp * inv);
    *converged = it->change <= it->tol * it->displacement + it->atol;
    return MPS_OK;
}

enum mps_status coupling_iter_relax(struct coupling_iter *it, struct coupling_accel *a,
                                    struct proto_msg *send, struct mps_err *err)
{
    enum mps_status st = coupling_accel_next(a, it->in, it->out, it->next, err);
    if (st)
        return st;
    /* clamped particles stay where the solid has them, whatever the scheme */
    const size_t nd = MPS_DIM * it->n;
    for (size_t k = 0; k < it->n; k++)
        if (it->fixed[k])
            for (int q = 0; q < MPS_DIM; q++) {
                it->next[MPS_DIM * k + q] = it->out[MPS_DIM * k + q];
                it->next[nd + MPS_DIM * k + q] = it->out[nd + MPS_DIM * k + q];
            }
    double *t = it->in;
    it->in = it->next;
    it->next = t;
    unpack(it, it->in, send);
    return MPS_OK;
}
