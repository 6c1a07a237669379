/* The command line every program shares:
 *   PROGRAM CASE.yml --out DIR [--set key=value]... [--quiet] [--stop-at T] [extra options]
 *   PROGRAM --restart DIR [--from T] [--set end_time=T] [--quiet] [--stop-at T]
 * The second continues the run in DIR from its latest checkpoint, or the
 * one nearest to --from T (docs/restart.md). --stop-at T stops a run at
 * its first checkpoint at or after simulated time T, as if killed there.
 * Extra options are declared by the program as name + whether they take a
 * value; anything else is an error naming the option. */
#ifndef MPS_CLI_H
#define MPS_CLI_H

#include <stddef.h>

#include "mps_err.h"

#define MPS_CLI_MAX_SETS 256
#define MPS_CLI_MAX_EXTRA 16

struct mps_cli_extra {
    const char *name;    /* "--model" */
    int takes_value;
    const char *help;
    const char *value;   /* filled: the value, or "1" for a flag given; NULL if absent */
};

struct mps_cli {
    const char *case_path;
    const char *out_dir;          /* NULL if --out not given */
    const char *sets[MPS_CLI_MAX_SETS];
    int nsets;
    int quiet;
    const char *restart_dir;      /* --restart DIR (then out_dir = DIR, no case_path) */
    double restart_from;          /* --from T, or -1: the latest checkpoint */
    double stop_at;               /* --stop-at T, or INFINITY */
    int keys;                     /* --keys: list the case keys (mps_case_print_keys) */
};

/* Parses argv. extra (may be NULL) is an array of nextra options, filled in
 * place. "--help" prints usage (with the extras' help) to stdout and returns
 * MPS_EINTR so main can exit 0 after it; "--keys" sets cli->keys and returns
 * MPS_EINTR, for main to print its key tables. */
enum mps_status mps_cli_parse(struct mps_cli *cli, int argc, char **argv,
                              struct mps_cli_extra *extra, int nextra, const char *usage,
                              struct mps_err *err);

/* Absolute, canonical form of an existing path into buf (size len); NULL on
 * failure (errno set). */
char *mps_realpath(const char *path, char *buf, size_t len);

/* Creates a directory and its parents (like mkdir -p). */
enum mps_status mps_mkdir_p(const char *path, struct mps_err *err);

#endif
