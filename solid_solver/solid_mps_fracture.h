/* Brittle fracture and contact for the MPS solid (paper section 4.4): the
 * optional part of solid_mps. A scene that sets neither solid.eps_max nor
 * solid.contact allocates none of it, and its step runs the plain code: the
 * same results, bit for bit, as before this module (test_solid_fracture).
 *
 * Fracture (Eq. 47): a bond breaks for good when its normal strain
 *     eps_ij = (|r_ij| - |r0_ij|) / |r0_ij| > eps_max,
 * the stretch that the volumetric term already uses for u_ij . e_ij
 * (solid_mps.h): tension only, blind to rigid rotations. Both ends of a bond
 * compute the same |r_ij| bit for bit, so each end breaks its own copy in the
 * same step without talking to the other. A broken bond has bk = bb = bbr = 0
 * and drops out of every sum (forces, torque, volumetric strain, energy).
 *
 * Surface (Eq. 48): i is a surface particle once n_i < n0_lattice - nc
 * (nc = 0.5), with n_i the number density of its intact bonds at their
 * initial lengths: the stored weights of section 4.4, set to zero on
 * fracture (s->nden). n_i changes only when a bond breaks, so the check runs
 * in the step a bond breaks, which is the same as every step. Current lengths
 * would flag a particle stretched by 3% (the bonds at 2 dp leave re) and, the
 * flag being for good, turn a whole impact zone into surface. Once surface,
 * always surface: s->surface is the per-step flag that interface() reports
 * to a coupled fluid (s->surface_rev counts the steps that changed it).
 *
 * Contact: two surface particles i, j with no intact bond between them (which
 * pairs count: scene.contact, solid_scene.h) closer than l0 = dp repel with
 * the central, frictionless force
 *     F_j = -F_i = K_ij (l0 - |r_ij|) e_ij,   K_ij = 2 M_i M_j / (M_i + M_j),
 * M = lambda + 2 mu the P-wave modulus of each body (F per metre depth, K in
 * Pa). Why this law: the contact stands for the layer of material between the
 * two particles, so it is as stiff as that layer: a row of contacts at
 * spacing dp carries the uniaxial stress M (l0 - r)/l0 of the bulk (two
 * half-layers in series for two materials). Stiffer, and the explicit step
 * would have to shrink; softer, and the bodies would sink into each other: at
 * speed v an isolated pair closes by v dp / (sqrt(2) c_p) (c_p = sqrt(M/rho)),
 * 0.1 l0 at the collision case's 15 m/s. The pair frequency is
 * sqrt(2) c_p / dp, within the stable step of solid_mps_stable_dt (a surface
 * particle has fewer bonds than an inner one, and a contact stands for the
 * ones it lacks). The force is zero at r = l0 (no jump), conservative (energy
 * 1/2 K (l0 - r)^2, no damping, like the bonds), equal and opposite along
 * r_ij: it conserves linear and angular momentum to round-off.
 *   Besides the surface particles, the contact also sees those that lost a
 * bond without turning surface: with nc = 0.5, a particle that lost one
 * diagonal bond (w(sqrt(2) dp) = 0.485) stays inner, and the loose particle at
 * the other end of that bond could slip into the body where no contact sees
 * it (at dp = 0.00625 two did, and sat 0.01-0.3 l0 from inner particles of
 * the square). The surface flag itself, reported to a fluid, stays Eq. 48.
 *
 * Contact search: only the contact set, in a cell list with a skin: the
 * pairs closer than (1 + SKIN) l0 are listed and kept until a listed
 * particle has moved SKIN l0 / 2 or a bond has broken. The cells are hashed
 * into ~2 buckets per particle, so the list costs O(listed particles) however
 * far fragments fly (the dense grid of mps_nbr grows with the area they
 * cover). The pass over the pairs is serial: they are a few per particle. */
#ifndef SOLID_MPS_FRACTURE_H
#define SOLID_MPS_FRACTURE_H

#include "mps_ckpt.h"
#include "mps_err.h"
#include "mps_json.h"

#define SOLID_FRAC_SKIN 0.5     /* contact list radius (1 + SKIN) l0 */

struct solid_mps;
struct solid_mps_frac;

/* Allocates the fracture and contact state that s->scene asks for; leaves
 * s->frac NULL (and allocates nothing) when it asks for neither. Called by
 * solid_mps_create after the bonds are built. */
enum mps_status solid_mps_frac_create(struct solid_mps *s, struct mps_err *err);
void solid_mps_frac_destroy(struct solid_mps_frac **f);

/* The volumetric strain pass of solid_mps (q_i) with Eq. 47-48: breaks the
 * bonds stretched past eps_max, then sums over the intact ones. */
void solid_mps_frac_strain(struct solid_mps *s);

/* Adds dt F / m of the contact forces at the current positions to v. */
enum mps_status solid_mps_frac_contact(struct solid_mps *s, double dt, struct mps_err *err);

/* Energy of the contacts now (J per metre depth, from the current list). */
double solid_mps_frac_energy(const struct solid_mps *s);

/* Smallest distance now between two particles not joined by an intact bond
 * (i.e. of different bodies or surfaces), searched within radius: returns
 * radius if no pair is closer. Exact (all particles, not only the surface);
 * O(n), allocates scratch. NAN if out of memory or the state is not finite. */
double solid_mps_min_gap(const struct solid_mps *s, double radius);

/* 1 if bond b (an index into s->bj) is intact. */
int solid_mps_bond_intact(const struct solid_mps *s, size_t b);

/* The fracture and contact state as blocks of a state image (mps_ckpt.h),
 * and back: the counters, and the contact list as built (its pairs, in
 * their order, and the positions it was built at): a list rebuilt at another
 * step would sum the same forces in another order. */
enum mps_status solid_mps_frac_put(const struct solid_mps *s, struct mps_ckpt *c,
                                   struct mps_err *err);
enum mps_status solid_mps_frac_get(struct solid_mps *s, struct mps_ckpt *c, struct mps_err *err);

/* Counters for summaries and tests. */
struct solid_mps_frac_stats {
    long broken;            /* bonds broken (pairs) */
    long surface;           /* surface particles now */
    long builds;            /* contact list builds */
    long pairs;             /* pairs in the contact list now */
    long active_max;        /* most pairs in contact (r < l0) in one step */
    double gap_min;         /* smallest contact distance seen so far, m (INFINITY: none) */
};
void solid_mps_frac_stats(const struct solid_mps *s, struct solid_mps_frac_stats *st);

/* The "fracture" member of the model's summary. */
void solid_mps_frac_summary(const struct solid_mps *s, struct mps_json *j);

#endif
