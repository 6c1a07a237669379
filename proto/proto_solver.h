/* The solver side of the coupling protocol (PROTOCOL.md sections 6-8) as one
 * loop, so every solver program in C runs the same conversation: HELLO,
 * CONFIG -> configure, READY, then ADVANCE -> advance / RESULT until STOP ->
 * BYE, with ERROR on any failure and a prompt exit on ABORT or a lost coupler.
 * A solver supplies its physics through these callbacks. */
#ifndef PROTO_SOLVER_H
#define PROTO_SOLVER_H

#include "mps_err.h"
#include "proto_msg.h"

struct proto_solver_ops {
    const char *role;    /* "fluid" or "solid" */
    const char *model;   /* "mps", "tlsph", ... */
    /* CONFIG: read the resolved case, build particles, open outputs (prefix
     * names them), write the initial snapshot. */
    enum mps_status (*configure)(void *self, const char *case_path, const char *out_dir,
                                 const char *prefix, struct mps_err *err);
    /* READY: fill payload (the solid's interface, or NONE), dt (own stable
     * step), nprobes and text (comma-separated probe names). Pointers in
     * reply stay owned by the solver until the next callback. */
    enum mps_status (*ready)(void *self, struct proto_msg *reply, struct mps_err *err);
    /* ADVANCE: take the step described by in (payload, time, dt, n_sub),
     * write a snapshot if in->flags has PROTO_F_SNAPSHOT, and fill reply's
     * payload, dt (next stable step) and, with PROTO_F_PROBES, nprobes and
     * probes. The loop fills type, step, iteration, time and flags. */
    enum mps_status (*advance)(void *self, const struct proto_msg *in, struct proto_msg *reply,
                               struct mps_err *err);
    /* STOP: finish outputs; return the summary as a malloc'd JSON object. */
    char *(*finish)(void *self, enum mps_status st, const struct mps_err *err);
    /* Optional, both or neither: implicit coupling (PROTOCOL.md 6, "Implicit
     * coupling"). save keeps everything the next step's result depends on
     * (outputs written so far included); restore returns to the last save,
     * bit for bit. A solver with them declares caps=rollback in HELLO. With
     * rollback=on in CONFIG the loop calls save after configure (so a scene
     * the solver cannot roll back is refused before READY) and before every
     * ADVANCE of iteration 0, and restore before every ADVANCE of
     * iteration > 0. */
    enum mps_status (*save)(void *self, struct mps_err *err);
    enum mps_status (*restore)(void *self, struct mps_err *err);
    /* 1: the solver applies the case's tank motion (the motion.* keys,
     * mps_motion.h), so it accepts CONFIG motion=KIND; 0: it answers that key
     * with ERROR input (PROTOCOL.md 4). */
    int moving_frame;
    /* Optional, both or neither: checkpoints (PROTOCOL.md 6, "Checkpoints";
     * docs/restart.md). A solver with them declares caps=checkpoint in HELLO.
     * checkpoint writes the solver's complete state after the step of an
     * ADVANCE with PROTO_F_CHECKPOINT as checkpoint number (the loop counts
     * them from CONFIG restart=N, or 0); resume, called after configure when
     * CONFIG has restart=N, reads checkpoint N back (state and outputs), so
     * READY then reports the state of that moment. */
    enum mps_status (*checkpoint)(void *self, long number, double time, struct mps_err *err);
    enum mps_status (*resume)(void *self, long number, struct mps_err *err);
    /* Optional (NULL: none): case keys of the solver's own section that its
     * command line sets, "KEY:VALUE,..." (HELLO sets=, PROTOCOL.md 4), e.g.
     * "solid.model:tlsph" for solid_solver --model tlsph; the coupler records
     * them in the run's case, which the solvers then read. */
    const char *sets;
};

/* Timing of the conversation, for the solver's summary. */
struct proto_solver_stats {
    double setup_seconds;     /* inside configure/ready */
    double compute_seconds;   /* inside advance, save and restore */
    double wait_seconds;      /* waiting for the coupler */
    double rollback_seconds;  /* inside save and restore (part of compute_seconds) */
    long advances;            /* every ADVANCE, repeated iterations included */
    long repeats;             /* ADVANCEs with iteration > 0 */
    int rollback;             /* CONFIG asked for rollback=on */
    long restart;             /* CONFIG restart=N (0: a new run), set before configure */
    long checkpoints;         /* the last checkpoint's number */
    double checkpoint_seconds; /* inside checkpoint (part of compute_seconds) */
    /* 1: the run ended with ABORT, with a case error sent to the coupler
     * (proto_solver_case_error), or with a signal before CONFIG: the coupler
     * tells the user why, on its own terminal, so the solver program prints
     * nothing (a case error is then one line, as the coupler's own are) */
    int coupler_reports;
};

/* Runs the conversation on endpoint until STOP (MPS_OK), ABORT (MPS_EPEER),
 * an error (sent to the coupler as ERROR when possible) or a signal
 * (*stop_flag set by the caller's handler: MPS_EINTR). hello_timeout_ms
 * bounds the wait for CONFIG. On error, finish() is still called so the
 * outputs are flushed. */
enum mps_status proto_solver_run(const char *endpoint, const struct proto_solver_ops *ops,
                                 void *self, int hello_timeout_ms,
                                 volatile const int *stop_flag, struct proto_solver_stats *stats,
                                 struct mps_err *err);

/* Solver programs run coupled as `PROGRAM --connect ENDPOINT [--key FILE]
 * [--timeout S] [--quiet]`. --key FILE sets PROTO_KEY_ENV (proto_key.h),
 * where proto_solver_run looks for the key of a tcp endpoint. Returns 1 and fills endpoint / hello_timeout_ms if argv holds
 * --connect, 0 if not, -1 (err set) if the coupled arguments are malformed. */
int proto_solver_args(int argc, char **argv, const char **endpoint, int *hello_timeout_ms,
                      struct mps_err *err);

/* For configure: marks st, the outcome of validating the solver's own case
 * keys (reading them and the checks across them), as a case error when it is
 * MPS_EINPUT; the loop then sends ERROR "input: case: MESSAGE" (PROTOCOL.md 8),
 * which the coupler prints as it prints its own keys' errors. err->msg must be
 * one line naming where, the key and the problem (mps_case_fail's). Returns
 * st. */
enum mps_status proto_solver_case_error(enum mps_status st, struct mps_err *err);

/* "a,b,c" from n names into buf (size len); returns buf. */
char *proto_join_names(const char *const *names, int n, char *buf, size_t len);

#endif
