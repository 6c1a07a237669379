/* The implicit coupling's interface vector (coupler/coupling_iter.h): what
 * the fluid is sent (positions and the step's mean velocity), the predictors
 * (extrapolated, or the solid's own),
 * the convergence test on the step's displacement, clamped particles, the
 * best iterate, and the refusal of an interface that changes. */
#include <math.h>
#include <string.h>

#include "coupling_iter.h"
#include "test_util.h"

#define N 3

static int ids[N] = {4, 7, 9};
static unsigned char surf[N] = {1, 1, 0}, fixd[N] = {0, 0, 1};

static struct proto_msg state(double (*x)[2], double (*v)[2])
{
    struct proto_msg m = proto_msg_make(PROTO_RESULT);
    m.payload = PROTO_STATE;
    m.count = N;
    m.id = ids;
    m.x = (const double(*)[2])x;
    m.v = (const double(*)[2])v;
    m.surface = surf;
    m.fixed = fixd;
    return m;
}

int main(void)
{
    struct mps_err err;
    struct coupling_iter it;
    double x0[N][2] = {{0, 0}, {0, 1}, {0, -1}}, v0[N][2] = {{1, 0}, {1, 0}, {0, 0}};
    struct proto_msg ready = state(x0, v0);
    CHECK(coupling_iter_init(&it, &ready, 0.1, 1e-4, &err) == MPS_OK);
    CHECK(coupling_iter_len(&it) == 2 * N);

    /* step 1 (no history): x0 + v0 dt; the fluid sees the mean velocity v0,
     * the clamped particle stays */
    struct proto_msg send;
    const double dt = 0.01;
    CHECK(coupling_iter_start(&it, &ready, dt, &send, &err) == MPS_OK);
    CHECK(send.count == N && send.id[1] == 7 && send.fixed[2] == 1);
    CHECK_NEAR(send.x[0][0], 0.01, 1e-15);
    CHECK_NEAR(send.v[0][0], 1.0, 1e-12);
    CHECK(send.x[2][0] == 0.0 && send.v[2][0] == 0.0 && send.x[2][1] == -1.0);

    /* the solid answers exactly the prediction: converged (change 0) */
    double x1[N][2] = {{0.01, 0}, {0.01, 1}, {0, -1}}, v1[N][2] = {{1, 0}, {1, 0}, {0, 0}};
    struct proto_msg r1 = state(x1, v1);
    int conv = 0;
    CHECK(coupling_iter_result(&it, &r1, &conv, &err) == MPS_OK && conv);
    CHECK_NEAR(it.increment, sqrt(2 * 0.01 * 0.01 / 3), 1e-15);

    /* step 2: linear prediction from the starts x0 -> x1 over dt, here a step
     * of dt / 2: x1 + (x1 - x0) / 2 */
    CHECK(coupling_iter_start(&it, &r1, 0.5 * dt, &send, &err) == MPS_OK);
    CHECK_NEAR(send.x[0][0], 0.015, 1e-15);
    CHECK_NEAR(send.v[0][0], 1.0, 1e-12);   /* (0.015 - 0.01) / 0.005 */
    /* an answer 20% of the step's displacement away is not converged at 0.1 */
    double x2[N][2] = {{0.016, 0}, {0.016, 1}, {0, -1}};
    struct proto_msg r2 = state(x2, v1);
    CHECK(coupling_iter_result(&it, &r2, &conv, &err) == MPS_OK && !conv);
    CHECK_NEAR(it.change, sqrt(2 * 0.001 * 0.001 / 3), 1e-15);

    /* the next iterate (constant relaxation 0.5) halves the gap; the clamped
     * particle is where the solid has it */
    struct coupling_accel *a = NULL;
    CHECK(coupling_accel_create(&a, "constant", 0.5, 0, 0.1, &err) == MPS_OK);
    CHECK(coupling_accel_begin(a, coupling_iter_len(&it), &err) == MPS_OK);
    CHECK(coupling_iter_relax(&it, a, &send, &err) == MPS_OK);
    CHECK_NEAR(send.x[0][0], 0.0155, 1e-15);
    CHECK_NEAR(send.v[0][0], 0.0055 / 0.005, 1e-12);
    CHECK(send.x[2][0] == 0.0 && send.x[2][1] == -1.0);

    /* a worse answer: the best input so far is the first one (0.015) */
    double x3[N][2] = {{0.0175, 0}, {0.0175, 1}, {0, -1}};
    struct proto_msg r3 = state(x3, v1);
    CHECK(coupling_iter_result(&it, &r3, &conv, &err) == MPS_OK && !conv);
    CHECK(coupling_iter_best(&it, &send) == 1);
    CHECK_NEAR(send.x[0][0], 0.015, 1e-15);
    /* its answer again: now the last is the best, nothing to repeat */
    CHECK(coupling_iter_result(&it, &r2, &conv, &err) == MPS_OK);
    CHECK(coupling_iter_best(&it, &send) == 0);

    /* the solid's prediction replaces the first input: its positions, the
     * mean velocity from the step's start, the clamped particle where it
     * was (the prediction moves it: ignored); the x_prev the next
     * extrapolation would use stays the step's start */
    double xp[N][2] = {{0.013, 0.001}, {0.012, 1}, {0.5, -1}};
    struct proto_msg pred = state(xp, v1);
    CHECK(coupling_iter_start(&it, &r2, dt, &send, &err) == MPS_OK);
    CHECK(coupling_iter_predicted(&it, &pred, &send, &err) == MPS_OK);
    CHECK(send.x[0][0] == 0.013 && send.x[0][1] == 0.001 && send.x[1][0] == 0.012);
    CHECK_NEAR(send.v[0][0], (0.013 - 0.016) / dt, 1e-12);
    CHECK_NEAR(send.v[0][1], 0.001 / dt, 1e-12);
    CHECK(send.x[2][0] == 0.0 && send.v[2][0] == 0.0);
    CHECK(it.x_prev[0][0] == 0.016);
    /* the answer equal to the prediction converges */
    struct proto_msg rp = state(xp, v1);
    double xq[N][2] = {{0.013, 0.001}, {0.012, 1}, {0, -1}};
    rp.x = (const double(*)[2])xq;
    CHECK(coupling_iter_result(&it, &rp, &conv, &err) == MPS_OK && conv && it.change == 0.0);
    /* the weight (coupling_iter_accept): 1 before any fit. Three steps from
     * the state rest0 (the interface at rest: the extrapolation e = rest0),
     * the prediction moving particle 0 by +4 mm in x, the answers at e + 2,
     * e + 20 and e - 500 mm: w = (sum of d.r, decayed) / (sum of d.d,
     * decayed), clamped to [0, 1] */
    {
        CHECK(it.w == 1.0);
        double r0[N][2] = {{0.1, 0.0}, {0.1, 1.0}, {0.0, -1.0}}, still0[N][2] = {{0}};
        struct proto_msg rest0 = state(r0, still0);
        const double shift[3] = {0.002, 0.02, -0.5};
        double w_want[3], spp = 0.0, spr = 0.0;
        for (int s3 = 0; s3 < 3; s3++) {
            it.dt_prev = 0.0;  /* no history: e = rest0 + 0 dt */
            CHECK(coupling_iter_start(&it, &rest0, dt, &send, &err) == MPS_OK);
            CHECK(send.x[0][0] == 0.1);
            double pxs[N][2] = {{0.104, 0.0}, {0.1, 1.0}, {0.0, -1.0}};
            struct proto_msg pp = state(pxs, still0);
            double w_before = it.w;
            CHECK(coupling_iter_predicted(&it, &pp, &send, &err) == MPS_OK);
            CHECK_NEAR(send.x[0][0], 0.1 + w_before * 0.004, 1e-15);
            double ans[N][2] = {{0.1 + shift[s3], 0.0}, {0.1, 1.0}, {0.0, -1.0}};
            struct proto_msg ra = state(ans, still0);
            CHECK(coupling_iter_result(&it, &ra, &conv, &err) == MPS_OK);
            coupling_iter_accept(&it);
            spp = 0.9 * spp + 0.004 * 0.004;
            spr = 0.9 * spr + 0.004 * shift[s3];
            w_want[s3] = spr / spp < 0.0 ? 0.0 : spr / spp > 1.0 ? 1.0 : spr / spp;
            CHECK_NEAR(it.w, w_want[s3], 1e-12);
        }
        CHECK_NEAR(w_want[0], 0.5, 1e-12);
        CHECK(w_want[1] == 1.0 && w_want[2] == 0.0);
        /* a step without a prediction leaves the weight as it is */
        CHECK(coupling_iter_start(&it, &rest0, dt, &send, &err) == MPS_OK);
        CHECK(coupling_iter_result(&it, &rest0, &conv, &err) == MPS_OK);
        coupling_iter_accept(&it);
        CHECK(it.w == 0.0);
        it.w = 1.0;
        it.s_pp = it.s_pr = 0.0;
    }

    /* a prediction of another interface is refused */
    int swapped[N] = {7, 4, 9};
    pred.id = swapped;
    CHECK(coupling_iter_predicted(&it, &pred, &send, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "id 7") != NULL);

    /* absolute tolerance, for an interface at rest: a velocity error of
     * 0.5e-4 m/s converges at 1e-4 m/s, 2e-4 m/s does not */
    coupling_iter_free(&it);
    double still[N][2] = {{0}};
    struct proto_msg rest = state(x0, still);
    CHECK(coupling_iter_init(&it, &rest, 0.1, 1e-4, &err) == MPS_OK);
    for (int pass = 0; pass < 2; pass++) {
        CHECK(coupling_iter_start(&it, &rest, dt, &send, &err) == MPS_OK);
        double x4[N][2];
        memcpy(x4, x0, sizeof x4);
        x4[0][0] += (pass ? 2e-4 : 0.5e-4) * dt;
        struct proto_msg r4 = state(x4, still);
        it.dt_prev = 0.0; /* no history: the prediction is the rest state */
        CHECK(coupling_iter_result(&it, &r4, &conv, &err) == MPS_OK && conv == !pass);
    }

    /* the relative test's edge: particles 0 and 1 answer delta beyond the
     * first input x0 + v0 dt (so the step's increment is dt + delta for
     * them, the change delta); converged iff
     * delta <= (tol dt + atol dt / sqrt(2/3)) / (1 - tol), both RMS over
     * the 3 particles. 1% on either side of that edge */
    coupling_iter_free(&it);
    CHECK(coupling_iter_init(&it, &ready, 0.1, 1e-4, &err) == MPS_OK);
    const double edge = (0.1 * 0.01 + 1e-4 * dt / sqrt(2.0 / 3.0)) / (1.0 - 0.1);
    for (int pass = 0; pass < 2; pass++) {
        it.dt_prev = 0.0; /* no history: x0 + v0 dt */
        CHECK(coupling_iter_start(&it, &ready, dt, &send, &err) == MPS_OK);
        CHECK_NEAR(send.x[0][0], 0.01, 1e-15);
        const double delta = (pass ? 1.01 : 0.99) * edge;
        double x5[N][2] = {{0.01 + delta, 0}, {0.01 + delta, 1}, {0, -1}};
        struct proto_msg r5 = state(x5, v1);
        CHECK(coupling_iter_result(&it, &r5, &conv, &err) == MPS_OK && conv == !pass);
    }

    /* another interface (fracture): refused with a message */
    int other[N] = {4, 8, 9};
    struct proto_msg bad = state(x1, v1);
    bad.id = other;
    CHECK(coupling_iter_result(&it, &bad, &conv, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "id 8") != NULL);
    bad.id = ids;
    bad.count = N - 1;
    CHECK(coupling_iter_start(&it, &bad, dt, &send, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "fracture") != NULL);

    /* put/get (checkpoints, docs/restart.md): after a restart READY reports
     * the positions then (x1); with the image the next step predicts as the
     * uninterrupted run does (x1 + (x1 - x0) over a step of dt) and measures
     * displacement from x0, not from x1 */
    coupling_iter_free(&it);
    struct coupling_iter run, back;
    struct mps_ckpt ck = {0};
    CHECK(coupling_iter_init(&run, &ready, 0.1, 1e-4, &err) == MPS_OK);
    CHECK(coupling_iter_start(&run, &ready, dt, &send, &err) == MPS_OK);
    run.w = 0.3; /* the prediction's weight and its sums come back too */
    run.s_pp = 2.5e-6;
    run.s_pr = 0.75e-6;
    CHECK(coupling_iter_put(&run, &ck, &err) == MPS_OK);
    CHECK(coupling_iter_init(&back, &r1, 0.1, 1e-4, &err) == MPS_OK);
    CHECK(back.w == 1.0);
    CHECK(coupling_iter_get(&back, &ck, &err) == MPS_OK);
    CHECK(back.w == 0.3 && back.s_pp == 2.5e-6 && back.s_pr == 0.75e-6);
    /* (the velocity reported at the restart, zero here, is not what the
     * step's prediction takes: only the first step uses one) */
    struct proto_msg send_b, r1s = state(x1, still);
    CHECK(coupling_iter_start(&run, &r1s, dt, &send, &err) == MPS_OK);
    CHECK(coupling_iter_start(&back, &r1s, dt, &send_b, &err) == MPS_OK);
    CHECK_NEAR(send.x[0][0], 0.02, 1e-15);
    CHECK(memcmp(send.x, send_b.x, sizeof x1) == 0 && memcmp(send.v, send_b.v, sizeof x1) == 0);
    CHECK(coupling_iter_result(&run, &r2, &conv, &err) == MPS_OK);
    CHECK(coupling_iter_result(&back, &r2, &conv, &err) == MPS_OK);
    CHECK(run.displacement == back.displacement && run.change == back.change);
    CHECK_NEAR(back.displacement, sqrt(2 * 0.016 * 0.016 / 3), 1e-15);
    /* the image of another interface is refused */
    coupling_iter_free(&back);
    struct proto_msg moved = state(x1, v1);
    int renamed[N] = {4, 7, 10};
    moved.id = renamed;
    CHECK(coupling_iter_init(&back, &moved, 0.1, 1e-4, &err) == MPS_OK);
    mps_ckpt_rewind(&ck);
    CHECK(coupling_iter_get(&back, &ck, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "other ids") != NULL);
    coupling_iter_free(&back);
    coupling_iter_free(&run);
    mps_ckpt_free(&ck);

    coupling_accel_destroy(&a);
    return test_summary("test_coupling_iter");
}
