/* The fluid's complete state, one definition for both uses: implicit
 * coupling repeats a step from its start (PROTOCOL.md 6, kept in memory) and
 * a run restarts from a checkpoint file (docs/restart.md). Both write the
 * state as blocks of an image (mps_ckpt.h) and read it back.
 *
 * What fluid_step reads before it writes it, so what the state holds:
 * every particle field in its current order (positions, velocities, the
 * pressure that warm-starts the PPE solve, the positions the Verlet list was
 * built at, the masks), the particle counts of each segment, the Verlet list
 * and the tank's reverse list (a rebuild at another moment would renumber
 * the fluid and give the same physics in other bits), time, step counter
 * (the first step always rebuilds the list; the CFL step reads it), whether
 * the solid has replaced the floor under it, the load normalisation, and the
 * counters of lost particles and guard uses, the sensors' time means
 * (fluid_sensors.h). Work counters (PPE iterations, list rebuilds, phase
 * timers) are not kept: they count the work done. Everything else (the
 * grid, the short list, the PPE matrix, pcg_defl's aggregates) is rebuilt
 * from these at every step. The PPE solver keeps no state between solves
 * except with fluid.ppe_solver: cholmod_reuse (the ordering of earlier
 * matrices): a rollback refuses it, and a restart with it is not bit for bit
 * (docs/restart.md). */
#ifndef FLUID_CHECKPOINT_H
#define FLUID_CHECKPOINT_H

#include "fluid.h"
#include "mps_ckpt.h"

/* Appends f's state to the image c. */
enum mps_status fluid_state_put(const struct fluid *f, struct mps_ckpt *c, struct mps_err *err);
/* Reads the next blocks of c (as put) into f, a fluid built from the same
 * case. */
enum mps_status fluid_state_get(struct fluid *f, struct mps_ckpt *c, struct mps_err *err);

/* Implicit coupling: the state at the step's start, in memory. The
 * neighbour lists, two thirds of the bytes at 1 mm (23 of 37 MB), are kept
 * apart and copied only when the fluid's differ from them (fluid.h,
 * nl_gen): a list outlives most steps, and both copies of it were 8% of a
 * 1 mm sloshing run. */
struct fluid_ckpt {
    int valid;
    struct mps_ckpt img;         /* everything but the lists */
    struct mps_ckpt lists;       /* nl, nl_tank */
    int lists_valid;
    unsigned long lists_gen;     /* the nl_gen they were built as */
};

/* Keeps f's state in c (zero-initialised before the first save).
 * MPS_EINPUT if the fluid's settings cannot be rolled back. */
enum mps_status fluid_ckpt_save(const struct fluid *f, struct fluid_ckpt *c, struct mps_err *err);
/* Returns f to the state of the last save. */
enum mps_status fluid_ckpt_restore(struct fluid *f, struct fluid_ckpt *c, struct mps_err *err);
void fluid_ckpt_free(struct fluid_ckpt *c);

#endif
