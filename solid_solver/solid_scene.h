/* The solid scene as plain data: bodies (rectangles filled with a square
 * lattice), clamps and probes, read from the "solid." keys of a case and
 * checked (every error names file, line and key). Tests and tools can also
 * fill a scene by hand and skip the case loader. Units SI, 2D per metre depth. */
#ifndef SOLID_SCENE_H
#define SOLID_SCENE_H

#include "mps_case.h"
#include "mps_dim.h"
#include "mps_motion.h"
#include "mps_err.h"
#include "solid_model.h"

#define SOLID_MAX_BODIES 32
#define SOLID_MAX_CLAMPS 32
#define SOLID_MAX_PROBES 64
#define SOLID_NAME_MAX 64

/* Lame constants from (E, nu): "strain" is Eq. 4 as printed (3D / plane
 * strain); "stress" uses the plane-stress lambda = E nu / (1 - nu^2), for which
 * a 2D beam bends with E itself (the paper's Eq. 53-54 assume E). */
enum solid_plane { SOLID_PLANE_STRAIN, SOLID_PLANE_STRESS };

/* Contact between solid surface particles not joined by an intact bond
 * (paper section 4.4; force law in solid_mps_fracture.h):
 *   NONE   no contact: bodies pass through each other;
 *   BODIES only between particles of different bodies: the paper's run
 *          "without contact detection" (Fig. 5 left), where the bodies still
 *          collide but the faces of a crack in one body do not see each other;
 *   ALL    also between the faces of cracks (bonds broken) and any other
 *          unbonded pair of one body: the paper's contact detection. */
enum solid_contact { SOLID_CONTACT_NONE, SOLID_CONTACT_BODIES, SOLID_CONTACT_ALL };

enum solid_probe_kind {
    SOLID_PROBE_DX,         /* x displacement, m */
    SOLID_PROBE_DY,         /* y displacement, m */
    SOLID_PROBE_X,          /* x position, m */
    SOLID_PROBE_Y,          /* y position, m */
    SOLID_PROBE_TANK_ANGLE, /* the tank frame's roll angle now (motion.*), deg */
    SOLID_PROBE_ENERGY,     /* kinetic + elastic energy of all bodies, J per m depth */
    /* the fluid's load on a body (or all), mean since the previous probe row
     * (solid_loadprobe.h); the load kinds come last (solid_scene.c) */
    SOLID_PROBE_FORCE_X,    /* N per metre depth */
    SOLID_PROBE_FORCE_Y,
    SOLID_PROBE_MOMENT      /* about (x, y), counterclockwise positive, N m per metre */
};

struct solid_body_def {
    char name[SOLID_NAME_MAX];
    double x0, y0, x1, y1;   /* rectangle, m; centres at x0 + dp/2 + i dp */
    double rho, E, nu;       /* kg/m^3, Pa, - */
    double v[MPS_DIM];       /* initial velocity, m/s */
};

struct solid_clamp_def {
    int body;                /* index into bodies */
    double x0, y0, x1, y1;   /* particles of body with centres inside are fixed */
};

struct solid_probe_def {
    char name[SOLID_NAME_MAX];
    enum solid_probe_kind kind;
    double x, y;             /* the particle(s) nearest this point at start; moment: the
                              * point the moment is taken about */
    int body;                /* load kinds: index into bodies, -1 all of them */
};

struct solid_scene {
    double dp;               /* lattice spacing, m: the case's dp / refine */
    double dp_coupling;      /* the case's dp, the spacing the fluid sees, m */
    int refine;              /* solid.refine: particles per dp_coupling (solid_refine.h);
                              * 0 or 1 (a scene built by hand): unrefined */
    double g[MPS_DIM];       /* body force per unit mass, m/s^2 */
    double courant;          /* (0, 1]: fraction of the stable step, see solid_mps.h */
    double mps_damping;      /* MPS solid: damping ratio at the spin frequency (solid_mps.h) */
    enum solid_plane plane;
    double plane_factor;     /* solid.plane_factor: on E, the 3D body's bending stiffness
                              * over the plane's (0 in a scene built by hand: 1) */
    double eps_max;          /* bond breaking strain (Eq. 47); 0: no fracture */
    enum solid_contact contact;
    int nbodies, nclamps, nprobes;
    struct solid_body_def bodies[SOLID_MAX_BODIES];
    struct solid_clamp_def clamps[SOLID_MAX_CLAMPS];
    struct solid_probe_def probes[SOLID_MAX_PROBES];
};

/* The solid keys ("solid.*"), for mps_case_load (with mps_case_common_keys). */
extern const struct mps_key_spec solid_case_keys[];
/* What the solid validates a case against, standalone and coupled: the
 * common keys, its own and the tank's motion */
#define SOLID_NTABLES 3
extern const struct mps_key_spec *const solid_case_tables[SOLID_NTABLES];

/* Reads and checks the scene (a body with no particles, an empty clamp, a
 * clamp naming an unknown body are errors naming the key). */
enum mps_status solid_scene_read(struct solid_scene *s, const struct mps_case *c,
                                 struct mps_err *err);

/* Particles one probe averages at most (a tip probe between two rows takes
 * the mean of both). */
#define SOLID_PROBE_TIES 8

/* For each probe of the scene, the particles nearest its point on the initial
 * lattice x0 (ties within 1e-6 dp all kept, up to SOLID_PROBE_TIES). */
void solid_probes_locate(const struct solid_scene *s, size_t n, const double (*x0)[MPS_DIM],
                         int *probe_n, size_t (*probe_i)[SOLID_PROBE_TIES]);

/* Probe k's current value: the mean over its particles of dx, dy, x or y;
 * for the load kinds, the mean load since the last restart of lp
 * (solid_loadprobe.h); NAN for the kinds the model answers itself
 * (tank_angle, energy). body: each particle's body. */
struct solid_load_probes;
double solid_probe_value(const struct solid_scene *s, int k, const int *probe_n,
                         const size_t (*probe_i)[SOLID_PROBE_TIES], const double (*x)[MPS_DIM],
                         const double (*x0)[MPS_DIM], const struct solid_load_probes *lp,
                         const int *body);

/* The tank_angle probe: theta at time t in degrees (0 without motion). */
static inline double solid_probe_tank_angle(const struct mps_motion *m, double t)
{
    return mps_motion_moving(m) ? mps_motion_at(m, t).theta * (180.0 / 3.14159265358979323846)
                                : 0.0;
}

/* Fluid loads (force per particle, N per metre depth) as accelerations:
 * aload[i] = force / (rho_body V), V = dp^2; particles not listed get zero.
 * An id outside 0..n-1, or listed twice, is MPS_EINPUT. */
enum mps_status solid_loads_accel(const struct solid_scene *s, const int *body, size_t n,
                                  const struct solid_loads *f, double (*aload)[MPS_DIM],
                                  struct mps_err *err);

/* Lattice columns and rows of body b (0 if it holds no particle): refine
 * times those of the case's dp, so each cell of the coupling lattice holds
 * refine x refine particles and the body keeps the extent it has at dp. */
void solid_scene_lattice(const struct solid_scene *s, int b, long *nx, long *ny);

/* Young's modulus of body b as the 2D model uses it, Pa: E times
 * solid.plane_factor. */
double solid_scene_modulus(const struct solid_scene *s, int b);

/* Lame constants of body b, Pa (Eq. 4, or plane stress, see enum solid_plane),
 * from solid_scene_modulus. */
void solid_scene_lame(const struct solid_scene *s, int b, double *lambda, double *mu);

#endif
