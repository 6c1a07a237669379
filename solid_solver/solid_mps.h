/* The explicit MPS elastic solid (paper sections 2.2, 4.2; Chikazawa et al.
 * 2001): particles bonded to their initial neighbours within re = 2.1 dp, with
 * a rotation per particle so that the shear forces of a bond exert no net
 * torque (angular momentum conserved, Eq. 41-46).
 *
 * Per bond ij (r_ij = x_j - x_i, r0 its initial value, w = w(|r0|), Eq. 7):
 *   u_ij = r_ij - R((theta_i + theta_j)/2) r0                      Eq. 25
 *   normal + shear stress 2 mu u_ij / |r0|                          Eq. 26-29, 31-32
 *   tr_i = sum_j beta_ij (|r_ij| - |r0|),  beta_ij = a_ij w / |r0|  Eq. 30
 *   p_i = -lambda tr_i                                              Eq. 33
 *   a_i = sum k_ij u_ij - sum (p_i beta_ij + p_j beta_ji) e_ij / rho + g + load
 *         k_ij = (2 mu / rho) (a_ij + a_ji) w / |r0|^2              Eq. 36-38
 *   I dw_i/dt = 1/2 sum r_ij x F_ij, I = m dp^2 / 6                  Eq. 41-44
 *   v += dt a, x += dt v; w += dt dw/dt, theta += dt w              Eq. 39-40, 45-46
 * with e_ij = r_ij / |r_ij| and a_ij = e0^T B_i^-1 e0 (e0 = r0/|r0|, B_i =
 * sum_k w_ik e0_ik e0_ik^T: the correction matrix of Eq. 15 on the initial
 * bonds). Inside the lattice a_ij = d/n0, and the above is the paper's model
 * term for term. Where it differs, and why:
 *  - 2d/n0_i of Eq. 36-38 becomes a_ij + a_ji: symmetric, so pair forces are
 *    exactly opposite (momentum conserved to round-off), and at a surface
 *    each direction is normalised by the bonds the particle has along it.
 *    With d/n0_i (which also counts the missing bonds across the surface) a
 *    b/dp = 5 beam is 8% too stiff in frequency; with a uniform n0 it is 10%
 *    too soft (docs/solid_cantilever.md).
 *  - Eq. 30's u_ij . r_ij / |r_ij| is taken as the stretch |r_ij| - |r0|
 *    (equal to first order). Eq. 38 is used as -grad p (Eq. 5), each pressure
 *    weighted by its own beta: then the forces are the exact gradient of
 *    sum 1/2 K |u|^2 + sum 1/2 lambda tr^2 V, and the symplectic update keeps
 *    the energy bounded.
 *
 * Stable step: dt = C min(dp / c_p, 2 / w_s): c_p = sqrt((lambda + 2 mu)/rho)
 * is the P-wave speed, and w_s bounds the spin frequency of the particles,
 * w_s^2 = max_i (3/dp^2) sum_j k_ij |r0_ij|^2 (all spins in phase, Eq. 43-44),
 * which is 24 mu / (rho dp^2) inside the lattice and up to 13% more next to a
 * surface. The spin mode is the stiffest of the lattice (for nu <= 0.4 in
 * plane strain, always in plane stress): with c_p alone C = 1 would be
 * unstable (the bulk limit would be C = 0.76 at nu = 0.3). With this bound the
 * measured limit is C = 1.02-1.09 for bodies at least 3 particles thick and
 * 0.96 for a strip 2 particles thick (test_solid_stability); the default
 * solid.courant = 0.9 keeps every shape stable.
 *
 * Damping (solid.mps.damping = zeta, default 0: the paper has none). Every
 * bond's deformation u_ij gets a Kelvin-Voigt rate term, u -> u + tau du/dt,
 * du/dt = v_j - v_i - w_ij x R r0 (w_ij the mean spin), tau = 2 zeta / w_s:
 * damping ratio zeta at the spin frequency and zeta w / w_s below it, so a
 * plate's bending mode (w / w_s ~ 1e-3) keeps its frequency and amplitude.
 * Why: coupled to a fluid the solid is driven by loads that change every
 * fluid step, a period of 1-3 spin periods; undamped, the spin energy grows
 * until the lattice tears (dam break on a plate, 3 mm: spin rms 14 rad/s at
 * 0.15 s, 130 at 0.56 s, 1000 at 0.6 s, then the plate broke up). The pair
 * forces stay opposite and the torques those of Eq. 41-43, so momentum and
 * angular momentum are still conserved; the stable step becomes
 * 2 (sqrt(1 + zeta^2) - zeta) / w_s on the spin bound.
 *
 * Brittle fracture and contact (section 4.4, solid.eps_max, solid.contact)
 * are in solid_mps_fracture.h: off unless the scene asks, and then free. */
#ifndef SOLID_MPS_H
#define SOLID_MPS_H

#include <stddef.h>

#include "mps_particles.h"
#include "mps_timer.h"
#include "solid_iface.h"
#include "solid_loadprobe.h"
#include "solid_model.h"
#include "solid_scene.h"

#if MPS_DIM != 2
#error "solid_mps: only MPS_DIM == 2 is implemented (rotations are scalars)"
#endif

#define SOLID_MPS_RE 2.1        /* effective radius / dp (paper section 3) */
#define SOLID_MPS_NC 0.5        /* surface if n0_i < n0_lattice - nc (Eq. 48) */
#define SOLID_MPS_PROBE_MAX SOLID_PROBE_TIES /* particles averaged by one probe */
#define SOLID_MPS_OMP_MIN 4096  /* below this many particles a step runs serial */
#define SOLID_MPS_NEXTRA 5      /* probes added when fracture or contact is on */

struct solid_mps_material {
    double rho, E, nu, lambda, mu;   /* kg/m^3, Pa, -, Pa, Pa */
    double wave_speed;               /* c_p, m/s */
};

/* contact last: timed (and summarised) only when contact is on */
enum solid_mps_phase { SOLID_PH_STRAIN, SOLID_PH_FORCE, SOLID_PH_UPDATE, SOLID_PH_CONTACT,
                       SOLID_PH_N };

/* Fields are readable by tests and drivers; change them only through the API
 * (tests may set v and omega before the first step). */
struct solid_mps {
    struct solid_scene scene;
    struct solid_mps_material mat[SOLID_MAX_BODIES];
    double dp, n0_lattice, courant;
    double spin_omega;               /* w_s, rad/s (see above) */
    double damp_tau;                 /* Kelvin-Voigt time, s; 0 undamped */
    double (*vold)[MPS_DIM], *wold;  /* v, omega at the start of a step (damping) */
    size_t n, nfree;

    /* particles (registered in ps: resized, freed and output together) */
    struct mps_particles ps;
    double (*x)[MPS_DIM], (*v)[MPS_DIM], *theta, *omega;
    double *hc, *hs;                 /* cos, sin of theta / 2 */
    double *kq;                      /* -lambda / rho, m^2/s^2 */
    double *q;                       /* p_i / rho, from the strain pass */
    double (*x0)[MPS_DIM], (*aload)[MPS_DIM], *n0;
    double *pressure, (*disp)[MPS_DIM]; /* filled for snapshots */
    int *id, *body;
    unsigned char *fixed;
    unsigned char *surface;          /* Eq. 48, updated every step under fracture */
    double *nden;                    /* n_i of the intact bonds; NULL without fracture */
    long surface_rev;                /* +1 in each step that made new surface particles */
    struct solid_mps_frac *frac;     /* fracture and contact state; NULL when off */

    /* bonds, CSR by particle (each pair stored from both ends); a broken
     * bond has bk = bb = bbr = 0 */
    size_t nbonds;
    size_t *bstart;                  /* n + 1 */
    int *bj;
    double (*br0)[MPS_DIM];          /* initial r_ij, m */
    double *blen;                    /* |r0_ij|, m */
    double *bk;                      /* k_ij, 1/s^2 */
    double *bb, *bbr;                /* beta_ij, beta_ji, 1/m */

    /* probes */
    int nprobes;
    int probe_n[SOLID_MAX_PROBES];
    size_t probe_i[SOLID_MAX_PROBES][SOLID_MPS_PROBE_MAX];
    struct solid_load_probes loadprobes; /* force and moment probes (solid_loadprobe.h) */

    /* interface cache (solid_model_ops.interface) */
    struct solid_iface_cache iface;
    long iface_rev;                  /* surface_rev the cache was built for */

    /* the tank frame's motion (owned; NULL or kind none: a fixed frame with
     * the scene's gravity); each step takes its body force at mid-step */
    struct mps_motion *motion;

    double time;
    long steps;
    struct mps_timer timer;

};

/* Builds particles, bonds, clamps and probes from a scene (copied). */
enum mps_status solid_mps_create(struct solid_mps **out, const struct solid_scene *scene,
                                 struct mps_err *err);
void solid_mps_destroy(struct solid_mps **s);

/* dt = courant * dp / max wave speed (see above), s. */
double solid_mps_stable_dt(const struct solid_mps *s);
/* One step of the symplectic update; MPS_EDIVERGED on a non-finite state. */
enum mps_status solid_mps_advance(struct solid_mps *s, double dt, struct mps_err *err);

/* Diagnostics (per metre depth): linear momentum (kg m/s), angular momentum
 * about the origin including particle spin (kg m^2/s), and energies (J):
 * kinetic (translation + spin), elastic (intact bonds + volumetric), gravity,
 * contact (0 without contact). */
struct solid_mps_diag {
    double momentum[MPS_DIM], angular;
    double kinetic, elastic, gravity, contact;
};
void solid_mps_diag(const struct solid_mps *s, struct solid_mps_diag *d);

/* Probe k's current value (mean over its particles). */
double solid_mps_probe(const struct solid_mps *s, int k);

/* The model behind the solid_model_ops interface. */
extern const struct solid_model_ops solid_mps_ops;

#endif
