#include "coupler_record.h"

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
    mps_prov_sets(r->sets, &r->nsets, (int)(sizeof r->sets / sizeof r->sets[0]) - 1);
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
    fclose(f);
    free(prov);
    enum mps_status st = bad ? mps_err_set(err, MPS_ENOMEM, "%s: out of memory", r->path)
                             : mps_case_write_resolved(c, r->path, buf, err);
    free(buf);
    return st;
}

enum mps_status coupler_record_hello(struct coupler_record *r, struct mps_case **c,
                                     const struct mps_key_spec *const *tables, int ntables,
                                     int peer, const char *command, const char *model,
                                     struct mps_err *err)
{
    const char *role = peer == COUPLER_RECORD_SOLID ? "solid" : "fluid";
    /* our solid_solver without --model says "case": it runs solid.model */
    snprintf(r->hello[peer], sizeof r->hello[peer], "%s program: %s (HELLO model=%s%s)", role,
             command, model, strcmp(model, "case") == 0 ? ": the case's solid.model" : "");
    if (peer == COUPLER_RECORD_SOLID && strcmp(model, mps_case_string(*c, "solid.model")) != 0 &&
        (size_t)snprintf(r->model_set, sizeof r->model_set, "solid.model=%s", model) <
            sizeof r->model_set) {
        /* A model the key cannot name (modal_beam, fake, or "case": the
         * case's own) leaves the case as it is; the comment says what ran. */
        int n = r->nsets;
        r->sets[n++] = r->model_set;
        struct mps_case *again = NULL;
        struct mps_err ignored;
        if (mps_case_load(&again, r->case_path, r->sets, n, tables, ntables, NULL, &ignored) ==
            MPS_OK) {
            mps_case_destroy(c);
            *c = again;
            r->nsets = n;
        }
    }
    return coupler_record_write(r, *c, err);
}
