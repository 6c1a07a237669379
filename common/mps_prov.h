/* Provenance: which command started a run, on which machine and when, so
 * every file a run writes says how it was made (docs/output.md).
 *
 * The record travels as case keys (run.command, run.hostname, run.host,
 * run.started; declared in mps_case_common_keys): a program started by the
 * user sets them from its own command line with mps_prov_sets(), so they go
 * into its resolved case and from there into every snapshot's /config; the
 * coupler's resolved case hands its own record to the solvers it launches,
 * which keep it. A value written in a case file is replaced. */
#ifndef MPS_PROV_H
#define MPS_PROV_H

#include "mps_case.h"
#include "mps_json.h"

#define MPS_PROV_NSETS 4

/* Records argv (shell-quoted, as one line), the host name, the CPU
 * (mps_host_describe) and the current UTC time. Call once, first thing in
 * main. */
void mps_prov_init(int argc, char *const *argv);

/* The command line recorded by mps_prov_init ("" before). */
const char *mps_prov_command(void);

/* Appends MPS_PROV_NSETS "run.KEY=VALUE" overrides (strings owned by this
 * module) to sets, which holds *n of room entries. Returns 0, or -1 (nothing
 * appended) when there is no room. */
int mps_prov_sets(const char **sets, int *n, int room);

/* "# key: value" lines for the top of a text output (probes.csv,
 * case_resolved.yml): program with version and git revision, case path, and
 * the case's run.* record. The caller frees it; NULL when out of memory. */
char *mps_prov_comment(const struct mps_case *c, const char *program);

/* The case's run.* record as summary members: command, hostname, started. */
void mps_prov_json(const struct mps_case *c, struct mps_json *j);

#endif
