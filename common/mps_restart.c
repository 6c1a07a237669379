#include "mps_restart.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

int mps_run_due(long *k, double period, double t, double eps)
{
    if (!(period > 0.0) || t < (double)*k * period - eps)
        return 0;
    while ((double)*k * period <= t + eps)
        (*k)++;
    return 1;
}

enum mps_status mps_run_checkpoint(struct mps_ckpt *c, const char *dir, const char *prefix,
                                   const char *case_yaml, struct mps_run_mark *m,
                                   const struct mps_h5_series *h5, double time,
                                   mps_state_put_fn put, const void *self, struct mps_err *err)
{
    mps_ckpt_clear(c);
    enum mps_status st;
    if ((st = mps_ckpt_put(c, "case", case_yaml, strlen(case_yaml) + 1, err)) ||
        (st = mps_ckpt_put(c, "run", m, sizeof *m, err)) || (st = mps_h5_put(h5, c, err)) ||
        (st = put(self, c, err)))
        return st;
    return mps_ckpt_write_file(c, dir, prefix, m->number, time, NULL, 0, err);
}

/* Reads the checkpoint at path: its case (*yaml, in c) and mark. */
static enum mps_status read_head(struct mps_ckpt *c, const char *path, const char **yaml,
                                 struct mps_run_mark *m, struct mps_err *err)
{
    const void *y;
    size_t ylen;
    enum mps_status st;
    if ((st = mps_ckpt_read_file(c, path, err)) ||
        (st = mps_ckpt_get_any(c, "case", &y, &ylen, err)) ||
        (st = mps_ckpt_get(c, "run", m, sizeof *m, err)))
        return st;
    if (!ylen || ((const char *)y)[ylen - 1] != '\0')
        return mps_err_set(err, MPS_EINPUT, "%s: the case in the checkpoint is damaged", path);
    if (m->number != c->number)
        return mps_err_set(err, MPS_EINPUT, "%s: holds checkpoint %ld, named %ld", path,
                           m->number, c->number);
    *yaml = y;
    return MPS_OK;
}

enum mps_status mps_run_restart_open(struct mps_ckpt *c, const struct mps_cli *cli,
                                     const char *prefix, char *case_path, size_t len,
                                     struct mps_run_mark *m, struct mps_err *err)
{
    char path[4400];
    const char *yaml = NULL;
    enum mps_status st;
    if ((st = mps_ckpt_find(cli->restart_dir, prefix, cli->restart_from, path, sizeof path,
                            err)) ||
        (st = read_head(c, path, &yaml, m, err)))
        return st;
    snprintf(case_path, len, "%s/" MPS_CKPT_DIR "/restart_case.yml", cli->restart_dir);
    FILE *f = fopen(case_path, "w");
    if (!f)
        return mps_err_set(err, MPS_EIO, "cannot create '%s'", case_path);
    int bad = fputs(yaml, f) < 0;
    if (fclose(f) != 0 || bad)
        return mps_err_set(err, MPS_EIO, "cannot write '%s'", case_path);
    return MPS_OK;
}

enum mps_status mps_run_read(struct mps_ckpt *c, const char *dir, const char *prefix,
                             long number, struct mps_run_mark *m, struct mps_err *err)
{
    char path[4400];
    const char *yaml = NULL;
    mps_ckpt_path(path, sizeof path, dir, prefix, number);
    return read_head(c, path, &yaml, m, err);
}

enum mps_status mps_run_get_rest(struct mps_ckpt *c, struct mps_h5_series *h5,
                                 struct mps_err *err)
{
    return mps_h5_get(h5, c, err);
}
