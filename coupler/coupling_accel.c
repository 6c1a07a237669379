#include "coupling_accel.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Columns kept at most (oldest dropped first); the interface has a few
 * hundred unknowns and a step rarely needs more than ten iterations. */
#define IQN_MAX_COLS 64

struct coupling_accel;

/* One scheme: its update after an iteration, and what it does at a step's end. */
struct accel_scheme {
    const char *name;
    enum mps_status (*next)(struct coupling_accel *a, const double *in, const double *out,
                            double *next, struct mps_err *err);
    void (*end)(struct coupling_accel *a);
};

struct coupling_accel {
    const struct accel_scheme *scheme;
    double omega0, omega;   /* initial factor; the one in use (aitken) */
    int reuse;
    double filter;          /* iqn_ils: QR2 filter, see coupling_accel_create */
    size_t n;
    int k;                  /* iterations done in this step */
    double *r, *r_prev, *out_prev;
    /* iqn_ils: columns newest first, column-major n x IQN_MAX_COLS */
    double *V, *W, *Q, *R, *c;
    int *age;               /* steps ended since the column was made */
    int ncols;
    double last;
};

static void residual(const struct coupling_accel *a, const double *in, const double *out,
                     double *r)
{
    for (size_t i = 0; i < a->n; i++)
        r[i] = out[i] - in[i];
}

static double dot(const double *x, const double *y, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += x[i] * y[i];
    return s;
}

static enum mps_status finite_or_fail(const double *v, size_t n, const char *what,
                                      struct mps_err *err)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return mps_err_set(err, MPS_EDIVERGED,
                               "implicit coupling: %s entry %zu is not finite (%g)", what, i, v[i]);
    return MPS_OK;
}

/* ---- constant and aitken: x~_(k+1) = x~_k + w r_k ---- */

static enum mps_status relax_next(struct coupling_accel *a, const double *in, const double *out,
                                  double *next, struct mps_err *err)
{
    (void)err;
    residual(a, in, out, a->r);
    for (size_t i = 0; i < a->n; i++)
        next[i] = in[i] + a->omega * a->r[i];
    a->last = a->omega;
    return MPS_OK;
}

static enum mps_status aitken_next(struct coupling_accel *a, const double *in, const double *out,
                                   double *next, struct mps_err *err)
{
    residual(a, in, out, a->r);
    if (a->k > 0) {
        /* w_k = -w_(k-1) r_(k-1).(r_k - r_(k-1)) / |r_k - r_(k-1)|^2; a zero
         * denominator (the residual did not change) keeps w */
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < a->n; i++) {
            double d = a->r[i] - a->r_prev[i];
            num += a->r_prev[i] * d;
            den += d * d;
        }
        if (den > 0.0)
            a->omega = -a->omega * num / den;
    }
    memcpy(a->r_prev, a->r, a->n * sizeof *a->r);
    for (size_t i = 0; i < a->n; i++)
        next[i] = in[i] + a->omega * a->r[i];
    a->last = a->omega;
    return finite_or_fail(next, a->n, "the Aitken update", err);
}

static void relax_end(struct coupling_accel *a)
{
    (void)a;
}

/* ---- iqn_ils ---- */

static void drop_column(struct coupling_accel *a, int j)
{
    const size_t n = a->n;
    int after = a->ncols - j - 1;
    if (after > 0) {
        memmove(a->V + (size_t)j * n, a->V + (size_t)(j + 1) * n, (size_t)after * n * sizeof *a->V);
        memmove(a->W + (size_t)j * n, a->W + (size_t)(j + 1) * n, (size_t)after * n * sizeof *a->W);
        memmove(a->age + j, a->age + j + 1, (size_t)after * sizeof *a->age);
    }
    a->ncols--;
}

/* The newest column first: V_0 = r_k - r_(k-1), W_0 = x_k - x_(k-1). */
static void push_column(struct coupling_accel *a, const double *out)
{
    const size_t n = a->n;
    if (a->ncols == IQN_MAX_COLS)
        a->ncols--; /* the oldest goes */
    memmove(a->V + n, a->V, (size_t)a->ncols * n * sizeof *a->V);
    memmove(a->W + n, a->W, (size_t)a->ncols * n * sizeof *a->W);
    memmove(a->age + 1, a->age, (size_t)a->ncols * sizeof *a->age);
    for (size_t i = 0; i < n; i++) {
        a->V[i] = a->r[i] - a->r_prev[i];
        a->W[i] = out[i] - a->out_prev[i];
    }
    a->age[0] = 0;
    a->ncols++;
}

/* Thin QR of V by modified Gram-Schmidt, newest column first, dropping the
 * columns the filter rejects (from V and W for good: nearly dependent
 * differences, from iterations that hardly moved or from the noise of the
 * fluid's loads, would make the coefficients blow up). Q and R fill a->Q,
 * a->R (upper triangle, row-major m x IQN_MAX_COLS); returns m = columns kept. */
static int qr_filtered(struct coupling_accel *a)
{
    const size_t n = a->n;
    int m = 0;
    for (int j = 0; j < a->ncols;) {
        double *q = a->Q + (size_t)m * n;
        memcpy(q, a->V + (size_t)j * n, n * sizeof *q);
        double norm0 = sqrt(dot(q, q, n));
        for (int i = 0; i < m; i++) {
            double rij = dot(a->Q + (size_t)i * n, q, n);
            a->R[i * IQN_MAX_COLS + m] = rij;
            for (size_t p = 0; p < n; p++)
                q[p] -= rij * a->Q[(size_t)i * n + p];
        }
        double nrm = sqrt(dot(q, q, n));
        if (!(norm0 > 0.0) || nrm < a->filter * norm0) {
            drop_column(a, j); /* column j is gone; the next one takes its index */
            continue;
        }
        for (size_t p = 0; p < n; p++)
            q[p] /= nrm;
        a->R[m * IQN_MAX_COLS + m] = nrm;
        m++;
        j++;
    }
    return m;
}

static enum mps_status iqn_next(struct coupling_accel *a, const double *in, const double *out,
                                double *next, struct mps_err *err)
{
    const size_t n = a->n;
    residual(a, in, out, a->r);
    if (a->k > 0)
        push_column(a, out);
    memcpy(a->r_prev, a->r, n * sizeof *a->r);
    memcpy(a->out_prev, out, n * sizeof *out);
    int m = a->ncols ? qr_filtered(a) : 0;
    a->last = m;
    if (m == 0) { /* nothing learnt yet: relax */
        for (size_t i = 0; i < n; i++)
            next[i] = in[i] + a->omega0 * a->r[i];
        return MPS_OK;
    }
    /* min |V c + r|: R c = -Q^T r, back substitution */
    for (int i = m - 1; i >= 0; i--) {
        double s = -dot(a->Q + (size_t)i * n, a->r, n);
        for (int j = i + 1; j < m; j++)
            s -= a->R[i * IQN_MAX_COLS + j] * a->c[j];
        a->c[i] = s / a->R[i * IQN_MAX_COLS + i];
    }
    memcpy(next, out, n * sizeof *next);
    for (int j = 0; j < m; j++)
        for (size_t i = 0; i < n; i++)
            next[i] += a->c[j] * a->W[(size_t)j * n + i];
    return finite_or_fail(next, n, "the IQN-ILS update", err);
}

static void iqn_end(struct coupling_accel *a)
{
    for (int j = 0; j < a->ncols; j++)
        a->age[j]++;
    while (a->ncols > 0 && a->age[a->ncols - 1] > a->reuse)
        a->ncols--; /* the oldest are last */
}

static const struct accel_scheme schemes[] = {
    {"constant", relax_next, relax_end},
    {"aitken", aitken_next, relax_end},
    {"iqn_ils", iqn_next, iqn_end},
};

const char *coupling_accel_names(void)
{
    return "constant, aitken, iqn_ils";
}

const char *coupling_accel_name(const struct coupling_accel *a)
{
    return a->scheme->name;
}

enum mps_status coupling_accel_create(struct coupling_accel **out, const char *name,
                                      double omega, int reuse, double filter,
                                      struct mps_err *err)
{
    *out = NULL;
    const struct accel_scheme *sc = NULL;
    for (size_t k = 0; k < sizeof schemes / sizeof schemes[0]; k++)
        if (strcmp(schemes[k].name, name) == 0)
            sc = &schemes[k];
    if (!sc)
        return mps_err_set(err, MPS_EINPUT, "coupling acceleration '%s' unknown (known: %s)",
                           name, coupling_accel_names());
    if (!(omega > 0.0 && omega <= 1.0) || reuse < 0 || !(filter >= 0.0 && filter < 1.0))
        return mps_err_set(err, MPS_EINPUT,
                           "coupling acceleration: relaxation %g must be in (0, 1], reuse %d >= 0, "
                           "filter %g in [0, 1)",
                           omega, reuse, filter);
    struct coupling_accel *a = calloc(1, sizeof *a);
    if (!a)
        return mps_err_set(err, MPS_ENOMEM, "coupling acceleration: out of memory");
    a->scheme = sc;
    a->omega0 = a->omega = omega;
    a->reuse = reuse;
    a->filter = filter;
    *out = a;
    return MPS_OK;
}

static void free_vectors(struct coupling_accel *a)
{
    free(a->r);
    free(a->r_prev);
    free(a->out_prev);
    free(a->V);
    free(a->W);
    free(a->Q);
    free(a->R);
    free(a->c);
    free(a->age);
    a->r = a->r_prev = a->out_prev = a->V = a->W = a->Q = a->R = a->c = NULL;
    a->age = NULL;
    a->ncols = 0;
    a->n = 0;
}

void coupling_accel_destroy(struct coupling_accel **pa)
{
    if (!pa || !*pa)
        return;
    free_vectors(*pa);
    free(*pa);
    *pa = NULL;
}

/* Vectors for length n > 0 (past columns dropped). */
static enum mps_status alloc_vectors(struct coupling_accel *a, size_t n, struct mps_err *err)
{
    free_vectors(a);
    size_t cols = a->scheme->end == iqn_end ? IQN_MAX_COLS : 0;
    a->r = malloc(n * sizeof *a->r);
    a->r_prev = malloc(n * sizeof *a->r_prev);
    a->out_prev = malloc(n * sizeof *a->out_prev);
    if (cols) {
        a->V = malloc(cols * n * sizeof *a->V);
        a->W = malloc(cols * n * sizeof *a->W);
        a->Q = malloc(cols * n * sizeof *a->Q);
        a->R = malloc(cols * cols * sizeof *a->R);
        a->c = malloc(cols * sizeof *a->c);
        a->age = malloc(cols * sizeof *a->age);
    }
    if (!a->r || !a->r_prev || !a->out_prev ||
        (cols && (!a->V || !a->W || !a->Q || !a->R || !a->c || !a->age))) {
        free_vectors(a);
        return mps_err_set(err, MPS_ENOMEM, "coupling acceleration: out of memory for %zu", n);
    }
    a->n = n;
    return MPS_OK;
}

enum mps_status coupling_accel_begin(struct coupling_accel *a, size_t n, struct mps_err *err)
{
    if (n == 0)
        return mps_err_set(err, MPS_EINPUT, "coupling acceleration: an empty interface");
    a->k = 0;
    /* aitken: the factor the last step ended with, if it is a plain
     * under-relaxation, else the initial one. The factor tracks how strongly
     * the fluid answers the solid's motion, which changes little from one
     * step to the next: on the light plate (6 mm to 0.4 s, tolerance 1e-3)
     * 5.1 iterations per step instead of 6.0 restarting from the initial
     * factor, and a step without fluid loads takes 2 instead of 3 */
    if (!(a->omega > 0.0 && a->omega <= 1.0))
        a->omega = a->omega0;
    if (n == a->n && a->r)
        return MPS_OK;
    return alloc_vectors(a, n, err); /* a new interface size: past columns mean nothing */
}

/* The checkpoint's fixed part (coupling_accel_put). */
struct accel_head {
    char scheme[16];
    double omega0, omega, filter, last;
    int64_t reuse, n, ncols;
};

enum mps_status coupling_accel_put(const struct coupling_accel *a, struct mps_ckpt *ck,
                                   struct mps_err *err)
{
    struct accel_head h;
    memset(&h, 0, sizeof h);
    snprintf(h.scheme, sizeof h.scheme, "%s", a->scheme->name);
    h.omega0 = a->omega0;
    h.omega = a->omega;
    h.filter = a->filter;
    h.last = a->last;
    h.reuse = a->reuse;
    h.n = (int64_t)a->n;
    h.ncols = a->ncols;
    const size_t cols = (size_t)a->ncols;
    enum mps_status st;
    if ((st = mps_ckpt_put(ck, "accel", &h, sizeof h, err)) ||
        (st = mps_ckpt_put(ck, "accel.age", a->age, cols * sizeof *a->age, err)) ||
        (st = mps_ckpt_put(ck, "accel.V", a->V, cols * a->n * sizeof *a->V, err)))
        return st;
    return mps_ckpt_put(ck, "accel.W", a->W, cols * a->n * sizeof *a->W, err);
}

enum mps_status coupling_accel_get(struct coupling_accel *a, struct mps_ckpt *ck,
                                   struct mps_err *err)
{
    struct accel_head h;
    enum mps_status st = mps_ckpt_get(ck, "accel", &h, sizeof h, err);
    if (st)
        return st;
    h.scheme[sizeof h.scheme - 1] = '\0';
    if (strcmp(h.scheme, a->scheme->name) || h.omega0 != a->omega0 || h.reuse != a->reuse ||
        h.filter != a->filter)
        return mps_err_set(err, MPS_EINPUT,
                           "checkpoint: coupling acceleration %s (relaxation %g, reuse %lld, "
                           "filter %g), this run has %s (%g, %d, %g)",
                           h.scheme, h.omega0, (long long)h.reuse, h.filter, a->scheme->name,
                           a->omega0, a->reuse, a->filter);
    if (h.n < 0 || h.ncols < 0 || h.ncols > (a->scheme->end == iqn_end ? IQN_MAX_COLS : 0) ||
        (h.ncols > 0 && h.n == 0))
        return mps_err_set(err, MPS_EINPUT,
                           "checkpoint: coupling acceleration with %lld columns of %lld: damaged",
                           (long long)h.ncols, (long long)h.n);
    free_vectors(a);
    if (h.n > 0 && (st = alloc_vectors(a, (size_t)h.n, err)))
        return st;
    const size_t cols = (size_t)h.ncols;
    if ((st = mps_ckpt_get(ck, "accel.age", a->age, cols * sizeof *a->age, err)) ||
        (st = mps_ckpt_get(ck, "accel.V", a->V, cols * a->n * sizeof *a->V, err)) ||
        (st = mps_ckpt_get(ck, "accel.W", a->W, cols * a->n * sizeof *a->W, err)))
        return st;
    a->ncols = (int)h.ncols;
    a->omega = h.omega;
    a->last = h.last;
    a->k = 0;
    return MPS_OK;
}

enum mps_status coupling_accel_next(struct coupling_accel *a, const double *in,
                                    const double *out, double *next, struct mps_err *err)
{
    enum mps_status st = a->scheme->next(a, in, out, next, err);
    a->k++;
    return st;
}

void coupling_accel_end(struct coupling_accel *a)
{
    a->scheme->end(a);
    a->k = 0;
}

double coupling_accel_last(const struct coupling_accel *a)
{
    return a->last;
}
