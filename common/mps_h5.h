/* Field output: one HDF5 file per snapshot (closed after writing, so a run
 * that dies leaves every earlier snapshot readable), and an XDMF index that is
 * rewritten atomically (write to a temporary file, rename) after each snapshot
 * so ParaView can open the series at any moment. docs/output.md describes the
 * files for their readers.
 *
 * Snapshot layout (FILE = DIR/PREFIX_NNNNNN.h5, NNNNNN the snapshot index):
 *   /            attributes: time (s), step, code_version, git_rev, solver
 *   /config      string dataset: the resolved case (YAML, with run.* saying
 *                which command ran it, on which host, when)
 *   /particles/position  n x 3 float64 (m); z = 0 in 2D
 *   /particles/<field>   n, n x 3 (vectors: z = 0 in 2D) or n x ncomp,
 *                        float64 / int32 / uint8, attribute "units" and, for
 *                        coded fields, "legend" ("0 fluid, 1 wall, ...")
 * XDMF: DIR/PREFIX.xmf, a temporal collection of Polyvertex grids. */
#ifndef MPS_H5_H
#define MPS_H5_H

#include <stddef.h>

#include "mps_ckpt.h"
#include "mps_dim.h"
#include "mps_err.h"

enum mps_field_type { MPS_F64, MPS_I32, MPS_U8 };

/* Components of a vector in the files: 3 whatever MPS_DIM is, since
 * ParaView's Xdmf3 reader keeps a 2-component "Vector" as it is and its
 * WarpByVector and Calculator then fail on it (XDMF defines a Vector as 3
 * values). The memory layout stays MPS_DIM. */
#define MPS_H5_VEC 3

struct mps_field {
    const char *name;   /* "pressure", "velocity", "type" */
    int ncomp;          /* 1 for scalars, MPS_DIM for vectors (written as MPS_H5_VEC) */
    enum mps_field_type type;
    const void *data;   /* n * ncomp values, borrowed */
    const char *units;
    const char *legend; /* what the codes of an integer field mean, or NULL */
};

struct mps_h5_series;

/* Opens a series writing into dir (created if missing) with file prefix
 * ("fluid", "solid"). solver and config_yaml are stored in every snapshot. */
enum mps_status mps_h5_open(struct mps_h5_series **out, const char *dir, const char *prefix,
                            const char *solver, const char *config_yaml, struct mps_err *err);

/* Writes one snapshot of n particles at positions x, then updates the XDMF. */
enum mps_status mps_h5_write(struct mps_h5_series *s, double time, long step, size_t n,
                             const double (*x)[MPS_DIM], const struct mps_field *fields,
                             int nfields, struct mps_err *err);

/* Number of snapshots written so far. */
int mps_h5_count(const struct mps_h5_series *s);

/* Forgets the snapshots after the first count (a solver that rolled back to
 * an earlier state: implicit coupling repeats a step). The index is rewritten
 * without them and the next write reuses their names, overwriting the files.
 * count >= the current count does nothing. NULL ok. */
enum mps_status mps_h5_rewind(struct mps_h5_series *s, int count, struct mps_err *err);

/* The series' index (the XDMF block of each snapshot so far) as a block of a
 * state image (mps_ckpt.h), and back: a run restarted from a checkpoint
 * continues the series where the checkpoint was taken, its next snapshot
 * overwriting the first one written after it (get rewrites the XDMF).
 * s may be NULL (no snapshots): an empty block. */
enum mps_status mps_h5_put(const struct mps_h5_series *s, struct mps_ckpt *c,
                           struct mps_err *err);
enum mps_status mps_h5_get(struct mps_h5_series *s, struct mps_ckpt *c, struct mps_err *err);

/* Closes the series (XDMF is already complete); accepts NULL, sets *s NULL. */
void mps_h5_close(struct mps_h5_series **s);

/* Writes DIR/NAME.xmf that shows several series (e.g. fluid and solid) as one
 * scene: at each time of the first series, a spatial collection of the
 * snapshots of every series with the nearest time. Reads the series' own .xmf
 * indexes in dir (series_prefixes, n of them). Atomic like the per-series file. */
enum mps_status mps_h5_write_scene_xdmf(const char *dir, const char *name,
                                        const char *const *series_prefixes, int n,
                                        struct mps_err *err);

#endif
