/* Error codes and messages shared by every module.
 * Library-style code returns an mps_status and fills a struct mps_err; only
 * main() ends a process. Messages name what failed and the value that made it
 * fail, e.g. "case.yml:14: dp = -0.003: must be > 0". */
#ifndef MPS_ERR_H
#define MPS_ERR_H

enum mps_status {
    MPS_OK = 0,
    MPS_EINPUT,    /* bad case file, bad command line, bad value */
    MPS_EIO,       /* a file or directory could not be read or written */
    MPS_ENOMEM,    /* allocation failed */
    MPS_ELIB,      /* a call into HDF5, CHOLMOD, ZeroMQ, libyaml failed */
    MPS_ESOLVE,    /* linear solver did not converge */
    MPS_EDIVERGED, /* NaN, a particle left the domain, a step could not be taken */
    MPS_EPROTO,    /* malformed or unexpected protocol message */
    MPS_ETIMEOUT,  /* a peer did not answer within its deadline */
    MPS_EPEER,     /* a peer reported an error or exited */
    MPS_EINTR      /* interrupted by a signal */
};

struct mps_err {
    enum mps_status code;
    char msg[1024];
};

/* Sets e (may be NULL) and returns code, so callers can write
 * `return mps_err_set(err, MPS_EINPUT, "...", ...);`. */
enum mps_status mps_err_set(struct mps_err *e, enum mps_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Prepends context ("while reading x: ") to an existing message; returns e->code. */
enum mps_status mps_err_prefix(struct mps_err *e, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

void mps_err_clear(struct mps_err *e);

/* Short name of a status ("input", "io", ...), for logs and protocol errors. */
const char *mps_status_name(enum mps_status code);

/* Process exit code for a status: 0 for MPS_OK, 2 for input errors, 1 otherwise,
 * 130 for MPS_EINTR (as a shell reports SIGINT). */
int mps_status_exit_code(enum mps_status code);

#endif
