#include "coupler_record.h"

#include "coupler_keys.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void coupler_record_init(struct coupler_record *r, const struct mps_cli *cli,
                         const char *solid_cmd, const char *fluid_cmd)
{
    memset(r, 0, sizeof *r);
    r->case_path = cli->case_path;
    for (int k = 0; k < cli->nsets; k++)
        r->sets[r->nsets++] = cli->sets[k];
    /* --solid/--fluid are the case keys solid_solver/fluid_solver, applied
     * last: the record names the program that ran */
    if (solid_cmd) {
        snprintf(r->solid_set, sizeof r->solid_set, "solid_solver=%s", solid_cmd);
        r->sets[r->nsets++] = r->solid_set;
    }
    if (fluid_cmd) {
        snprintf(r->fluid_set, sizeof r->fluid_set, "fluid_solver=%s", fluid_cmd);
        r->sets[r->nsets++] = r->fluid_set;
    }
    /* room is left for the solvers' HELLO sets= */
    mps_prov_sets(r->sets, &r->nsets, COUPLER_RECORD_MAX_SETS - COUPLER_RECORD_HELLO_SETS);
}

enum mps_status coupler_record_write(const struct coupler_record *r, const struct mps_case *c,
                                     struct mps_err *err)
{
    char *prov = mps_prov_comment(c, "coupler");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = prov ? open_memstream(&buf, &len) : NULL;
    if (!f) {
        free(prov);
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", r->path);
    }
    fputs(prov, f);
    for (int k = 0; k < COUPLER_RECORD_PEERS; k++)
        if (r->hello[k][0])
            fprintf(f, "# %s\n", r->hello[k]);
    int bad = ferror(f);
    bad |= fclose(f) != 0; /* the stream's buffer is only complete after it */
    free(prov);
    enum mps_status st = bad ? mps_err_set(err, MPS_ENOMEM, "%s: out of memory", r->path)
                             : mps_case_write_resolved(c, r->path, buf, err);
    free(buf);
    return st;
}

enum mps_status coupler_record_hello(struct coupler_record *r, struct mps_case **c, int peer,
                                     const char *command, const char *model, const char *sets,
                                     struct mps_err *err)
{
    const char *role = peer == COUPLER_RECORD_SOLID ? "solid" : "fluid";
    /* our solid_solver without --model says "case": it runs solid.model */
    snprintf(r->hello[peer], sizeof r->hello[peer], "%s program: %s (HELLO model=%s%s)", role,
             command, model, strcmp(model, "case") == 0 ? ": the case's solid.model" : "");
    /* HELLO sets=KEY:VALUE,...: keys of the solver's own section that its
     * command line set (solid_solver --model tlsph: solid.model:tlsph). The
     * solver owns them, so they are taken as said; keys of another section
     * are not the solver's to set and are left out. */
    char section[8];
    snprintf(section, sizeof section, "%s.", role);
    int n = r->nsets;
    for (const char *p = sets ? sets : "";
         *p && n < COUPLER_RECORD_MAX_SETS && r->nhello < COUPLER_RECORD_HELLO_SETS;) {
        size_t len = strcspn(p, ",");
        const char *colon = memchr(p, ':', len);
        char *item = r->hello_sets[r->nhello];
        if (colon && strncmp(p, section, strlen(section)) == 0 && colon > p + strlen(section) &&
            (size_t)snprintf(item, sizeof r->hello_sets[0], "%.*s=%.*s", (int)(colon - p), p,
                             (int)(len - (size_t)(colon - p) - 1),
                             colon + 1) < sizeof r->hello_sets[0]) {
            r->sets[n++] = item;
            r->nhello++;
        }
        p += len + (p[len] == ',');
    }
    if (n > r->nsets) {
        struct mps_case *again = NULL;
        struct mps_err ignored;
        if (mps_case_load(&again, r->case_path, r->sets, n, coupler_case_tables, COUPLER_NTABLES,
                          coupler_solver_sections, &ignored) == MPS_OK) {
            mps_case_destroy(c);
            *c = again;
            r->nsets = n;
        }
    }
    return coupler_record_write(r, *c, err);
}
