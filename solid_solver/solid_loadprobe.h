/* Probes of the fluid's load on the solid bodies (solid.probes kinds force_x,
 * force_y, moment; docs/sensors.md), for every solid model. The value is the
 * total of the Eq. 50 forces the fluid sent (N per metre depth), over the
 * particles of a body (or of all bodies), and its moment about a point, taken
 * at the particles' positions at each step (counterclockwise positive). A
 * row of probes.csv holds its mean over the time since the previous row,
 * each step weighted by its dt: a load held over n_sub sub-steps of dt/n_sub
 * weighs dt, as in the coupler's solid_fx, which these agree with.
 * A model calls solid_load_probes_set from set_loads and
 * solid_load_probes_step before each step; whoever writes the rows reads
 * the values (solid_probe_value) and then restarts the means. */
#ifndef SOLID_LOADPROBE_H
#define SOLID_LOADPROBE_H

#include <stddef.h>

#include "mps_dim.h"
#include "mps_err.h"
#include "solid_model.h"
#include "solid_scene.h"

struct solid_load_probes {
    int active;                  /* the scene has load probes */
    size_t n, cap;               /* particles loaded by the latest set */
    size_t *idx;                 /* their indices (the loads' ids) */
    double (*force)[MPS_DIM];    /* N per metre depth */
    double sum[SOLID_MAX_PROBES]; /* time integral of each load probe, since the restart */
    double time;                 /* s */
};

int solid_probe_is_load(enum solid_probe_kind kind);

/* Empty; active if the scene has a load probe (else every call is a no-op). */
void solid_load_probes_init(struct solid_load_probes *lp, const struct solid_scene *s);
void solid_load_probes_free(struct solid_load_probes *lp);

/* Holds a copy of the loads (ids already checked by solid_loads_accel). */
enum mps_status solid_load_probes_set(struct solid_load_probes *lp, const struct solid_loads *f,
                                      struct mps_err *err);

/* Before a step of dt from positions x (body: each particle's body). */
void solid_load_probes_step(struct solid_load_probes *lp, const struct solid_scene *s,
                            const int *body, const double (*x)[MPS_DIM], double dt);

/* Load probe k's mean since the restart, or its value now if no step since. */
double solid_load_probes_value(const struct solid_load_probes *lp, const struct solid_scene *s,
                               int k, const int *body, const double (*x)[MPS_DIM]);

/* A probe row was written: the means start again. */
void solid_load_probes_restart(struct solid_load_probes *lp);

#endif
