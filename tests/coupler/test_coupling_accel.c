/* The implicit coupling's acceleration schemes (coupler/coupling_accel.h) on a
 * linear model problem with a known fixed point: H(x) = A x + b, x* = H(x*).
 * A = Q diag(lambda) Q^T with Q orthogonal and one strongly negative
 * eigenvalue (-6: the added-mass mode of a light structure, where the plain
 * iteration multiplies the error by -6 each time) besides milder ones. The
 * plain iteration must diverge on it (so the problem is a real test), Aitken
 * and IQN-ILS must converge with bounded iteration counts, and IQN-ILS that
 * keeps its columns must solve the next "time step" (another b) in far fewer
 * iterations than the first. On A = lambda I Aitken's factor is exact after
 * one secant: the fixed point at the third evaluation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coupling_accel.h"
#include "test_util.h"

#define N 12

static const double lambda[N] = {-6.0, -2.0, -0.8, 0.5, 0.3, -0.3, 0.2, 0.1, -0.1, 0.05, 0.0, -0.05};
static double A[N][N], xstar[N], b[N];

static double rnd(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return ((*s >> 8) & 0xffff) / 65536.0 - 0.5;
}

static void build(unsigned seed)
{
    double Q[N][N];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            Q[i][j] = rnd(&seed);
    for (int j = 0; j < N; j++) { /* Gram-Schmidt on the columns */
        for (int k = 0; k < j; k++) {
            double d = 0.0;
            for (int i = 0; i < N; i++)
                d += Q[i][j] * Q[i][k];
            for (int i = 0; i < N; i++)
                Q[i][j] -= d * Q[i][k];
        }
        double nrm = 0.0;
        for (int i = 0; i < N; i++)
            nrm += Q[i][j] * Q[i][j];
        for (int i = 0; i < N; i++)
            Q[i][j] /= sqrt(nrm);
    }
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            A[i][j] = 0.0;
            for (int k = 0; k < N; k++)
                A[i][j] += Q[i][k] * lambda[k] * Q[j][k];
        }
}

/* b for the fixed point x* = 1 + i/N (+ shift): b = x* - A x* */
static void set_fixed_point(double shift)
{
    for (int i = 0; i < N; i++)
        xstar[i] = 1.0 + (double)i / N + shift * sin(i);
    for (int i = 0; i < N; i++) {
        b[i] = xstar[i];
        for (int j = 0; j < N; j++)
            b[i] -= A[i][j] * xstar[j];
    }
}

static double rel_error(const double *x)
{
    double e = 0.0, s = 0.0;
    for (int i = 0; i < N; i++) {
        e += (x[i] - xstar[i]) * (x[i] - xstar[i]);
        s += xstar[i] * xstar[i];
    }
    return sqrt(e / s);
}

/* Iterates from x (updated in place) until the residual is below tol
 * relative to |x*|; returns the evaluations of H, or -1 after max (or on a
 * scheme error); *worst gets the largest error seen. */
static int solve(struct coupling_accel *a, double *x, double tol, int max, double *worst)
{
    double out[N], next[N];
    struct mps_err err;
    *worst = 0.0;
    if (coupling_accel_begin(a, N, &err))
        return -1;
    for (int k = 1; k <= max; k++) {
        double r2 = 0.0, s2 = 0.0;
        for (int i = 0; i < N; i++) {
            out[i] = b[i];
            for (int j = 0; j < N; j++)
                out[i] += A[i][j] * x[j];
            r2 += (out[i] - x[i]) * (out[i] - x[i]);
            s2 += xstar[i] * xstar[i];
        }
        double e = rel_error(x);
        if (e > *worst)
            *worst = e;
        if (sqrt(r2 / s2) < tol) {
            memcpy(x, out, sizeof out);
            coupling_accel_end(a);
            return k;
        }
        if (coupling_accel_next(a, x, out, next, &err))
            return -1;
        memcpy(x, next, sizeof next);
    }
    coupling_accel_end(a);
    return -1;
}

static int run(const char *scheme, double omega, int reuse, double tol, int max, double *x,
               double *worst)
{
    struct coupling_accel *a = NULL;
    struct mps_err err;
    if (coupling_accel_create(&a, scheme, omega, reuse, 0.1, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -2;
    }
    int k = solve(a, x, tol, max, worst);
    coupling_accel_destroy(&a);
    return k;
}

int main(void)
{
    build(7u);
    set_fixed_point(0.0);
    const double tol = 1e-10;
    double x[N], worst;

    /* the plain iteration (constant, w = 1) diverges: the problem needs help */
    memset(x, 0, sizeof x);
    int k = run("constant", 1.0, 0, tol, 30, x, &worst);
    printf("  constant w = 1: %d (worst error %.3g)\n", k, worst);
    CHECK(k == -1 && worst > 1e6);

    /* a constant factor that damps the -6 mode converges, slowly: the factor
     * 1/7 leaves 1 - (1 - 0.5)/7 = 0.93 per iteration on the 0.5 mode */
    memset(x, 0, sizeof x);
    k = run("constant", 1.0 / 7.0, 0, tol, 2000, x, &worst);
    printf("  constant w = 1/7: %d iterations, error %.3g\n", k, rel_error(x));
    CHECK(k > 100 && k < 2000);
    CHECK(rel_error(x) < 1e-8);

    /* Aitken from w0 = 0.5 (which alone diverges: 1 - 0.5 * 7 = -2.5) */
    memset(x, 0, sizeof x);
    k = run("aitken", 0.5, 0, tol, 200, x, &worst);
    printf("  aitken: %d iterations, error %.3g\n", k, rel_error(x));
    CHECK(k > 0 && k <= 60);
    CHECK(rel_error(x) < 1e-8);

    /* IQN-ILS: a secant method on a linear map converges in about N + 1
     * evaluations (the least squares recover the inverse Jacobian on the
     * span of the differences) */
    memset(x, 0, sizeof x);
    k = run("iqn_ils", 0.5, 0, tol, 200, x, &worst);
    printf("  iqn_ils: %d iterations, error %.3g\n", k, rel_error(x));
    CHECK(k > 0 && k <= N + 4);
    CHECK(rel_error(x) < 1e-8);

    /* Reuse: a sequence of "time steps", b changing, A fixed. With the past
     * step's columns IQN-ILS knows the Jacobian and the second step is a few
     * evaluations; without them it starts over. */
    struct coupling_accel *a = NULL;
    struct mps_err err;
    int steps_reuse[3], steps_fresh[3];
    for (int pass = 0; pass < 2; pass++) {
        CHECK(coupling_accel_create(&a, "iqn_ils", 0.5, pass == 0 ? 2 : 0, 0.01, &err) == MPS_OK);
        memset(x, 0, sizeof x);
        for (int s = 0; s < 3; s++) {
            set_fixed_point(0.1 * (s + 1));
            int it = solve(a, x, tol, 200, &worst);
            (pass == 0 ? steps_reuse : steps_fresh)[s] = it;
            CHECK(it > 0 && rel_error(x) < 1e-8);
        }
        coupling_accel_destroy(&a);
    }
    printf("  iqn_ils over 3 steps: reuse 2: %d %d %d; reuse 0: %d %d %d\n", steps_reuse[0],
           steps_reuse[1], steps_reuse[2], steps_fresh[0], steps_fresh[1], steps_fresh[2]);
    CHECK(steps_reuse[1] <= 3 && steps_reuse[2] <= 3);
    CHECK(steps_fresh[1] > 2 * steps_reuse[1]);

    /* put/get between steps (checkpoints, docs/restart.md): a scheme read
     * back from the image of another after its first two steps must take
     * the third as that one does, bit for bit; without the image (a fresh
     * scheme) the third step differs, so the check can fail. IQN-ILS keeps
     * its columns for reuse 2 steps; Aitken its last factor. */
    const char *names[2] = {"iqn_ils", "aitken"};
    for (int m = 0; m < 2; m++) {
        struct coupling_accel *orig = NULL, *back = NULL, *fresh = NULL;
        struct mps_ckpt ck = {0};
        CHECK(coupling_accel_create(&orig, names[m], 0.5, 2, 0.01, &err) == MPS_OK);
        memset(x, 0, sizeof x);
        for (int s = 0; s < 2; s++) {
            set_fixed_point(0.1 * (s + 1));
            CHECK(solve(orig, x, 1e-6, 200, &worst) > 0);
        }
        CHECK(coupling_accel_put(orig, &ck, &err) == MPS_OK);
        CHECK(coupling_accel_create(&back, names[m], 0.5, 2, 0.01, &err) == MPS_OK);
        CHECK(coupling_accel_create(&fresh, names[m], 0.5, 2, 0.01, &err) == MPS_OK);
        CHECK(coupling_accel_get(back, &ck, &err) == MPS_OK);
        CHECK(coupling_accel_last(back) == coupling_accel_last(orig));
        set_fixed_point(0.3);
        double x0[N], xb[N], xf[N];
        memcpy(x0, x, sizeof x);
        memcpy(xb, x, sizeof x);
        memcpy(xf, x, sizeof x);
        int k0 = solve(orig, x0, 1e-6, 200, &worst);
        int kb = solve(back, xb, 1e-6, 200, &worst);
        int kf = solve(fresh, xf, 1e-6, 200, &worst);
        printf("  %s put/get after 2 steps: step 3 in %d iterations, restored %d, fresh %d\n",
               names[m], k0, kb, kf);
        CHECK(k0 > 0 && kb == k0 && memcmp(x0, xb, sizeof x0) == 0);
        CHECK(kf != k0 || memcmp(x0, xf, sizeof x0) != 0);
        /* another scheme or parameter is refused, naming both */
        struct coupling_accel *other = NULL;
        CHECK(coupling_accel_create(&other, names[m], 0.5, 3, 0.01, &err) == MPS_OK);
        mps_ckpt_rewind(&ck);
        CHECK(coupling_accel_get(other, &ck, &err) == MPS_EINPUT);
        CHECK(strstr(err.msg, "reuse 2") != NULL);
        coupling_accel_destroy(&other);
        coupling_accel_destroy(&orig);
        coupling_accel_destroy(&back);
        coupling_accel_destroy(&fresh);
        mps_ckpt_free(&ck);
    }

    /* input errors */
    CHECK(coupling_accel_create(&a, "newton", 0.5, 0, 0.1, &err) == MPS_EINPUT && !a);
    CHECK(strstr(err.msg, "aitken") != NULL);
    CHECK(coupling_accel_create(&a, "aitken", 0.0, 0, 0.1, &err) == MPS_EINPUT && !a);
    CHECK(coupling_accel_create(&a, "aitken", 1.5, 0, 0.1, &err) == MPS_EINPUT && !a);
    CHECK(coupling_accel_create(&a, "iqn_ils", 0.5, 0, 1.0, &err) == MPS_EINPUT && !a);

    /* Aitken's factor, known answer: on H(x) = lambda x + b (A = lambda I)
     * the residual's change is (lambda - 1) times the step, so the factor
     * -w r_(k-1).(r_k - r_(k-1)) / |r_k - r_(k-1)|^2 is 1 / (1 - lambda) at
     * the second evaluation, and x + w r is the fixed point: the third
     * evaluation finds a zero residual. A factor off by 10% leaves 10% of
     * the error there (and then converges at its own pace). */
    memset(A, 0, sizeof A);
    for (int i = 0; i < N; i++)
        A[i][i] = -6.0;
    set_fixed_point(0.3);
    memset(x, 0, sizeof x);
    k = run("aitken", 0.5, 0, 1e-12, 50, x, &worst);
    printf("  aitken on A = -6 I: %d evaluations, error %.3g\n", k, rel_error(x));
    CHECK(k == 3);
    CHECK(rel_error(x) < 1e-13);
    return test_summary("test_coupling_accel");
}
