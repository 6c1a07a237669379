/* The interface state of implicit coupling as a vector, between the STATE
 * messages of the solid and the acceleration schemes (coupling_accel.h);
 * no sockets, so it is tested alone.
 *
 * The unknown of a coupling step is the solid's interface at the step's end,
 * s = (x, v) of every interface particle (surface and near-surface, in the
 * order of the solid's READY). The vector holds x and v dt (m, both): over a
 * step a velocity error dv moves the boundary by about dv dt, so both parts
 * weigh in the schemes' dot products by what they do to the fluid.
 *
 * Convergence (coupling.implicit.tolerance, abs_tolerance): the step has
 * converged when the positions the solid returned differ from those the
 * fluid was given by at most tol times the interface's displacement from its
 * initial positions plus atol, both as root mean squares over the interface
 * particles: rms|x_k - x~_k| <= tol rms|x_k - x_0| + atol.
 *
 * The first input of a step is the solid's state at the step's start (the
 * weak coupling's choice: the first iteration is then the explicit step), or
 * with the linear predictor its extrapolation to the step's end from the
 * last two steps' starts, s_n + (s_n - s_(n-1)) dt_n / dt_(n-1). */
#ifndef COUPLING_ITER_H
#define COUPLING_ITER_H

#include <stddef.h>

#include "coupling_accel.h"
#include "mps_dim.h"
#include "mps_err.h"
#include "proto_msg.h"

struct coupling_iter {
    size_t n;                       /* interface particles */
    int *id;                        /* in READY's order */
    unsigned char *surface, *fixed;
    double (*x0)[MPS_DIM];          /* READY's positions: the displacement reference */
    double tol, atol;               /* convergence, see above */
    int predictor;                  /* 1: linear */
    /* the state at the last step's start and that step's length (predictor) */
    double (*x_last)[MPS_DIM], (*v_last)[MPS_DIM];
    double dt_last;
    int have_last;
    double dt;                      /* this step's */
    double *in, *out, *next;        /* vectors of 2 MPS_DIM n: x, then v dt */
    double (*x_send)[MPS_DIM], (*v_send)[MPS_DIM];
    /* the last iteration's measure: rms|x_k - x~_k|, rms|x_k - x_0| (m) */
    double change, displacement;
};

/* From the solid's READY (its STATE payload: ids, order, flags and reference
 * positions). tol > 0, atol >= 0 (m); predictor: 0 none, 1 linear. */
enum mps_status coupling_iter_init(struct coupling_iter *it, const struct proto_msg *ready,
                                   double tol, double atol, int predictor, struct mps_err *err);
void coupling_iter_free(struct coupling_iter *it);

/* A step of dt starts from the solid's state now (the last RESULT): fills
 * send (a STATE message whose arrays live in it) with the first input. */
enum mps_status coupling_iter_start(struct coupling_iter *it, const struct proto_msg *now,
                                    double dt, struct proto_msg *send, struct mps_err *err);

/* The solid's RESULT of the iteration: checks that it is the same interface
 * (ids in READY's order: a solid whose interface changes size within an
 * implicit run is refused), and sets *converged. */
enum mps_status coupling_iter_result(struct coupling_iter *it, const struct proto_msg *res,
                                     int *converged, struct mps_err *err);

/* The next input, from the acceleration scheme, into send. */
enum mps_status coupling_iter_relax(struct coupling_iter *it, struct coupling_accel *a,
                                    struct proto_msg *send, struct mps_err *err);

/* Vector length, for coupling_accel_begin. */
size_t coupling_iter_len(const struct coupling_iter *it);

#endif
