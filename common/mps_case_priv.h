/* What the modules of the case reader share (not part of the API: see
 * mps_case.h). The case is a flat table of dotted keys (struct entry),
 * filled by the YAML reader (mps_case_yaml.c) and --set (mps_case_set.c),
 * checked against copies of the spec tables (mps_case_keys.c, with
 * mps_case_suggest.c's "did you mean"), read by the getters (mps_case.c)
 * and written back nested (mps_case_resolved.c). */
#ifndef MPS_CASE_PRIV_H
#define MPS_CASE_PRIV_H

#include <stddef.h>

#include "mps_case.h"

#define KEY_MAX 512        /* longest key a getter formats */
/* Bounds that keep a hostile or mistaken file from costing more than a real
 * case ever needs (ours are a few kB and under 300 keys; lookups are linear,
 * so the key count bounds the quadratic work of loading). */
#define CASE_MAX_BYTES (1L << 20)
#define CASE_MAX_KEYS 10000
#define CASE_MAX_DEPTH 32
#define INDEX_MAX_DIGITS 9 /* a sequence index fits an int */

struct value {
    double d;
    long i;
    int b;
};

struct entry {
    char *key;   /* "fluid.blocks.0.x0" */
    char *val;   /* the scalar as text */
    char *where; /* "case.yml:14", "--set dp=1", "default" */
    const struct mps_key_spec *spec; /* into mps_case.specs; NULL: ignored key */
    struct value v;                  /* parsed value when spec != NULL */
};

struct mps_case {
    char *path, *dir;
    char *origin; /* a resolved copy's user case (mps_case_origin); NULL: path */
    struct entry *e;
    int n, cap;
    /* Copies of the spec tables and ignore prefixes (strings in pool), so the
     * caller's tables need not outlive the case. */
    struct mps_key_spec *specs;
    int nspecs;
    const char **ignore;
    int nignore;
    char *pool;
};

/* ---- growable string (mps_case.c) ---- */
struct sbuf {
    char *s;
    size_t n, cap;
};
int case_sb_add(struct sbuf *b, const void *p, size_t n);
void case_sb_cut(struct sbuf *b, size_t n);
char *case_xprintf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* ---- key names and the table (mps_case.c) ---- */
/* A sequence index component: digits, no leading zero, fits an int. */
int case_is_index(const char *s, size_t n);
/* Spec name pat ("fluid.blocks.*.x0") against key ("fluid.blocks.3.x0"). */
int case_name_matches(const char *pat, const char *key);
/* No empty components: rejects "", ".a", "a.", "a..b". */
int case_key_shape_ok(const char *key);
struct entry *case_find_entry(const struct mps_case *c, const char *key);
const struct mps_key_spec *case_find_spec(const struct mps_case *c, const char *key);
int case_is_ignored(const struct mps_case *c, const char *key);
/* An existing key that cannot coexist with key: one is a section of the
 * other ("gravity" and "gravity.x"). */
const struct entry *case_find_conflict(const struct mps_case *c, const char *key);
/* Appends key = val (vlen bytes); takes ownership of where. -1: no memory. */
int case_add_entry(struct mps_case *c, const char *key, const char *val, size_t vlen,
                   char *where);

/* ---- the error list: one line (house rule), the first problem in full and
 * how many more there are, with the next one (mps_case.c) ---- */
struct errs {
    struct mps_err *err;
    int n;
    char next[200]; /* the second problem */
};
void case_add_err(struct errs *es, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Control bytes from the file shown as '?': an error stays one line. */
void case_one_line(char *msg);
/* Appends "(and N more problems; the next: ...)" to the first one. */
void case_finish_errs(struct errs *es);

/* ---- values and specs (mps_case_keys.c) ---- */
/* v, or "(empty)" */
const char *case_shown(const char *v);
/* "must be in [0, 1]", "must be > 0", or "out of range" (no bounds). */
void case_bounds_text(const struct mps_key_spec *s, char *buf, size_t n);
/* Parses text as the spec's type and checks its bounds. Returns 0, or -1
 * with the problem ("must be > 0") in prob. */
int case_check_value(const struct mps_key_spec *s, const char *text, struct value *v, char *prob,
                     size_t np);
/* Copies the spec tables and ignore prefixes into the case. -1: no memory. */
int case_copy_specs(struct mps_case *c, const struct mps_key_spec *const *tables, int ntables,
                    const char *const *ignore);
/* Every key against the specs, the required keys, then the defaults.
 * MPS_ENOMEM, or MPS_OK with the problems in es. */
enum mps_status case_validate(struct mps_case *c, struct errs *es);

/* ---- "did you mean" (mps_case_suggest.c) ---- */
/* Writes "; did you mean fluid.blocks.0.x0?" (with key's own indices) or "". */
void case_suggest(const struct mps_case *c, const char *key, char *out, size_t n);

/* ---- the resolved file (mps_case_resolved.c) ---- */
/* Its first line, and the comment lines after the YAML that say where each
 * key came from and its value there ("#@ fluid.rho<TAB>case.yml:14<TAB>1000";
 * the origin is also "--set dp=0.01" or "default"). */
#define RESOLVED_INTRO "# Resolved from "
#define RESOLVED_TAIL " (defaults filled in, --set applied)"
#define ORIGIN_INTRO "# Where each key was given (a program that reads this file names those places):\n"
#define ORIGIN_MARK "#@ "
/* For a resolved file (first line RESOLVED_INTRO PATH RESOLVED_TAIL), takes
 * PATH as c->origin and gives each key that
 * still has the value of its ORIGIN_MARK line that line's origin, so a
 * program that finds a problem in the copy names the user's file and line or
 * --set; other files: nothing. */
enum mps_status case_read_origins(struct mps_case *c, struct mps_err *err);

/* ---- reading (mps_case_yaml.c) and --set (mps_case_set.c) ---- */
/* The case file c->path into the table; fatal errors in err. */
enum mps_status case_read_file(struct mps_case *c, struct mps_err *err);
/* One --set key=value; a problem goes to es (MPS_EINPUT), MPS_ENOMEM to es->err. */
enum mps_status case_apply_set(struct mps_case *c, const char *set, struct errs *es);

#endif
