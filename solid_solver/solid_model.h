/* The contract every solid model honours (MPS solid, TLSPH solid, ...), so the
 * solid program and the coupling loop never depend on a model's insides.
 * A model owns its particles; the caller borrows views of them. Units SI;
 * in 2D forces are per metre of depth. */
#ifndef SOLID_MODEL_H
#define SOLID_MODEL_H

#include <stddef.h>

#include "mps_case.h"
#include "mps_ckpt.h"
#include "mps_dim.h"
#include "mps_err.h"
#include "mps_h5.h"
#include "mps_json.h"
#include "mps_particles.h"

/* What the coded fields of every model's snapshots mean (HDF5 "legend"). */
#define SOLID_LEGEND_FIXED "1 clamped (never moves), 0 free"
#define SOLID_LEGEND_SURFACE "1 on a body's surface (initial or made by fracture), 0 inside"
#define SOLID_LEGEND_BODY "index of the body in solid.bodies"

/* Sets those legends on a model's particle table (fields fixed, surface, body). */
static inline void solid_model_legends(struct mps_particles *ps)
{
    mps_particles_set_legend(ps, "fixed", SOLID_LEGEND_FIXED);
    mps_particles_set_legend(ps, "surface", SOLID_LEGEND_SURFACE);
    mps_particles_set_legend(ps, "body", SOLID_LEGEND_BODY);
}

/* What a coupled fluid needs of the solid: the surface particles (they take
 * part in the fluid's pressure Poisson equation and receive loads) and the
 * inner particles within `depth` of the surface (they only fill the fluid's
 * particle number density, like dummy wall particles). Arrays are borrowed and
 * stay valid until the next call into the model. */
struct solid_iface {
    size_t n;
    const int *id;                  /* stable particle ids (index at creation) */
    const double (*x)[MPS_DIM];     /* m */
    const double (*v)[MPS_DIM];     /* m/s */
    const unsigned char *surface;   /* 1 surface, 0 inner near-surface */
    const unsigned char *fixed;     /* 1 clamped (never moves) */
};

/* Fluid loads on surface particles, held constant over the sub-steps of one
 * fluid step. force: total fluid force on the particle (N, per metre depth in
 * 2D), i.e. Eq. 50's force density times the particle volume. */
struct solid_loads {
    size_t n;
    const int *id;
    const double *pressure;         /* Pa, for output */
    const double (*force)[MPS_DIM];
};

/* Every particle of a model, borrowed like the interface: what the
 * refinement (solid_refine.h) needs to meet the fluid on a coarser lattice. */
struct solid_particles_view {
    size_t n;
    const int *id, *body;
    const double (*x0)[MPS_DIM];    /* initial lattice, m */
    const double (*x)[MPS_DIM];     /* m */
    const double (*v)[MPS_DIM];     /* m/s */
    const unsigned char *surface, *fixed;
};

struct solid_model_ops {
    const char *name;   /* "mps", "tlsph" */
    /* Builds the bodies from the case (keys under "solid."). */
    enum mps_status (*create)(void **self, const struct mps_case *c, struct mps_err *err);
    /* Largest stable explicit step now (s), Courant number included. */
    double (*stable_dt)(const void *self);
    /* Replaces the fluid loads (ids not present get zero load). */
    enum mps_status (*set_loads)(void *self, const struct solid_loads *f, struct mps_err *err);
    /* One explicit step of dt <= stable_dt. Reports MPS_EDIVERGED on NaN. */
    enum mps_status (*advance)(void *self, double dt, struct mps_err *err);
    enum mps_status (*interface)(void *self, double depth, struct solid_iface *out,
                                 struct mps_err *err);
    /* Case probes ("solid.probes.*"): names and current values. */
    int (*probe_count)(const void *self);
    const char *(*probe_name)(const void *self, int k);
    double (*probe_value)(const void *self, int k);
    /* A probe row was written: the probes that are means over time (the
     * fluid's load on a body, solid_loadprobe.h) start a new interval. */
    void (*probe_restart)(void *self);
    /* Particle positions and output fields for a snapshot (borrowed). */
    size_t (*snapshot)(void *self, const double (**x)[MPS_DIM], struct mps_field *fields,
                       int max_fields, int *nfields);
    /* Extra summary members (phase times, counters) into an open JSON object. */
    void (*summary)(const void *self, struct mps_json *j);
    void (*destroy)(void **self);
    /* The model's complete state, one definition for implicit coupling's
     * rollback (a repeated step restarts from it, in memory) and for
     * checkpoints (docs/restart.md): every part of the state that advance
     * reads (particles, rotations, bonds and broken bonds, contact lists,
     * time and step counters, the load probes' means) as blocks of an image
     * (mps_ckpt.h), and back into a model built from the same case, after
     * which the same loads give the same state bit for bit. Optional, both
     * or neither (NULL: the model cannot checkpoint or roll back). */
    enum mps_status (*state_put)(const void *self, struct mps_ckpt *c, struct mps_err *err);
    enum mps_status (*state_get)(void *self, struct mps_ckpt *c, struct mps_err *err);
    /* Optional: MPS_EINPUT, saying why, for a scene whose steps cannot be
     * repeated under implicit coupling although its state can be saved. */
    enum mps_status (*rollback_check)(const void *self, struct mps_err *err);
    /* Optional: every particle (NULL: the model cannot run refined). */
    void (*particles)(const void *self, struct solid_particles_view *out);
};

/* Writes the model's snapshot at time t, step into the series (the one
 * snapshot writer of the solid program alone and under the coupler); adds
 * the wall seconds it took to *seconds. */
enum mps_status solid_model_snapshot(const struct solid_model_ops *ops, void *model,
                                     struct mps_h5_series *h5, double t, long step,
                                     double *seconds, struct mps_err *err);

/* The most steps to end_time a solid may ask for: at the fastest 100 ns a
 * step (one particle) 1e12 steps are more than a day of computing, and every
 * count stays exact in a double and far inside a long. */
#define SOLID_MAX_STEPS 1e12

/* Creates the model *ops names from the case; with solid.refine > 1 wraps it
 * in the refinement (solid_refine.h) and points *ops at the wrapper, which
 * every later call goes through. */
enum mps_status solid_model_open(const struct solid_model_ops **ops, void **self,
                                 const struct mps_case *c, struct mps_err *err);

/* MPS_EINPUT, naming the stiffest body's E where it was given (a problem of
 * the case's keys: PROTOCOL.md 8's case error), if the model's stable step
 * is zero or needs more than SOLID_MAX_STEPS steps to end_time. */
enum mps_status solid_model_check_step(const struct solid_model_ops *ops, const void *self,
                                       const struct mps_case *c, struct mps_err *err);

/* The models compiled in, by name; NULL if unknown. */
const struct solid_model_ops *solid_model_find(const char *name);
/* "mps, tlsph": for error messages. */
const char *solid_model_names(void);

#endif
