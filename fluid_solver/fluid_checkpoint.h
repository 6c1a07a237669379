/* The fluid's state at the start of a coupling step, kept so the step can be
 * repeated from it (implicit coupling, PROTOCOL.md 6): a repeated step with
 * the same solid boundary then gives the same loads bit for bit.
 *
 * What fluid_step reads before it writes it, so what a checkpoint holds:
 * every particle field in its current order (positions, velocities, the
 * pressure that warm-starts the PPE solve, the positions the Verlet list was
 * built at, the masks), the particle counts of each segment, the Verlet list
 * and the tank's reverse list (a rebuild at another moment would renumber
 * the fluid and give the same physics in other bits), time, step counter
 * (the first step always rebuilds the list; the CFL step reads it), whether
 * the solid has replaced the floor under it, the load normalisation, and the
 * counters of lost particles and guard uses, the sensors' time means
 * (fluid_sensors.h). Work counters (PPE iterations,
 * list rebuilds, phase timers) are not rolled back: they count the work done.
 * The PPE solver keeps no state between solves except with
 * fluid.ppe_solver: cholmod_reuse (the ordering of earlier matrices), which
 * a save therefore refuses. */
#ifndef FLUID_CHECKPOINT_H
#define FLUID_CHECKPOINT_H

#include "fluid.h"
#include "mps_particles.h"

struct fluid_ckpt {
    int valid;
    struct mps_particles_ckpt ps;
    struct mps_nbr_list nl, nl_tank;
    size_t nfluid, nfixed_end;
    double time, dt_last, load_scale;
    long step, lost, wall_guard;
    int solid_placed;
    struct fluid_sensors_mark sens;
};

/* Copies f's state into c (zero-initialised before the first save).
 * MPS_EINPUT if the fluid's settings cannot be rolled back. */
enum mps_status fluid_ckpt_save(const struct fluid *f, struct fluid_ckpt *c, struct mps_err *err);
/* Returns f to the state of the last save. */
enum mps_status fluid_ckpt_restore(struct fluid *f, const struct fluid_ckpt *c,
                                   struct mps_err *err);
void fluid_ckpt_free(struct fluid_ckpt *c);

#endif
