/* Case files: YAML read through libyaml into a flat table of dotted keys,
 * validated against declared key specs, with --set overrides.
 *
 * Nested mappings become dotted paths ("fluid.rho"); sequence items get their
 * index ("fluid.blocks.0.x0", "probes.1.name"). A spec name uses "*" for any
 * index ("fluid.blocks.*.x0"). Every key in the file and in --set must match a
 * spec (or lie under an ignored prefix, for sections another program owns),
 * have the spec's type and lie in its bounds; else the load fails with
 * "FILE:LINE: KEY = VALUE: problem" (and "did you mean ..." for near misses).
 * Values given by --set report "--set KEY=VALUE" in place of FILE:LINE. */
#ifndef MPS_CASE_H
#define MPS_CASE_H

#include <stddef.h>
#include <stdio.h>

#include "mps_err.h"
#include "mps_utf8.h"

enum mps_key_type {
    MPS_KEY_DOUBLE,
    MPS_KEY_INT,
    MPS_KEY_BOOL,   /* true/false, yes/no, on/off, 1/0 */
    MPS_KEY_STRING,
    MPS_KEY_ENUM    /* one of spec.choices, "a|b|c" */
};

enum mps_key_flags {
    MPS_KEY_REQUIRED = 1 << 0, /* must be given (in the file or by --set) */
    MPS_KEY_LO_OPEN = 1 << 1,  /* value > lo (default: value >= lo) */
    MPS_KEY_HI_OPEN = 1 << 2,  /* value < hi (default: value <= hi) */
    MPS_KEY_NO_LO = 1 << 3,    /* no lower bound */
    MPS_KEY_NO_HI = 1 << 4,    /* no upper bound */
    MPS_KEY_PATH = 1 << 5      /* STRING: a file path, relative to the case file's
                                * directory; the resolved YAML holds it absolute */
};

struct mps_key_spec {
    const char *name;     /* dotted path, "*" for a sequence index */
    enum mps_key_type type;
    const char *def;      /* default as text; NULL: no default (absent means "off") */
    double lo, hi;        /* bounds for DOUBLE and INT, see flags */
    unsigned flags;
    const char *choices;  /* ENUM: "corrected|plain" */
    const char *units;    /* "m", "s", "Pa", "" */
    const char *help;     /* one line, shown in errors and docs */
};

/* A table of specs ends with an entry whose name is NULL. */
struct mps_case;

/* Loads path, applies sets ("key=value", nsets of them), validates every key
 * against the union of the spec tables, and fills defaults. Keys under any of
 * ignore_prefixes (e.g. "solid." for the fluid solver; NULL-terminated list,
 * may be NULL) are kept but not validated. Required keys that are missing are
 * errors. On failure *out is NULL and err says why. */
enum mps_status mps_case_load(struct mps_case **out, const char *path,
                              const char *const *sets, int nsets,
                              const struct mps_key_spec *const *spec_tables, int ntables,
                              const char *const *ignore_prefixes, struct mps_err *err);

void mps_case_destroy(struct mps_case **c);

/* Typed getters. The key is printf-formatted ("fluid.blocks.%d.x0", i). The key
 * must match a spec; a key absent from the file gives the spec default. Asking
 * for an undeclared key, or an absent key with no default, is a programmer
 * error: it aborts with a message (use mps_case_has first for optional keys). */
double mps_case_double(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
long mps_case_int(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
int mps_case_bool(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* STRING and ENUM values; the pointer lives as long as c. */
const char *mps_case_string(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* 1 if the key was given in the file or by --set, or has a default. */
int mps_case_has(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* The value of key as written (file or --set), for any key present, declared
 * or under an ignored prefix (e.g. the solid reading fluid.tank.width for
 * Eq. 55); NULL if absent. No default is filled in and nothing is parsed. */
const char *mps_case_text(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Number of items in the sequence at prefix ("fluid.blocks"): 1 + the largest
 * index present, 0 if none. */
int mps_case_count(const struct mps_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* "case.yml:14" (or "--set" or "default") for the key, for error messages from
 * checks that span several keys, e.g. a fluid block outside the tank. */
const char *mps_case_where(const struct mps_case *c, const char *key);

/* Builds an input error "WHERE: KEY = VALUE: problem" for key, as the loader
 * does, for semantic checks made by the solvers. Returns MPS_EINPUT. */
enum mps_status mps_case_fail(const struct mps_case *c, struct mps_err *err, const char *key,
                              const char *fmt, ...) __attribute__((format(printf, 4, 5)));

/* Path of the case file as given, and its directory (for relative paths). */
const char *mps_case_path(const struct mps_case *c);
/* The file to name in a message about the case as a whole or a key it lacks:
 * for a resolved copy (mps_case_write_resolved), the user's case it was
 * resolved from, as the coupler named it; else mps_case_path. */
const char *mps_case_origin(const struct mps_case *c);
const char *mps_case_dir(const struct mps_case *c);

/* The resolved configuration (every declared key with its value, defaults
 * included, plus ignored keys verbatim) as YAML text, sorted by key.
 * The caller frees the returned string. This goes into every output file. */
char *mps_case_resolved_yaml(const struct mps_case *c);

/* Writes the resolved configuration to path as a YAML file that
 * mps_case_load reads back to the same values (used by the coupler to hand
 * one resolved case to every solver), after a comment line naming the case
 * and the comment lines given (each "# ...\n"; NULL: none), and followed by
 * comment lines saying where each key was given, which mps_case_load reads
 * back too: a solver's message about a key of the copy names the user's
 * "case.yml:14" or "--set KEY=VALUE", as the coupler's would. Written
 * through path.tmp and rename(), so a reader never sees half a file. */
enum mps_status mps_case_write_resolved(const struct mps_case *c, const char *path,
                                        const char *comment, struct mps_err *err);

/* Prints the spec tables as Markdown (--keys): a "## TITLE" section per
 * table (titles[t]), a line per key with its type, units, default, bounds
 * and help. */
void mps_case_print_keys(FILE *f, const struct mps_key_spec *const *tables,
                         const char *const *titles, int ntables);

/* Specs every program shares: dp, end_time, gravity, output.*. */
extern const struct mps_key_spec mps_case_common_keys[];
#define MPS_CASE_COMMON_KEYS_TITLE "Every program: the run, gravity, output"

#endif
