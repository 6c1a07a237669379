/* Fluid case keys (declared once, validated by mps_case) and the resolved
 * parameters the fluid solver runs with. */
#ifndef FLUID_PARAMS_H
#define FLUID_PARAMS_H

#include "mps_case.h"
#include "mps_dim.h"
#include "mps_motion.h"

#define FLUID_MAX_BLOCKS 16
#define FLUID_MAX_PROBES 32

enum fluid_gradient { FLUID_GRAD_CORRECTED, FLUID_GRAD_PLAIN };

/* Pressure at fixed and solid boundaries: wall particles as PPE unknowns
 * (paper 4.3), or a Neumann condition by hydrostatic extrapolation from the
 * fluid (docs/fluid.md). */
enum fluid_wall_bc { FLUID_WALL_NEUMANN, FLUID_WALL_PPE, FLUID_WALL_SOLID_PPE };

/* The load on a solid surface particle (fluid_coupling.c): its pressure on
 * its face, or the paper's Eq. 50-51. */
enum fluid_solid_load { FLUID_LOAD_FACE, FLUID_LOAD_EQ50 };



/* Probe kinds (docs/sensors.md). PRESSURE, WALL_FORCE and WALL_MOMENT are
 * means over the steps since the previous probe row (fluid_sensors.h); the
 * others are the value at the step that writes the row. */
enum fluid_probe_kind {
    FLUID_PROBE_FRONT,       /* x of the leading edge of the water on the floor, m */
    FLUID_PROBE_HEIGHT,      /* water height at x (default: the left wall), m */
    FLUID_PROBE_PRESSURE,    /* pressure sensor of a given diameter at (x, y), Pa */
    FLUID_PROBE_BOTTOM,      /* pressure on the floor (y = 0) under water, Pa */
    FLUID_PROBE_MAX_SPEED,   /* max fluid speed, m/s */
    FLUID_PROBE_ESCAPED,     /* fluid particles outside the tank, count */
    FLUID_PROBE_WALL_FORCE,  /* normal force on a tank wall, outward positive, N/m */
    FLUID_PROBE_WALL_MOMENT, /* moment of that force about (x, y), counterclockwise, N m/m */
    FLUID_PROBE_TANK_ANGLE   /* the tank's roll angle theta now (motion.*), deg */
};

/* The tank's walls, by their inner faces: x = 0, x = width, y = 0, y = height. */
enum fluid_wall { FLUID_WALL_LEFT, FLUID_WALL_RIGHT, FLUID_WALL_FLOOR, FLUID_WALL_LID,
                  FLUID_NWALLS };

/* Where a pressure sensor sits (fluid.probes.*.on). AUTO is resolved to WALL
 * when the case is read (the point on a wall face), to SOLID or WATER at the
 * first evaluation (a solid surface particle within dp of the point or not). */
enum fluid_sensor_on { FLUID_ON_AUTO, FLUID_ON_WALL, FLUID_ON_SOLID, FLUID_ON_WATER };

struct fluid_probe_def {
    const char *name;
    enum fluid_probe_kind kind;
    double x, y;
    double diameter;            /* pressure: sensor face diameter, m */
    enum fluid_sensor_on on;    /* pressure: where it sits */
    enum fluid_wall wall;       /* pressure on a wall, wall_force, wall_moment */
};

struct fluid_params {
    double dp, end_time, g[MPS_DIM];
    double rho, nu;
    double courant, dt_max, dt_min;
    int droplet_neighbours; /* fewer neighbours within re_n: outside Eq. 52 */
    int mixed_source;             /* add the velocity-divergence source term */
    int divergence_wide;          /* its Eq. 10 on the Laplacian's neighbours (re_lap) */
    int divergence_near_bodies;   /* ... only in the rows that reach a solid body */
    int divergence_slip;          /* its Eq. 10 with the tank's walls slipping */
    double divergence_floor;      /* fraction of dp: closer pairs read there in Eq. 10 */
    double gradient_floor;        /* fraction of dp: closer pairs read there in Eq. 9/14 */
    int initial_hydrostatic;      /* start from the hydrostatic pressure of each block */
    double kappa, alpha;          /* Eq. 23 relaxation; compressibility 1/(rho c^2), 1/Pa */
    double kappa_dt;              /* s: steps shorter than this correct kappa dt / kappa_dt */
    double kappa_step_decay;      /* per step: how fast Eq. 23's reference step may fall */
    double kappa_step_decay_expansion; /* the same, for the rows whose water has expanded */
    int density_quadratic;        /* Eq. 23's density error from mps_weight_quadratic */
    double density_dead_band;     /* n0: Eq. 23 corrects only the error beyond this */
    double re_n, re_lap;          /* effective radii, multiples of dp */
    double beta1, beta2;          /* free-surface double check */
    double surface_scan;          /* empty-side confirmation radius, dp; 0 = off */
    double surface_scan_density;  /* scan only candidates with n >= this x n0 */
    enum fluid_gradient gradient;
    enum fluid_wall_bc wall_bc;
    enum fluid_solid_load solid_load;
    int body_shadow;              /* no PPE coupling through a coupled solid (fluid_ppe.c) */
    int surface_closure;          /* close the PPE Laplacian under the free surface */
    int gradient_min;             /* subtract the neighbourhood minimum pressure */
    int clamp_negative;           /* negative PPE pressures set to 0 */
    int tension_solves;           /* more PPE solves releasing rows under tension (0: clamp) */
    int tension_sweeps;           /* projected Gauss-Seidel sweeps for the first held set */
    int tension_start_last;       /* the held set starts from the last step's (fluid.tension_start) */
    double collision_dist;        /* fraction of dp; 0 = off */
    double collision_restitution;
    double side_wall_breadth;     /* m: 0 = no side walls (2D) */
    double side_wall_period;      /* s: their boundary layers' period; 0 = the motion's */
    int side_wall_inertia;        /* the layers' reactive half too (an inertia), not the drag only */
    double shift_coef, shift_max; /* particle shifting: A (0 = off), cap in dp */
    int shift_smooth;             /* shifting along the smooth weight's gradient */
    double jitter;                /* dp: largest start displacement per axis; 0 = lattice */
    unsigned long jitter_seed;    /* which realisation of the jitter */
    const char *ppe_solver;
    int step_log;                 /* write PREFIX_steps.csv */
    double ppe_rtol;
    int ppe_max_iter;
    double ppe_drop;       /* pcg_sic0 drop threshold */
    double ppe_coarse_cell;       /* pcg_defl aggregate cell side, in dp */
    double tank_w, tank_h;
    int tank_lid;
    int wall_layers;              /* wall + dummy layers, >= 3 */
    int nblocks;
    double block[FLUID_MAX_BLOCKS][4]; /* x0, y0, x1, y1 */
    int nprobes;
    struct fluid_probe_def probes[FLUID_MAX_PROBES];
    double output_interval, probe_interval, checkpoint_interval;
    /* the tank frame's motion (borrowed from the caller, who reads it with
     * mps_motion_read; fluid_params_read leaves it NULL: a fixed tank) */
    const struct mps_motion *motion;
};

extern const struct mps_key_spec fluid_case_keys[];
/* "left", "right", "floor", "lid", by enum fluid_wall. */
extern const char *const fluid_wall_names[FLUID_NWALLS];

/* Reads and cross-checks the fluid keys (blocks inside the tank, CFL cap
 * satisfiable, ...). Errors name file, line and key. */
enum mps_status fluid_params_read(struct fluid_params *p, const struct mps_case *c,
                                  struct mps_err *err);

/* The explicit viscosity's (Eq. 16) stable step, roughly dp^2 / (2 d nu);
 * INFINITY for an inviscid fluid. One definition for the step limit and for
 * the check at reading that it is not below dt_min. */
double fluid_viscous_dt(const struct fluid_params *p);

#endif
