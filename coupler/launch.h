/* Starting and watching the solver processes. A solver command is a string
 * of words ("solid_solver --model tlsph"); a bare program name is looked up
 * beside the coupler's own executable first, then on PATH. Children get
 * SIGTERM if the coupler dies (PR_SET_PDEATHSIG), so no solver outlives it. */
#ifndef LAUNCH_H
#define LAUNCH_H

#include <sys/types.h>

#include "mps_err.h"

struct child {
    const char *name;      /* "fluid", "solid" */
    char command[4096];    /* as given, for messages */
    pid_t pid;             /* 0: not launched (or external) */
    int exited;            /* reaped */
    int status;            /* waitpid status once exited */
};

/* Message latency between processes depends on where they run: on this
 * 2-core VM a ZeroMQ round trip between two processes on different CPUs
 * takes 94 us (each hop wakes a thread on the other CPU), on one CPU 17 us
 * (bench/zmq_roundtrip.c). The processes take turns, so they can share one:
 * with want set, this pins the calling process (the coupler, before it opens
 * any socket) to the first allowed CPU no other coupler on the machine has
 * claimed (a lock file per CPU in /tmp, held for the coupler's life; none
 * left: not pinned), and solvers launched afterwards get
 * every allowed CPU back with OMP_PLACES listing that CPU first and
 * OMP_PROC_BIND=close, so OpenMP binds their main thread to it and their
 * workers to the others. Does nothing with one CPU, or if the user set
 * OMP_PLACES or OMP_PROC_BIND. Returns 1 if pinned; note says what was done
 * and why. */
int launch_share_cpu(int want, char *note, size_t len);

/* Launches `command --connect endpoint`. key_file (NULL: none) reaches the
 * solver as PROTO_KEY_ENV in its environment, never on its command line,
 * which every user can read in ps. */
enum mps_status launch_start(struct child *c, const char *name, const char *command,
                             const char *endpoint, const char *key_file, struct mps_err *err);

/* Reaps the child if it has exited (non-blocking). Returns 1 if it has
 * exited (now or before), 0 if still running or never launched. */
int launch_poll(struct child *c);

/* "exited with status 3", "was killed by signal 11 (Segmentation fault)". */
void launch_describe(const struct child *c, char *buf, size_t len);

/* Waits for n children on one clock: child k gets SIGTERM grace_s[k] after
 * the call if it is still running, SIGKILL 2 s after that. Returns once all
 * have exited (at most max(grace_s) + 2 s). */
void launch_reap_all(struct child *const *kids, const double *grace_s, int n);

#endif
