/* Total-Lagrangian SPH elastic solid (second paper, section 2-2, Eq. 12; Lin et
 * al. 2015): every quantity is a sum over the neighbours a particle had at
 * creation, with kernel gradients taken in the reference configuration X, so
 * no neighbour search runs while stepping.
 *
 * Kernel: Wendland C2, h = SOLID_TLSPH_HDP dp, support 2h, G_ij = grad_i W at
 * X_i - X_j, i.e. G_ij = |W'(R)| X_ij / R with X_ij = X_j - X_i, R = |X_ij|.
 * Per particle (V = dp^2 per metre depth, x_ij = x_j - x_i):
 *   L_i = (sum_j V_j G_ij (x) X_ij)^-1          correction: exact for linear fields
 *   F_i = sum_j V_j x_ij (x) L_i G_ij             deformation gradient
 *   E = (F^T F - I)/2, S = lambda tr(E) I + 2 mu E, P = F S   (St Venant-Kirchhoff)
 * and per pair, with w_ij = V_j |W'(R)| / R:
 *   rho0 dv_i/dt = sum_j V_j (P_i L_i G_ij - P_j L_j G_ji)    Eq. 12, stress
 *        + rho0 alpha c_p h sum_j w_ij (v_ji . x_ij) x_ij / R^2   viscosity
 *        + k_hg E sum_j w_ij (2 x_ij - (F_i + F_j) X_ij)          hourglass
 *        + rho0 g + f_load / V
 * The stress term is minus the gradient of U = sum_i V_i Psi(F_i). Since
 * G_ij is parallel to X_ij, F_i is the least-squares fit of x_ij ~ F X_ij with
 * weights w_ij; the hourglass term is minus the gradient of
 * U_hg = sum_i (k_hg E V_i / 2) sum_j w_ij |x_ij - F_i X_ij|^2, the residual of
 * that fit (the fit's optimality makes dU_hg/dF_i = 0, so the force is just the
 * pair sum). It is zero for any affine motion (patch tests, rigid motion) and
 * penalises the zero-energy modes of particle integration (checkerboard and
 * column zig-zag: their neighbour sums cancel, F does not see them), after
 * Ganzenmueller (2015), made energy-consistent. Pair terms are antisymmetric
 * (linear momentum exact) and U, U_hg are rotation invariant (angular
 * momentum); the viscosity is a central pair damper (Monaghan's linear term
 * on the reference distance) that vanishes for rigid motion.
 *
 * Update: symplectic Euler, v then x (as solid_mps); it keeps linear and
 * angular momentum to round-off (test_tlsph_conservation).
 *
 * Stable step: dt = C h / ((1 + 0.6 alpha) c_p + |v|max), c_p =
 * sqrt((lambda + 2 mu)/rho0): the CFL step of the P wave, with the explicit
 * viscous term added to the speed in the form of Monaghan's (1992) condition
 * (his coefficient is 1.2; 0.6 is measured for this operator). Measured limit
 * of C (test_tlsph_stability, small random velocities): 1.09-1.21 at alpha = 1
 * for bodies 3 or more particles thick, nu from -0.5 to 0.49, 0.99 for a strip
 * 2 particles thick; 1.01-1.17 for alpha from 0.5 to 2. Without viscosity
 * (alpha = 0) the small-amplitude limit is 0.91-1.06 (0.76 for the strip) and a
 * block oscillating at 1% strain is pumped up at C = 0.9 (a parametric
 * instability of the modes near the limit) but stays bounded at C = 0.8. So
 * the default solid.courant = 0.9 is safe at alpha >= 0.5; use C <= 0.7 with
 * alpha = 0.
 *
 * Accuracy: F_i is exact for linear fields but, at the two outer rows, the
 * one-sided fit of a bending field returns the strain of a point further in:
 * a beam b/dp = 5 particles thick has 0.76 of its bending stiffness (0.93 at
 * b/dp = 10, 0.98 at 20; second order), so the cantilever at b/dp = 5 is 13%
 * low in frequency. solid.tlsph.correction: quadratic replaces L_i G_ij by the
 * first-derivative rows of the weighted least-squares fit
 * x_ij ~ F X_ij + 1/2 H : X_ij X_ij (exact for quadratic fields; bodies >= 3
 * particles thick): the bending stiffness is then the lattice's own
 * (1 - (dp/b)^2), the cantilever at b/dp = 5 is 2.4% low, as the MPS solid,
 * for the same cost per step but a step 0.55 times as long (SOLID_TLSPH_QUAD_DT:
 * the one-sided quadratic fit at surfaces and corners is stiffer; measured
 * limit of C at alpha = 1 then 1.07-1.35). The hourglass term keeps the
 * linear fit F_lin, whose residual it penalises, so the forces stay the
 * exact gradient of U(F) + U_hg(F_lin). docs/solid_models.md.
 *
 * Case keys: solid.tlsph.correction (linear|quadratic, default linear, the
 * paper's), solid.tlsph.alpha (default 1: damps the lattice-scale modes
 * that the sudden loads excite and removes the parametric instability above;
 * the cantilever's bending mode loses < 0.1% of its amplitude per period) and
 * solid.tlsph.hourglass (k_hg, default 0.05: without it the cantilever
 * accumulates a zig-zag that F does not see, a fit residual of 0.8, 1.0,
 * 1.2% strain at its 1st, 2nd, 3rd return through the undeformed position;
 * with it 0.007-0.03%; it adds 2% to the bending energy of a smooth field at
 * b/dp = 5, 0.1% at 20). */
#ifndef SOLID_TLSPH_H
#define SOLID_TLSPH_H

#include <stddef.h>

#include "mps_particles.h"
#include "mps_timer.h"
#include "solid_iface.h"
#include "solid_loadprobe.h"
#include "solid_model.h"
#include "solid_scene.h"

#if MPS_DIM != 2
#error "solid_tlsph: only MPS_DIM == 2 is implemented"
#endif

#define SOLID_TLSPH_HDP 1.3         /* h / dp: support 2.6 dp, 20 neighbours */
#define SOLID_TLSPH_VISC_CFL 0.6    /* viscous term of the stable step, see below */
#define SOLID_TLSPH_QUAD_DT 0.55    /* step factor of the quadratic correction (measured) */
#define SOLID_TLSPH_PROBE_MAX SOLID_PROBE_TIES /* particles averaged by one probe */

struct solid_tlsph_material {
    double rho, E, nu, lambda, mu;  /* kg/m^3, Pa, -, Pa, Pa */
    double wave_speed;              /* c_p, m/s */
    double kv, kh;                  /* alpha c_p h (m^2/s), k_hg E / rho (m^2/s^2) */
};

enum solid_tlsph_phase { SOLID_TL_STRAIN, SOLID_TL_FORCE, SOLID_TL_UPDATE, SOLID_TL_N };

/* Tensors are row-major 2x2: {xx, xy, yx, yy}. Fields are readable by tests;
 * change them only through the API (tests may set x and v before a step). */
struct solid_tlsph {
    struct solid_scene scene;
    struct solid_tlsph_material mat[SOLID_MAX_BODIES];
    double dp, h, vol, courant, alpha, hourglass;
    int quadratic;                  /* second-order corrected gradient (see below) */
    double vmax;                    /* |v| max after the last step, m/s */
    size_t n, nfree;

    struct mps_particles ps;
    double (*x)[MPS_DIM], (*v)[MPS_DIM], (*acc)[MPS_DIM], (*aload)[MPS_DIM];
    double (*F)[4], (*P)[4];        /* of the last deformation pass */
    double (*Fl)[4];                /* linear fit (quadratic mode only; else F) */
    double (*sg)[MPS_DIM];          /* sum_j V_j L_i G_ij (0 inside the lattice), 1/m */
    unsigned char *fixed;
    double (*x0)[MPS_DIM], (*L)[4], (*disp)[MPS_DIM], *von_mises, *pressure;
    int *id, *body, *nnb;
    unsigned char *surface;

    /* pairs, CSR by particle, each pair stored from both ends */
    size_t npairs;
    size_t *pstart;                 /* n + 1 */
    int *pj;
    double (*pg)[MPS_DIM];          /* V_j L_i G_ij, 1/m (quadratic mode: see .c) */
    double (*pgl)[MPS_DIM];         /* the linear V_j L_i G_ij (== pg in linear mode) */
    double (*pgr)[MPS_DIM];         /* V_j L_j G_ij (the pair seen from j, sign flipped) */
    double (*pX)[MPS_DIM];          /* X_ij, m */
    double *pw;                     /* w_ij = V_j |W'(R)| / R, 1/m^2 */
    double *pwr;                    /* w_ij / R^2, 1/m^4 */
    int full_count;                 /* neighbours of a particle inside the lattice */

    int nprobes;
    int probe_n[SOLID_MAX_PROBES];
    size_t probe_i[SOLID_MAX_PROBES][SOLID_TLSPH_PROBE_MAX];
    struct solid_load_probes loadprobes; /* force and moment probes (solid_loadprobe.h) */

    struct solid_iface_cache iface; /* solid_model_ops.interface */

    /* the tank frame's motion (owned; NULL or kind none: a fixed frame with
     * the scene's gravity); each step takes its body force at mid-step */
    struct mps_motion *motion;

    double time;
    long steps;
    struct mps_timer timer;
};

/* Builds particles, pairs, clamps and probes from a scene (copied); alpha and
 * hourglass as above (>= 0); quadratic: 0 for the linear correction L_i, 1 for
 * the second-order one. A body must be at least 2 particles thick (a single
 * row has no 2D neighbourhood: L_i does not exist), 3 in quadratic mode. */
enum mps_status solid_tlsph_create(struct solid_tlsph **out, const struct solid_scene *scene,
                                   double alpha, double hourglass, int quadratic,
                                   struct mps_err *err);
void solid_tlsph_destroy(struct solid_tlsph **s);

/* courant * h / ((1 + 0.6 alpha) c_p + |v|max) (h times 0.55 with the
 * quadratic correction), s. */
double solid_tlsph_stable_dt(const struct solid_tlsph *s);
/* One step; MPS_EDIVERGED on a non-finite state. */
enum mps_status solid_tlsph_advance(struct solid_tlsph *s, double dt, struct mps_err *err);

/* F and P of the current positions (advance does this itself). */
void solid_tlsph_deform(struct solid_tlsph *s);

/* Diagnostics per metre depth: momentum (kg m/s), angular momentum about the
 * origin (kg m^2/s), energies (J): kinetic, elastic (sum V Psi(F)), hourglass
 * (U_hg), gravity; hg_residual = sqrt(sum w |x_ij - F_i X_ij|^2 /
 * sum w |X_ij|^2), the size of the non-affine (zig-zag) motion as a strain. */
struct solid_tlsph_diag {
    double momentum[MPS_DIM], angular;
    double kinetic, elastic, hourglass, gravity;
    double hg_residual;
};
void solid_tlsph_diag(const struct solid_tlsph *s, struct solid_tlsph_diag *d);

double solid_tlsph_probe(const struct solid_tlsph *s, int k);

extern const struct solid_model_ops solid_tlsph_ops;

#endif
