/* Acceleration of the implicit coupling's fixed-point iteration
 * (docs/coupling.md, "Implicit coupling").
 *
 * Over one coupling step the coupler looks for the interface state s with
 * s = H(s), H = S o F: the fluid F steps with the solid boundary at s and
 * gives loads, the solid S steps from its checkpoint under them and gives a
 * state. Iteration k sends an input x~_k, gets the output x_k = H(x~_k) and
 * the residual r_k = x_k - x~_k; a scheme then chooses x~_(k+1):
 *   constant   x~_(k+1) = x~_k + w r_k, w fixed;
 *   aitken     the same with Aitken's dynamic factor (Irons & Tuck 1969;
 *              Kuettler & Wall 2008): w_k = -w_(k-1) r_(k-1).(r_k - r_(k-1))
 *              / |r_k - r_(k-1)|^2; w_0 is the last step's final factor when
 *              that is in (0, 1], else the initial factor;
 *   iqn_ils    interface quasi-Newton with an inverse Jacobian from least
 *              squares (Degroote et al. 2009): with V the differences of
 *              successive residuals and W those of successive outputs (this
 *              step's, and those of the last `reuse` steps), c minimises
 *              |V c + r_k| and x~_(k+1) = x_k + W c; a step's first
 *              iteration with no columns relaxes with the initial factor.
 * Vectors are plain doubles of one length n per step (the coupler packs
 * the positions of the interface particles, coupling_iter.h). The module
 * keeps no pointer to the caller's arrays. */
#ifndef COUPLING_ACCEL_H
#define COUPLING_ACCEL_H

#include <stddef.h>

#include "mps_ckpt.h"
#include "mps_err.h"

struct coupling_accel;

/* name: "constant", "aitken" or "iqn_ils" (coupling_accel_names()); omega:
 * the initial (or constant) relaxation factor, in (0, 1]; reuse: iqn_ils
 * keeps the columns of this many past steps (0: only the current step's);
 * filter: iqn_ils drops a column whose part orthogonal to the newer ones is
 * shorter than this fraction of it, in [0, 1) (the QR2 filter of
 * Haelterman et al. 2016). */
enum mps_status coupling_accel_create(struct coupling_accel **out, const char *name,
                                      double omega, int reuse, double filter,
                                      struct mps_err *err);
void coupling_accel_destroy(struct coupling_accel **a);

/* "constant, aitken, iqn_ils", for messages. */
const char *coupling_accel_names(void);
const char *coupling_accel_name(const struct coupling_accel *a);

/* A coupling step starts: its vectors have n > 0 entries (past columns of
 * another length are dropped). */
enum mps_status coupling_accel_begin(struct coupling_accel *a, size_t n, struct mps_err *err);

/* After iteration k of the step: in = x~_k (what was sent), out = x_k =
 * H(x~_k); writes x~_(k+1) into next (n entries; may not alias in or out). */
enum mps_status coupling_accel_next(struct coupling_accel *a, const double *in,
                                    const double *out, double *next, struct mps_err *err);

/* The step ended (converged or accepted): iqn_ils keeps its columns for the
 * next `reuse` steps. */
void coupling_accel_end(struct coupling_accel *a);

/* Between steps (after coupling_accel_end), what the next steps depend on,
 * as checkpoint blocks "accel" (scheme, parameters, Aitken's factor in use,
 * vector length), "accel.age", "accel.V", "accel.W" (iqn_ils's kept
 * columns: variable size, empty for the other schemes). get reads them into
 * an accel created with the same scheme and parameters (MPS_EINPUT naming
 * the one that differs); the next step then chooses what it would have
 * chosen without the checkpoint, bit for bit (docs/restart.md). */
enum mps_status coupling_accel_put(const struct coupling_accel *a, struct mps_ckpt *ck,
                                   struct mps_err *err);
enum mps_status coupling_accel_get(struct coupling_accel *a, struct mps_ckpt *ck,
                                   struct mps_err *err);

/* The relaxation factor of the last update (constant, aitken); for iqn_ils
 * the number of columns it used. For summaries. */
double coupling_accel_last(const struct coupling_accel *a);

#endif
