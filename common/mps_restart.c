#include "mps_restart.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "mps_host.h"
#include "mps_simd.h"
#include "mps_version.h"

static unsigned arith_what;

void mps_run_arith_set(unsigned what)
{
    arith_what = what;
}

/* "build=REV\ncpu=MODEL\n", then "threads=N\n" and "paths=P\n" where they
 * count: one line a key, so that a note can name what differs. */
static void arith_describe(char *buf, size_t len)
{
    char cpu[256];
    mps_host_describe(cpu, sizeof cpu);
    char *count = strrchr(cpu, ','); /* ", N CPUs": how many does not change a sum */
    if (count)
        *count = '\0';
    size_t k = (size_t)snprintf(buf, len, "build=%s\ncpu=%s\n", mps_git_rev, cpu);
    if ((arith_what & MPS_ARITH_THREADS) && k < len)
        k += (size_t)snprintf(buf + k, len - k, "threads=%d\n", omp_get_max_threads());
    if ((arith_what & MPS_ARITH_SIMD) && k < len)
        snprintf(buf + k, len - k, "paths=%s\n", mps_simd_wide() ? "avx512" : "portable");
}

/* The value of key in a description into out (size len; "" if absent). */
static void arith_value(const char *desc, const char *key, char *out, size_t len)
{
    out[0] = '\0';
    const size_t kl = strlen(key);
    for (const char *line = desc; *line;) {
        const char *end = strchr(line, '\n');
        const size_t ll = end ? (size_t)(end - line) : strlen(line);
        if (ll > kl && line[kl] == '=' && strncmp(line, key, kl) == 0) {
            snprintf(out, len, "%.*s", (int)(ll - kl - 1), line + kl + 1);
            return;
        }
        line += ll + (end != NULL);
    }
}

void mps_run_arith_check(const struct mps_ckpt *c, const char *program, const char *path,
                         char *note, size_t len)
{
    static const char *const keys[] = {"build", "cpu", "threads", "paths"};
    const void *data;
    size_t bytes;
    note[0] = '\0';
    if (!mps_ckpt_peek(c, "arith", &data, &bytes) || !bytes ||
        ((const char *)data)[bytes - 1] != '\0')
        return;
    char now[512], was[256], is[256];
    arith_describe(now, sizeof now);
    size_t k = 0;
    for (size_t i = 0; i < sizeof keys / sizeof *keys && k < len; i++) {
        arith_value(data, keys[i], was, sizeof was);
        arith_value(now, keys[i], is, sizeof is);
        if (strcmp(was, is) != 0)
            k += (size_t)snprintf(note + k, len - k, "%s%s %s -> %s", k ? ", " : "", keys[i],
                                  was[0] ? was : "?", is[0] ? is : "?");
    }
    if (note[0])
        fprintf(stderr,
                "%s: note: %s was written with other arithmetic (%s): the run continues with "
                "the same physics, but not necessarily bit for bit as it would have gone on "
                "(docs/restart.md)\n",
                program, path, note);
}

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
    char arith[512];
    arith_describe(arith, sizeof arith);
    if ((st = mps_ckpt_put(c, "case", case_yaml, strlen(case_yaml) + 1, err)) ||
        (st = mps_ckpt_put(c, "run", m, sizeof *m, err)) ||
        (st = mps_ckpt_put(c, "arith", arith, strlen(arith) + 1, err)) ||
        (st = mps_h5_put(h5, c, err)) ||
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
    const void *arith; /* read by mps_run_arith_check; older builds wrote none */
    size_t alen;
    if (mps_ckpt_has(c, "arith") && (st = mps_ckpt_get_any(c, "arith", &arith, &alen, err)))
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
