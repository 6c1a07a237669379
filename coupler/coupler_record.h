/* The coupler's record of a run as it ran: the case it hands the solvers
 * (OUT/case_resolved.yml, read back by them into every snapshot's /config)
 * carries the user's --set, the solver commands actually launched (--solid,
 * --fluid), the model the solid announced in its HELLO when solid.model can
 * name it, and the run.* provenance (mps_prov.h); its comment header adds each
 * solver's command and HELLO model. */
#ifndef COUPLER_RECORD_H
#define COUPLER_RECORD_H

#include "mps_case.h"
#include "mps_cli.h"
#include "mps_prov.h"

enum { COUPLER_RECORD_FLUID = 0, COUPLER_RECORD_SOLID = 1, COUPLER_RECORD_PEERS = 2 };

/* a solver's HELLO sets= items the record takes, per run (both solvers) */
#define COUPLER_RECORD_HELLO_SETS 8
#define COUPLER_RECORD_MAX_SETS (MPS_CLI_MAX_SETS + 2 + MPS_PROV_NSETS + COUPLER_RECORD_HELLO_SETS)

struct coupler_record {
    const char *case_path;
    const char *sets[COUPLER_RECORD_MAX_SETS];
    int nsets;
    char solid_set[4200], fluid_set[4200];
    char hello_sets[COUPLER_RECORD_HELLO_SETS][256];
    int nhello;
    char path[4200];                           /* OUT/case_resolved.yml, absolute */
    char hello[COUPLER_RECORD_PEERS][320];     /* "fluid: COMMAND (model NAME)" */
};

/* Collects what the run's case is made of: the user's sets, then the solver
 * commands given on the command line (NULL: the case's), then provenance. */
void coupler_record_init(struct coupler_record *r, const struct mps_cli *cli,
                         const char *solid_cmd, const char *fluid_cmd);

/* Writes r->path (set by the caller) from c with the comment header. */
enum mps_status coupler_record_write(const struct coupler_record *r, const struct mps_case *c,
                                     struct mps_err *err);

/* Records a solver's HELLO (peer: COUPLER_RECORD_*; command as launched;
 * model as announced; sets: its HELLO sets= value, "KEY:VALUE,...", or NULL).
 * The items of sets in the solver's own section ("solid." for the solid) are
 * applied to the case after the user's: *c is reloaded with them. Then
 * rewrites the file. Call between the HELLO and the CONFIG that hands the
 * solver the file, so the solver reads the record of its own run. */
enum mps_status coupler_record_hello(struct coupler_record *r, struct mps_case **c, int peer,
                                     const char *command, const char *model, const char *sets,
                                     struct mps_err *err);

#endif
