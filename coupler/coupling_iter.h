/* The interface state of implicit coupling as a vector, between the STATE
 * messages of the solid and the acceleration schemes (coupling_accel.h);
 * no sockets, so it is tested alone.
 *
 * The unknown of a coupling step is where the solid's interface particles
 * (surface and near-surface, in the order of the solid's READY) are at the
 * step's end: the vector of their positions x. The fluid is given those
 * positions and, as their velocity, the mean over the step,
 * (x - x_start) / dt: the boundary then moves consistently over the step.
 * Why not the solid's end-of-step velocities, as the explicit scheme sends:
 * they carry the particle-scale vibration of a particle solid. On the light
 * plate (rho_s = 100, 6 mm, to 0.4 s) their rms change between iterations
 * was 1-2 m/s, ten times the tip's speed; iterated on with the positions
 * (same factor or coefficients), Aitken needed 3.4 iterations per step
 * against 2.05 with the mean velocity, and IQN-ILS sent the plate away until
 * the fluid failed, with or without reused columns.
 *
 * Convergence (coupling.implicit.tolerance, abs_tolerance): the step has
 * converged when the positions the solid returned differ from those the
 * fluid was given by at most tol times the interface's displacement over the
 * step plus atol dt (atol a velocity), both as root mean squares over the
 * interface particles: rms|x_k - x~_k| <= tol rms|x_k - x_start| + atol dt.
 * (The displacement from the initial positions, rms|x_k - x_0|, is measured
 * and logged, not tested: docs/coupling.md says why.)
 *
 * The first input of a step is the linear extrapolation of the positions at
 * the last two steps' starts, x_n + (x_n - x_(n-1)) dt_n / dt_(n-1) (the
 * first step: x_0 + v_0 dt). It saves iterations: on the standard plate
 * (6 mm, to 1 s) 1.16 per step against 1.48 starting from the solid's state
 * at the step's start. Or, with coupling.implicit.predictor: solid (the
 * default), the positions the solid reaches over the step under the last
 * step's loads (coupling_iter_predicted): the extrapolation carries the
 * error the last step was accepted with and misses the solid's own
 * acceleration; the solid's prediction misses only the change of the loads,
 * but where the structure is much lighter than the fluid it moves, that
 * change is large: alone under the last loads, without the fluid's added
 * mass, the solid overshoots (the explicit scheme's instability). So the
 * first input is the extrapolation e moved towards the prediction p by a
 * weight w fitted to the past steps: after each step, w minimises
 * sum lambda^age |e + w (p - e) - x|^2 over the steps' accepted answers x
 * (lambda = 0.9, w in [0, 1]; 1 before any step has been fitted).
 * Fluid advances per step, with the extrapolation / the prediction alone /
 * this blend: the 6 mm plate to 0.5 s 1.56 / 1.05 / 1.05; a plate a
 * hundredth as heavy as the water 6.45 / 8.42 / 6.08; the high sloshing at
 * 1 mm over 0-0.3 s 1.92 / 1.89 / 1.50 (docs/coupling.md). */
#ifndef COUPLING_ITER_H
#define COUPLING_ITER_H

#include <stddef.h>

#include "coupling_accel.h"
#include "mps_ckpt.h"
#include "mps_dim.h"
#include "mps_err.h"
#include "proto_msg.h"

struct coupling_iter {
    size_t n;                       /* interface particles */
    int *id;                        /* in READY's order */
    unsigned char *surface, *fixed;
    double (*x0)[MPS_DIM];          /* READY's positions: the displacement reference */
    double tol, atol;               /* convergence, see above */
    double (*x_start)[MPS_DIM];     /* at this step's start */
    double (*x_prev)[MPS_DIM];      /* at the last step's start (predictor) */
    double dt, dt_prev;             /* this step's length, the last one's (0: none) */
    double *in, *out, *next;        /* vectors of MPS_DIM n: positions */
    double *best;                   /* the step's input with the smallest change so far */
    /* the solid predictor's blend (coupling_iter_predicted): this step's
     * extrapolation and prediction, and the fitted weight of the prediction */
    double *pred_e, *pred_p;
    int have_pred;
    double s_pp, s_pr, w;
    double best_change;             /* its rms change (m); INFINITY: none yet */
    int best_k, last_k;             /* their iterations (0-based) */
    double (*x_send)[MPS_DIM], (*v_send)[MPS_DIM];
    /* the last iteration's measures (m): rms|x_k - x~_k|, rms|x_k - x_0|,
     * rms|x_k - x_start| */
    double change, displacement, increment;
};

/* From the solid's READY (its STATE payload: ids, order, flags and reference
 * positions). tol > 0, atol >= 0 (m). */
enum mps_status coupling_iter_init(struct coupling_iter *it, const struct proto_msg *ready,
                                   double tol, double atol, struct mps_err *err);
void coupling_iter_free(struct coupling_iter *it);

/* A step of dt starts from the solid's state now (the last RESULT): fills
 * send (a STATE message whose arrays live in it) with the first input. */
enum mps_status coupling_iter_start(struct coupling_iter *it, const struct proto_msg *now,
                                    double dt, struct proto_msg *send, struct mps_err *err);

/* After coupling_iter_start, the first input (the extrapolation) moved
 * towards the interface of pred, a STATE of the solid advanced alone over
 * the step (the same interface as READY's), by the fitted weight; clamped
 * particles are kept where they are. */
enum mps_status coupling_iter_predicted(struct coupling_iter *it, const struct proto_msg *pred,
                                        struct proto_msg *send, struct mps_err *err);

/* After a step's last iteration (its answer in out): with a prediction in
 * the step, refits the weight of the next ones. */
void coupling_iter_accept(struct coupling_iter *it);

/* The solid's RESULT of the iteration: checks that it is the same interface
 * (ids in READY's order: a solid whose interface changes size within an
 * implicit run is refused), and sets *converged. */
enum mps_status coupling_iter_result(struct coupling_iter *it, const struct proto_msg *res,
                                     int *converged, struct mps_err *err);

/* The next input, from the acceleration scheme, into send. */
enum mps_status coupling_iter_relax(struct coupling_iter *it, struct coupling_accel *a,
                                    struct proto_msg *send, struct mps_err *err);

/* After max iterations without convergence: if an earlier input of the
 * step gave a smaller change than the last, puts it into send and returns
 * 1 (the coupler repeats it, which gives that iteration's answer again, bit
 * for bit, and accepts it); 0 if the last was the best. */
int coupling_iter_best(struct coupling_iter *it, struct proto_msg *send);

/* Between steps, what the next steps depend on, as checkpoint blocks
 * "iter" (particles, the last step's length), "iter.id", "iter.x0" (the
 * displacement reference: after a restart READY reports the positions then,
 * not the initial ones) and "iter.x_prev" (the predictor's last step start).
 * get reads them into it after coupling_iter_init from the restarted
 * solid's READY, which must list the same interface (MPS_EINPUT if not). */
enum mps_status coupling_iter_put(const struct coupling_iter *it, struct mps_ckpt *ck,
                                  struct mps_err *err);
enum mps_status coupling_iter_get(struct coupling_iter *it, struct mps_ckpt *ck,
                                  struct mps_err *err);

/* Vector length, for coupling_accel_begin. */
size_t coupling_iter_len(const struct coupling_iter *it);

#endif
