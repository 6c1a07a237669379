/* probes.csv: comment lines "# key: value" saying how the run was made
 * (mps_prov_comment: program, version, case, command, host, start time), a
 * header row "time,<name>,..." and one row per probe interval. Readers skip
 * the lines starting with '#' (pandas: comment='#'). Each row is flushed as
 * written, so the file is complete up to the last row if the process dies. */
#ifndef MPS_PROBES_H
#define MPS_PROBES_H

#include <stdio.h>

#include "mps_err.h"

struct mps_probes;

/* comment: "# ..." lines written first, verbatim (NULL: none). */
/* MPS_EINPUT naming the case file and the name when two of the n names are
 * equal: probes.csv could not tell their columns apart. Every writer of a
 * probes.csv (fluid and solid alone, the coupler's merged table) asks it. */
enum mps_status mps_probes_check_names(const char *const *names, int n, const char *case_path,
                                       struct mps_err *err);
enum mps_status mps_probes_open(struct mps_probes **out, const char *path, const char *comment,
                                const char *const *names, int n, struct mps_err *err);
/* One row: time then n values (%.9g). */
enum mps_status mps_probes_write(struct mps_probes *p, double time, const double *values,
                                 struct mps_err *err);
/* Bytes written so far (header included): where a restart continues. */
long mps_probes_bytes(const struct mps_probes *p);
/* Continues path as written by a run up to its first bytes (mps_probes_bytes
 * at a checkpoint): the rows after them are cut, the next row follows. */
enum mps_status mps_probes_resume(struct mps_probes **out, const char *path, long bytes, int n,
                                  struct mps_err *err);
void mps_probes_close(struct mps_probes **p);

/* Any csv table a restart continues (probes.csv, the coupler's
 * iterations.csv): cuts path to its first bytes (its length at the
 * checkpoint) and opens it for appending into *f. MPS_EINPUT if the file is
 * missing or shorter (not the one the checkpoint was written with). */
enum mps_status mps_table_continue(FILE **f, const char *path, long bytes, struct mps_err *err);

#endif
