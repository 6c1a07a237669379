/* The coupling protocol's codec: messages to frames and back, no sockets.
 * proto/PROTOCOL.md is the contract; this is its C side.
 *
 * Ownership: a message you build borrows every pointer you put in it (they
 * can point straight into a solid_iface or solid_loads). proto_msg_decode()
 * copies the frames into one block owned by the message; proto_msg_clear()
 * frees it. Encoded frames borrow from the message and from the
 * proto_frames struct itself (the header bytes), so keep both alive and do
 * not copy a proto_frames while its frames are in use. */
#ifndef PROTO_MSG_H
#define PROTO_MSG_H

#include <stddef.h>
#include <stdint.h>

#include "mps_dim.h"
#include "mps_err.h"

#define PROTO_VERSION 2
#define PROTO_HEADER_LEN 80
#define PROTO_MAX_FRAMES 8               /* header + 5 STATE arrays + probes + text */
#define PROTO_MAX_COUNT 2147483647ull    /* particles per message (ids are i32) */
#define PROTO_MAX_PROBES 65536
#define PROTO_MAX_TEXT (1u << 20)        /* bytes */

enum proto_type {
    PROTO_HELLO = 1,   /* solver -> coupler: "role=fluid model=NAME pid=N" */
    PROTO_REJECT = 2,  /* coupler -> solver: reason */
    PROTO_CONFIG = 3,  /* coupler -> solver: key=value lines */
    PROTO_READY = 4,   /* solver -> coupler: initial STATE (solid), probe names */
    PROTO_ADVANCE = 5, /* coupler -> solver: one step of dt from time */
    PROTO_RESULT = 6,  /* solver -> coupler: payload, next stable dt */
    PROTO_STOP = 7,    /* coupler -> solver: finish normally */
    PROTO_BYE = 8,     /* solver -> coupler: summary JSON */
    PROTO_ERROR = 9,   /* solver -> coupler: "status: message" */
    PROTO_ABORT = 10   /* coupler -> solver: reason; no reply */
};

enum proto_payload {
    PROTO_NONE = 0,
    PROTO_STATE = 1,   /* id, x, v, surface, fixed */
    PROTO_LOADS = 2    /* id, pressure, force */
};

enum {
    PROTO_F_TEXT = 1u,      /* set by the encoder iff text != NULL */
    PROTO_F_SNAPSHOT = 2u,  /* ADVANCE: write a snapshot after the step */
    PROTO_F_PROBES = 4u,    /* ADVANCE: return probes; RESULT: probe frame present */
    PROTO_F_CHECKPOINT = 8u /* ADVANCE: write a checkpoint after the step (caps=checkpoint) */
};

struct proto_msg {
    enum proto_type type;
    enum proto_payload payload;
    uint32_t flags;
    int64_t step;        /* coupling step index, 0-based */
    int32_t iteration;   /* coupling iteration, 0 for the weak coupling */
    int32_t n_sub;       /* ADVANCE: sub-steps (>= 1) */
    double time;         /* s */
    double dt;           /* s */
    size_t count;        /* particles in the payload arrays */
    /* STATE and LOADS */
    const int *id;
    /* STATE */
    const double (*x)[MPS_DIM];      /* m */
    const double (*v)[MPS_DIM];      /* m/s */
    const unsigned char *surface;    /* 0/1 */
    const unsigned char *fixed;      /* 0/1 */
    /* LOADS */
    const double *pressure;          /* Pa */
    const double (*force)[MPS_DIM];  /* N (per metre depth in 2D) */
    /* READY: number of names in text; RESULT with PROBES: values in probes */
    int nprobes;
    const double *probes;
    const char *text;    /* NUL-terminated UTF-8, or NULL for no text frame */
    void *own_;          /* storage owned after decode; NULL when built by hand */
};

/* One frame: borrowed bytes. */
struct proto_frame {
    const void *data;
    size_t len;
};

/* Encoded frames of one message; see the ownership note above. */
struct proto_frames {
    int n;
    struct proto_frame f[PROTO_MAX_FRAMES];
    unsigned char header[PROTO_HEADER_LEN];
    void *swap_;  /* big-endian hosts: little-endian copies of the arrays */
};

/* A zeroed message of the given type (payload NONE, no text). */
struct proto_msg proto_msg_make(enum proto_type type);

/* Checks m against every rule of PROTOCOL.md (the ones decode checks after
 * the wire layout) and fills out. PROTO_F_TEXT in m->flags is ignored and
 * derived from m->text. Returns MPS_EPROTO with a message naming the field
 * on a rule violation; out is then empty. */
enum mps_status proto_msg_encode(const struct proto_msg *m, struct proto_frames *out,
                                 struct mps_err *err);

/* Releases what encode allocated (nothing on little-endian hosts); NULL ok. */
void proto_frames_clear(struct proto_frames *fr);

/* Decodes and validates nframes frames into m (which then owns copies of the
 * arrays and the text; frames can be released right after). On failure m is
 * zeroed and the status is MPS_EPROTO (MPS_ENOMEM if the copy fails). */
enum mps_status proto_msg_decode(struct proto_msg *m, const struct proto_frame *frames,
                                 int nframes, struct mps_err *err);

/* Frees decoded storage and zeroes m. NULL ok. */
void proto_msg_clear(struct proto_msg *m);

/* "HELLO", "ADVANCE", ...; "?" for unknown codes. */
const char *proto_type_name(int type);
/* "NONE", "STATE", "LOADS"; "?" for unknown codes. */
const char *proto_payload_name(int payload);

/* Finds key in a text of key=value items separated by sep (' ' for HELLO,
 * '\n' for CONFIG) and copies its value into buf (size n, NUL-terminated).
 * Returns 1 if found, 0 if absent, -1 if the value does not fit. */
int proto_text_get(const char *text, char sep, const char *key, char *buf, size_t n);

/* The status an ERROR text starts with ("diverged: ..." -> MPS_EDIVERGED);
 * MPS_EPEER if the text does not start with a status name. *message (may be
 * NULL) is set to the part after "status: ". */
enum mps_status proto_error_status(const char *text, const char **message);

/* A case error (PROTOCOL.md 8): an ERROR "input: case: LINE" by which a solver
 * says one of its case keys is wrong, LINE being the one-line message the
 * coupler would print for a key of its own ("case.yml:14: solid.bodies.0.E =
 * -1: must be > 0"). */
#define PROTO_CASE_ERROR "case: "
/* 1 and *line (may be NULL) set to LINE if text is a case error; else 0. */
int proto_case_error(const char *text, const char **line);

#endif
