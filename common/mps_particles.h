/* Particle storage as a structure of arrays. A solver keeps typed pointers to
 * its fields (double (*x)[MPS_DIM], double *p, ...) in its own struct and
 * registers their addresses here once; this table then drives resizing,
 * reordering for cache locality, and HDF5 output, so adding a field is one line. */
#ifndef MPS_PARTICLES_H
#define MPS_PARTICLES_H

#include <stddef.h>

#include "mps_ckpt.h"
#include "mps_err.h"
#include "mps_h5.h"

#define MPS_PARTICLES_MAX_FIELDS 40

struct mps_pfield {
    const char *name;
    int ncomp;
    enum mps_field_type type;
    void **data;        /* address of the solver's pointer to the array */
    const char *units;
    int output;         /* written to snapshots */
    const char *legend; /* what an integer field's codes mean (HDF5 attribute), or NULL */
};

struct mps_particles {
    size_t n, cap;
    int nfields;
    struct mps_pfield f[MPS_PARTICLES_MAX_FIELDS];
};

void mps_particles_init(struct mps_particles *ps);
/* data: address of a NULL pointer that will own the array. */
void mps_particles_add_field(struct mps_particles *ps, const char *name, int ncomp,
                             enum mps_field_type type, void **data, const char *units,
                             int output);
/* Sets the legend of the field called name (must exist): the meaning of its
 * codes, written with it into every snapshot. */
void mps_particles_set_legend(struct mps_particles *ps, const char *name, const char *legend);
/* Sets the count to n, growing every array (new entries zeroed). */
enum mps_status mps_particles_resize(struct mps_particles *ps, size_t n, struct mps_err *err);
/* Reorders the first m particles of every field: new[i] = old[perm[i]] for
 * i < m, perm a permutation of 0 .. m-1; the others stay. */
enum mps_status mps_particles_permute(struct mps_particles *ps, const size_t *perm, size_t m,
                                      struct mps_err *err);
/* Fills out (room for max) with the output fields; returns how many. */
int mps_particles_output(const struct mps_particles *ps, struct mps_field *out, int max);
/* Frees every array and sets the solver's pointers NULL. */
void mps_particles_free(struct mps_particles *ps);

/* Every registered field of the n particles as blocks of a state image
 * (mps_ckpt.h: implicit coupling's rollback and the checkpoint files), one
 * block per field named by it, after a block with n. */
enum mps_status mps_particles_put(const struct mps_particles *ps, struct mps_ckpt *c,
                                  struct mps_err *err);
/* Resizes ps to the image's count and reads every field back: the particles
 * are then bit for bit what they were at the put. The image must come from
 * the same field table (names and sizes are checked). */
enum mps_status mps_particles_get(struct mps_particles *ps, struct mps_ckpt *c,
                                  struct mps_err *err);

#endif
