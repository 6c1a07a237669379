/* What a program's checkpoint holds besides its solver's state, and how a
 * program restarts from one (docs/restart.md). One mechanism for the fluid
 * and solid programs alone and under the coupler:
 *   image = "case" (the resolved case, YAML) + "run" (struct mps_run_mark:
 *   event counters, where probes.csv ended) + "snapshots" (the XDMF index,
 *   mps_h5_put) + the solver's state (fluid_state_put, solid model
 *   state_put).
 * Checkpoints are taken at the end of the first step reaching each multiple
 * of output.checkpoint_interval, like snapshots and probe rows: the schedule
 * of outputs never changes a step, so a run with checkpoints is bit for bit
 * the run without. */
#ifndef MPS_RESTART_H
#define MPS_RESTART_H

#include "mps_ckpt.h"
#include "mps_cli.h"
#include "mps_err.h"
#include "mps_h5.h"

#define MPS_RUN_TABLES 2 /* csv tables a program continues (probes.csv, a step log) */

/* Where a run's outputs stood at a checkpoint. */
struct mps_run_mark {
    long out_k, probe_k, ck_k; /* next snapshot, probe row and checkpoint (multiples of their
                                * interval) */
    long number;               /* this checkpoint's number */
    long steps;                /* steps taken (a program's own count) */
    long table_bytes[MPS_RUN_TABLES]; /* length of each csv table (mps_probes_bytes) */
};

/* 1 if time t has reached the k-th multiple of period (> 0; 0 or less: never),
 * the first step reaching it writes; then *k moves past t. eps: the time
 * tolerance of the run (a step landing within eps of the event reaches it). */
int mps_run_due(long *k, double period, double t, double eps);

/* A solver's state writer (fluid_state_put, solid_model_ops.state_put). */
typedef enum mps_status (*mps_state_put_fn)(const void *self, struct mps_ckpt *c,
                                            struct mps_err *err);

/* Writes checkpoint number m->number of the run at time into
 * DIR/checkpoint/PREFIX_NNNNNN.ckpt: the program's part (case, *m, the
 * snapshot index), then put(self). c is the image's buffer (reused). */
enum mps_status mps_run_checkpoint(struct mps_ckpt *c, const char *dir, const char *prefix,
                                   const char *case_yaml, struct mps_run_mark *m,
                                   const struct mps_h5_series *h5, double time,
                                   mps_state_put_fn put, const void *self, struct mps_err *err);

/* --restart: reads the checkpoint of prefix in cli->restart_dir (the latest,
 * or the one nearest to --from), writes its case to
 * DIR/checkpoint/restart_case.yml (case_path, size len, gets that name) and
 * reads the mark. The caller then loads the case with cli's --set (end_time)
 * and builds its solver, and calls mps_run_get_rest. */
enum mps_status mps_run_restart_open(struct mps_ckpt *c, const struct mps_cli *cli,
                                     const char *prefix, char *case_path, size_t len,
                                     struct mps_run_mark *m, struct mps_err *err);
/* Under the coupler: reads checkpoint number of prefix in DIR/checkpoint/
 * (the coupler chose it: CONFIG restart=N) and its mark; the case it holds is
 * the coupler's, which the solver has already loaded. Then mps_run_get_rest. */
enum mps_status mps_run_read(struct mps_ckpt *c, const char *dir, const char *prefix,
                             long number, struct mps_run_mark *m, struct mps_err *err);
/* Reads the snapshot index into h5 (may be NULL: the run writes none); the
 * solver's state follows in c. */
enum mps_status mps_run_get_rest(struct mps_ckpt *c, struct mps_h5_series *h5,
                                 struct mps_err *err);

/* What a run's last bits depend on besides its input and the restart's
 * state: the build and the CPU always, and for a program whose sums depend on
 * them the OpenMP thread count and the vector paths (the fluid: its
 * reductions and its AVX-512 paths; the solid is the same run on any count
 * and either path). A checkpoint records them (block "arith", after "run";
 * a checkpoint of an older build has none); a restart with other ones goes
 * on, with the same physics, but need not be bit for bit the run it
 * continues, and says so. A program sets what counts once, at start. */
#define MPS_ARITH_THREADS 1u
#define MPS_ARITH_SIMD 2u
void mps_run_arith_set(unsigned what);
/* After a restart's read of c: writes what differs between the arithmetic
 * the checkpoint records and this run's into note (size len, e.g. "threads
 * 2 -> 1, paths avx512 -> portable"), "" where nothing does or the
 * checkpoint records none; where something does, prints a line saying so,
 * "PROGRAM: note: PATH was written with other arithmetic (NOTE): ...", even
 * under --quiet (it is about the result). */
void mps_run_arith_check(const struct mps_ckpt *c, const char *program, const char *path,
                         char *note, size_t len);

#endif
