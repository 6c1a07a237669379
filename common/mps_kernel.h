/* The MPS weight function (Eq. 7) and the constants derived from the initial
 * lattice: n0 (Eq. 8), N0 (neighbour count) and lambda (Eq. 13). */
#ifndef MPS_KERNEL_H
#define MPS_KERNEL_H

#include <math.h>
#include <stddef.h>

#include "mps_dim.h"

/* Eq. 7: w(r) = re/r - 1 for 0 < r <= re, else 0. */
static inline double mps_weight(double r, double re)
{
    return (r > 0.0 && r < re) ? re / r - 1.0 : 0.0;
}

/* Eq. 7 from the squared distance, without a branch: max(re/r - 1, 0) is
 * re/r - 1 inside re and 0 outside, and r = 0 maps to r = inf (w = 0, as
 * mps_weight). Neighbour loops visit a skin list of which about a third
 * lies beyond re, in no order a branch predictor could learn. */
static inline double mps_weight_r2(double r2, double re)
{
    double w = re / sqrt(r2 > 0.0 ? r2 : INFINITY) - 1.0;
    return 0.5 * (w + fabs(w)); /* max(w, 0), exact, and compiled without a jump */
}

/* The pair factor w(r) / r^2 of Eq. 10 and of the gradients (Eq. 9, 14-15)
 * for a pair closer than r_floor (r2 < r_floor^2, r2 > 0): w(r_floor) /
 * (r_floor r), the pair read at r_floor in its own direction (dx / r) and at
 * its own speed or pressure difference. The callers keep their own
 * arithmetic for the pairs outside, so a run without such a pair is the same
 * to the bit with or without the floor. Why: w / r^2 grows as 1 / r^3; in
 * Eq. 10 the pressure that answers one close pair's approach throws it apart
 * (docs/pressure.md, "Pairs closer than half a spacing"), in the gradient a
 * few pascals across a pair at 0.02 dp throw it apart at metres per second
 * (docs/hard_cases.md, section 4). */
static inline double mps_divergence_floor_factor(double r2, double re, double r_floor)
{
    return (re / r_floor - 1.0) / (r_floor * sqrt(r2));
}

/* mps_weight_r2 of n squared distances, in place, times scale. Kept apart
 * from the loops that gather the distances so that it runs over contiguous
 * values, packed: one at a time, the square roots and divisions bound a
 * neighbour loop (about 10 cycles a candidate). Eight at a time with
 * mps_weight8_r2 where mps_simd_wide() (within a few units in the last
 * place), else SSE2 with the same bits as mps_weight_r2. Intrinsics,
 * because the compiler vectorises the plain loop only without errno from
 * sqrt (-fno-math-errno), and that flag made the scalar square roots
 * elsewhere 6-7% slower (3.5 mm dam break, 2 threads). */
void mps_weights_r2(double *restrict w, size_t n, double re, double scale);

/* The two paths of mps_weights_r2, for tests. mps_weights_r2_wide returns 0
 * and does nothing when mps_simd_wide() is 0. */
void mps_weights_r2_sse2(double *restrict w, size_t n, double re, double scale);
int mps_weights_r2_wide(double *restrict w, size_t n, double re, double scale);

/* Neighbour loops that call mps_weights_r2 take their list in chunks of this
 * many candidates, with stack buffers of this size. */
#define MPS_WEIGHT_CHUNK 128

/* The smooth weight (1 - r/re)^2 for 0 <= r < re, the particle itself
 * included (w(0) = 1), that fluid.density_weight = quadratic uses for Eq.
 * 23's density error. Eq. 7's weight is convex (re/r - 1 grows without
 * bound as r -> 0), so a disordered lattice has a higher number density than
 * an ordered one at the same area (+3.3% for a lattice jittered by 0.1 dp):
 * a correction that holds it at n0 expands water that loses its order. The
 * quadratic weight is nearly flat in that sense (+1.0%), yet still peaked
 * at r = 0, so a closing pair still raises it (a weight with a flat top,
 * as the cubic spline, let still water pair up within 0.5 s at 0.2 ms
 * steps). docs/pressure.md, "Still water, 10 s". */
static inline double mps_weight_quadratic(double r, double re)
{
    double q = 1.0 - r / re;
    return (r >= 0.0 && q > 0.0) ? q * q : 0.0;
}

struct mps_lattice_consts {
    double n0;       /* Eq. 8 on the full square lattice */
    double lambda;   /* Eq. 13, m^2 */
    double nq0;      /* the sum of mps_weight_quadratic, the particle itself included:
                      * the reference of mps_ops_number_density_quadratic */
    int count;       /* neighbours inside re (N0 of the free-surface check) */
};

/* Lattice points at lo + (i + 1/2) dp inside [lo, hi]: how many a body, a
 * water block or a wall fills, whole spacings only (the tolerance absorbs
 * decimal round-off: 0.584 / 0.004 gives 146, 0.304 / 0.0008 gives 380).
 * One count for the solvers and the coupler's check of the layout
 * (coupler/scene_check.h), so the check reads what the solvers build. */
static inline long mps_lattice_count(double lo, double hi, double dp)
{
    double n = floor((hi - lo) / dp + 1e-6);
    /* capped so the conversion stays defined; the memory checks refuse
     * such a scene anyway */
    return n > 0 ? (long)fmin(n, 1e15) : 0;
}

/* Constants for a particle inside a full square lattice of spacing l0, with
 * effective radius re (both in m). */
struct mps_lattice_consts mps_lattice_consts(double l0, double re);

/* How fast sum_j -w'(r_ij) e_ij (the particle shifting's gradient) grows as
 * the middle particle of a full square lattice moves off its site, per metre
 * of its displacement: w = mps_weight, or mps_weight_quadratic if smooth. */
double mps_lattice_gradient_response(double l0, double re, int smooth);

#endif
