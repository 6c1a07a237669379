/* CURVE keys of the coupling protocol on tcp (proto/PROTOCOL.md section 10):
 * one key pair for the coupler per run, one per solver it expects, in
 * ZeroMQ's Z85 text form (40 characters for 32 bytes).
 *
 * A solver's key file is text, mode 0600, lines "name=value" ('#' starts a
 * comment line):
 *   server_public=<40 Z85 chars>   the coupler's public key
 *   client_public=<40 Z85 chars>   this solver's public key
 *   client_secret=<40 Z85 chars>   this solver's secret key
 * The coupler writes one per solver into its private run directory (0700);
 * a solver finds it through --key FILE or the environment variable
 * PROTO_KEY_ENV (set by the coupler for the solvers it launches). */
#ifndef PROTO_KEY_H
#define PROTO_KEY_H

#include "mps_err.h"

#define PROTO_KEY_Z85 40               /* a 32-byte key in Z85 */
#define PROTO_KEY_ENV "MPS_COUPLING_KEY"

/* The keys one side of a link holds. The coupler fills server_* and the
 * client_public it expects; a solver fills server_public and client_*. */
struct proto_curve {
    char server_public[PROTO_KEY_Z85 + 1];
    char server_secret[PROTO_KEY_Z85 + 1];
    char client_public[PROTO_KEY_Z85 + 1];
    char client_secret[PROTO_KEY_Z85 + 1];
};

/* 1 if this libzmq can do CURVE (built with libsodium or tweetnacl). */
int proto_key_curve_available(void);

/* A fresh key pair (Z85) into pub and sec. MPS_ELIB if libzmq cannot. */
enum mps_status proto_key_pair(char pub[PROTO_KEY_Z85 + 1], char sec[PROTO_KEY_Z85 + 1],
                               struct mps_err *err);

/* Writes a solver's key file (server_public, client_public, client_secret of
 * k) to path, created new with mode 0600 (an existing file is an error:
 * nobody can have opened it before us). */
enum mps_status proto_key_write(const char *path, const struct proto_curve *k,
                                struct mps_err *err);

/* Reads a solver's key file into k (server_secret left empty). Refuses a
 * file that others than its owner may read or write, a missing or repeated
 * name, a value that is not 40 Z85 characters, an unknown name, and a
 * client_public that does not belong to client_secret. MPS_EIO if the file
 * cannot be read, MPS_EINPUT for everything else; the message names the
 * file and line. */
enum mps_status proto_key_read(const char *path, struct proto_curve *k, struct mps_err *err);

#endif
