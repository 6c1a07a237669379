/* The semi-implicit MPS fluid (paper 4.1, 4.3): state and one time step.
 * Particles are stored as a structure of arrays in three segments:
 *   [0, nfluid)            fluid
 *   [nfluid, nfixed_end)   tank wall (first layer) and dummy layers
 *   [nfixed_end, n)        solid particles given by a coupled solid (moving
 *                          boundary), surface and inner ones.
 * Boundary pressure (fluid.wall_bc): with Neumann walls only fluid particles
 * are PPE unknowns and every boundary particle takes the fluid's pressure
 * extrapolated hydrostatically; with the paper's walls the wall and solid
 * surface particles are PPE unknowns and dummies carry none; solid_ppe (the
 * default) puts the solid surface in the PPE (the paper's coupling) and keeps
 * Neumann tank walls. fluid_update_masks() says who is what.
 * docs/fluid.md describes the step and every deviation from the paper. */
#ifndef FLUID_H
#define FLUID_H

#include <stddef.h>

#include "fluid_linsolve.h"
#include "fluid_params.h"
#include "fluid_sensors.h"
#include "mps_dim.h"
#include "mps_json.h"
#include "mps_nbr.h"
#include "mps_particles.h"
#include "mps_timer.h"

enum fluid_ptype {
    FLUID_P = 0,
    WALL_P = 1,
    DUMMY_P = 2,
    SOLID_SURF_P = 3,
    SOLID_INNER_P = 4,
    SOLID_SUNK_P = 5 /* a solid particle inside the tank's walls: a wall particle to the fluid */
};

enum fluid_phase {
    PH_NBR, PH_PREDICT, PH_DENSITY, PH_ASSEMBLE, PH_SOLVE, PH_CORRECT, PH_SENSORS, PH_OTHER,
    PH_COUNT
};

/* What the last step did, for the step log (fluid.step_log). */
struct fluid_step_stats {
    double dt;
    double dt_cfl;         /* the CFL step at the step's start (>= dt) */
    double dt_kappa;       /* the step Eq. 23's correction was scaled by (fluid_ppe.c) */
    double dt_kappa_expansion; /* ... in the rows below n0 (>= dt_kappa) */
    int ppe_iterations;
    int ppe_rows;
    int rows_at_zero;      /* PPE rows whose pressure came out <= 0 (released or clamped) */
    int tension_solves;    /* PPE solves after the first (fluid.tension_solves) */
    long collisions;       /* pair impulses of the collision model */
    int neighbour_build;   /* 1 if the neighbour list was rebuilt */
};

struct fluid {
    struct fluid_params prm;
    struct mps_particles ps;
    /* fields (registered in ps) */
    double (*x)[MPS_DIM];
    double (*xref)[MPS_DIM];   /* positions when the neighbour list was built */
    double (*v)[MPS_DIM];
    double (*vstar)[MPS_DIM];
    double (*lap)[MPS_DIM];
    double (*grad)[MPS_DIM];
    double (*acc)[MPS_DIM];    /* body force per unit mass: gravity, or in a moving tank
                                * the frame's (mps_motion.h); fluid_body_accel fills it */
    double *p;
    double *div;           /* divergence of v* (mixed PPE source; on the Laplacian's
                            * stencil fluid_ppe_assemble fills it) */
    double *nd;            /* particle number density n* (re_n) */
    double *nq;            /* mps_ops_number_density_quadratic's at x* (fluid.density_weight) */
    int *ncount;           /* neighbours within re_n */
    int *type;             /* enum fluid_ptype */
    int *id;               /* stable id (solid particles: the solid's id) */
    int *row;              /* PPE row, -1 if not an unknown */
    unsigned char *ppe_flag; /* the masks PPE pass 1 reads of a neighbour, in one byte
                              * (fluid_ppe.c, PPE_F_*), set at each assembly */
    unsigned char *surface; /* free surface (P = 0) */
    unsigned char *has_p;   /* carries a pressure: fluid, wall, solid surface */
    unsigned char *is_fluid;
    unsigned char *nbr_query; /* gets a row in nl: not a tank particle (Neumann walls) */
    unsigned char *unknown;   /* a PPE unknown unless on the free surface */
    unsigned char *ghost;     /* boundary whose pressure a PPE row extrapolates from
                               * itself, P_j = P_i + rho g.(x_j - x_i) (Neumann) */
    unsigned char *grad_use;  /* carries a pressure the gradient uses */
    unsigned char *fallback; /* corrected gradient fell back to Eq. 9 */
    double (*body_n)[MPS_DIM]; /* solid surface particles: unit normal away from the body's
                                * particles, 0 if none near (fluid.body_shadow, fluid_shadow.h) */
    unsigned char *in_body;    /* fluid particle behind the face of its nearest solid surface
                                * particle: never shadowed (fluid_shadow.h) */
    size_t nfluid, nfixed_end;
    /* lattice constants */
    double n0, n0_lap, lambda_lap;
    double nq0;            /* mps_lattice_consts' nq0 at re_n (fluid.density_weight) */
    double shift_gain;     /* fluid.shifting_weight smooth: the MPS weight's lattice
                            * response over the smooth one's (about 5 at re = 2.1 dp) */
    double load_scale;     /* Eq. 50 normalisation, see fluid_coupling.c */
    int solid_placed;      /* walls under the solid removed */
    int count0;
    /* neighbours */
    struct mps_nbr_grid grid;
    struct mps_nbr_list nl;       /* re_lap + skin, built at x^n */
    struct mps_nbr_list nl_n;     /* re_n, filtered from nl at x* */
    struct mps_nbr_list nl_tank;  /* Neumann walls: the fluid neighbours of each tank
                                   * particle (nl has no rows for them) */
    double *wlap;                 /* c w_ij at x* of the PPE row's Laplacian neighbours, */
    int *wcol;                    /* and their indices, packed from each nl row's start */
    size_t cap_wlap;
    int *nwlap;                   /* per particle: how many of them (a field) */
    unsigned char *shadow_use;    /* per entry of nl_n: 0 if a solid stands between the
                                   * pair (fluid.body_shadow, fluid_shadow.h) */
    size_t cap_shadow;
    int *agg;                     /* pcg_defl: aggregate of each PPE row */
    size_t cap_agg;
    long long *aggkey;            /* scratch: cell of each row, and a cell -> aggregate map */
    int *aggmap;
    size_t cap_aggkey, cap_aggmap;
    double skin;
    double side_wall_rate;        /* 1/s: the side walls' drag per unit velocity (0: none) */
    double side_wall_inertia;     /* delta / b: the side walls' added inertia (0: none) */
    double rho_inertial;          /* kg/m3: rho (1 + side_wall_inertia), what the pressure
                                   * gradient accelerates (rho without side walls) */
    /* PPE */
    int nrows;
    int *rowptr, *col;
    double *val, *rhs, *sol;
    size_t cap_rows, cap_nnz;
    /* with keep_ppe_terms (fluid_solver --dump-ppe): per row, the row
     * particle's position at the assembly and the rhs's parts, each a
     * FLUID_PPE_TERMS-wide record (fluid_ppe.h) */
    /* fluid.tension_solves: the assembled system, kept while rows are
     * released (the solves change val and rhs), and per row 1 if it is
     * fluid, held at P = 0 now, next (fluid_ppe.c) */
    double *val_assembled, *rhs_assembled;
    unsigned char *row_is_fluid, *row_held, *row_held_next;
    unsigned char *row_touched, *row_seed; /* scratch, one byte a row */
    unsigned char *ppe_held;    /* per particle: its row was held at P = 0 in the last solve */
    int *row_list;  /* the rows fluid.tension_sweeps sweeps; then those a re-solve changes */
    size_t cap_held_rows, cap_held_nnz;
    int keep_ppe_terms;
    double *ppe_terms;
    size_t cap_ppe_terms;
    struct fluid_linsolve *ls;
    /* bookkeeping */
    double time;
    long step;
    /* the step a restart began from (0 otherwise): the counters below and
     * the phase timers are this process's, so its per-step figures are
     * over step - step_start (a restarted summary read 6.4 PCG iterations
     * a step for 12.0) */
    long step_start;
    double dt_last;
    double dt_kappa;           /* the last step's dt_kappa (fluid.kappa_step_decay) */
    double dt_kappa_expansion; /* and its dt_kappa_expansion (..._decay_expansion) */
    long ppe_iterations;
    long nbr_rebuilds;
    /* Which build the lists nl and nl_tank hold: a fresh value at every
     * build, and a rollback that restores older lists restores their value
     * too, so fluid_ckpt_save/restore copy the lists only when they differ
     * from the saved ones (fluid_checkpoint.c). Never reused: from
     * nl_gen_next, which no rollback touches. */
    unsigned long nl_gen, nl_gen_next;
    long lost;             /* fluid particles that splashed out of an open tank */
    long wall_guard;       /* times a particle was put back inside the tank */
    long wall_guard_face[4];   /* of them through the floor, left, right wall, lid */
    double wall_guard_first[3]; /* the first use (if wall_guard > 0): time, x, y */
    int wall_guard_first_face;  /* and its face, as wall_guard_face's index */
    struct fluid_step_stats last;
    struct mps_timer timer;
    struct fluid_sensors *sens;   /* time means of the averaged probes (NULL: none) */
};

/* Builds the tank and the water blocks from validated parameters. */
enum mps_status fluid_create(struct fluid **out, const struct fluid_params *prm,
                             struct mps_err *err);
void fluid_destroy(struct fluid **f);

/* The step the CFL condition (Eq. 52) allows now, capped by dt_max. */
double fluid_cfl_dt(const struct fluid *f);

/* MPS_EDIVERGED, saying so, if a step of dt is below fluid.dt_min (or zero:
 * a speed that overflowed). Checked before a step, and before the fluid
 * offers its next step to a coupler, where a zero cannot go on the wire. */
enum mps_status fluid_check_step(const struct fluid *f, double dt, struct mps_err *err);

/* One step of dt (Eq. 16-24). Fails with MPS_EDIVERGED on NaN or a particle
 * leaving the domain, MPS_ESOLVE if the PPE solve fails. */
enum mps_status fluid_step(struct fluid *f, double dt, struct mps_err *err);

/* Replaces the solid particles (coupled runs). surface[k] selects PPE
 * particles; the rest only count in the number density. On the first call,
 * wall and dummy particles closer than dp/2 to a solid particle are removed,
 * so a solid clamped into the tank floor replaces the wall there. */
enum mps_status fluid_set_solid(struct fluid *f, size_t n, const int *id,
                                const double (*x)[MPS_DIM], const double (*v)[MPS_DIM],
                                const unsigned char *surface, struct mps_err *err);

/* Loads on the solid surface particles after a step: pressure and the fluid
 * force of Eq. 50-51 times the particle volume dp^d (N per metre in 2D).
 * Fills up to max entries in the order of the solid particles given to
 * fluid_set_solid (surface ones only); returns the count. */
size_t fluid_solid_loads(const struct fluid *f, int *id, double *pressure,
                         double (*force)[MPS_DIM], size_t max);

/* Eq. 10 on f->vstar over nl_n (re_n) into f->div for the particles with
 * rows[i], the tank's wall and dummy neighbours slipping
 * (fluid.divergence_walls = slip): such a neighbour j enters with v*_j plus
 * the tangential part of v*_i - v*_j along its face, so that only the
 * approach normal to the wall counts. */
void fluid_divergence_slip_walls(struct fluid *f, const unsigned char *rows);

/* Recomputes the type masks (has_p, is_fluid) after particle types change. */
void fluid_update_masks(struct fluid *f);

/* The collision model after the prediction (fluid.collision_distance,
 * fluid.collision_restitution): on v* and x, over the neighbour list of the
 * step; returns the number of colliding pairs. Public for the known-answer
 * test. */
long fluid_collide(struct fluid *f, double dt);

/* The particle shifting at the end of a step (fluid.shifting, its weight
 * fluid.shifting_weight), over the neighbour list of the step; public for
 * the known-answer test. */
void fluid_shift(struct fluid *f, double dt);

/* Fills f->acc for every particle at time t (fluid_body.c): prm.g in a fixed
 * tank, else the moving frame's body acceleration at each particle's x, v. */
void fluid_body_accel(struct fluid *f, double t);

/* Probe k (see enum fluid_probe_kind): the mean since the last
 * fluid_probes_restart() for the averaged kinds (fluid_sensors.h), the value
 * now for the others. */
double fluid_probe(const struct fluid *f, int k);
/* A probe row was written: the averaged probes start a new interval. */
void fluid_probes_restart(const struct fluid *f);

/* Output fields for a snapshot; returns the count written into out. */
int fluid_output_fields(const struct fluid *f, struct mps_field *out, int max);

/* Summary members (counts, phase times) into an open JSON object. */
void fluid_summary(const struct fluid *f, struct mps_json *j);

#endif
