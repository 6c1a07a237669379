#include "mps_probes.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

struct mps_probes {
    FILE *f;
    int n;
    char *path;
};

/* A header cell, quoted (RFC 4180) only when it needs to be. */
static void csv_cell(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\r\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* Flushes and reports a write error; the row is on disk when this returns OK. */
static enum mps_status flush_row(struct mps_probes *p, struct mps_err *err)
{
    if (fflush(p->f) != 0 || ferror(p->f)) {
        int e = errno;
        clearerr(p->f);
        return mps_err_set(err, MPS_EIO, "cannot write '%s': %s", p->path, strerror(e));
    }
    return MPS_OK;
}

/* A probes file object for path with n columns (no file yet). */
static enum mps_status alloc_probes(struct mps_probes **out, const char *path, int n,
                                    struct mps_err *err)
{
    *out = NULL;
    struct mps_probes *p = calloc(1, sizeof *p);
    size_t len = strlen(path) + 1;
    if (!p || !(p->path = malloc(len))) {
        free(p);
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    }
    memcpy(p->path, path, len);
    p->n = n;
    *out = p;
    return MPS_OK;
}

enum mps_status mps_probes_check_names(const char *const *names, int n, const char *case_path,
                                       struct mps_err *err)
{
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++)
            if (names[a] && names[b] && !strcmp(names[a], names[b]))
                return mps_err_set(err, MPS_EINPUT,
                                   "%s: two probes named '%s' share probes.csv (fluid.probes, "
                                   "solid.probes, a solver's own probes and the coupler's "
                                   "solid_fx, solid_fy, coupling_iterations): rename one",
                                   case_path ? case_path : "case", names[a]);
    return MPS_OK;
}

enum mps_status mps_probes_open(struct mps_probes **out, const char *path, const char *comment,
                                const char *const *names, int n, struct mps_err *err)
{
    *out = NULL;
    if (n < 0 || (n > 0 && !names))
        return mps_err_set(err, MPS_EINPUT, "%s: bad probe list (%d probes)", path, n);
    struct mps_probes *p;
    enum mps_status st = alloc_probes(&p, path, n, err);
    if (st)
        return st;
    if (!(p->f = fopen(path, "w"))) {
        st = mps_err_set(err, MPS_EIO, "cannot create '%s': %s", path, strerror(errno));
        mps_probes_close(&p);
        return st;
    }
    if (comment)
        fputs(comment, p->f);
    fputs("time", p->f);
    for (int k = 0; k < n; k++) {
        fputc(',', p->f);
        csv_cell(p->f, names[k] ? names[k] : "");
    }
    fputc('\n', p->f);
    st = flush_row(p, err);
    if (st != MPS_OK) {
        mps_probes_close(&p);
        return st;
    }
    *out = p;
    return MPS_OK;
}

long mps_probes_bytes(const struct mps_probes *p)
{
    return p ? ftell(p->f) : 0;
}

enum mps_status mps_table_continue(FILE **f, const char *path, long bytes, struct mps_err *err)
{
    struct stat sb;
    *f = NULL;
    if (stat(path, &sb) != 0 || sb.st_size < bytes)
        return mps_err_set(err, MPS_EINPUT, "%s: %s than the checkpoint's %ld bytes: not the "
                           "file the checkpoint was written with", path,
                           stat(path, &sb) != 0 ? "missing, shorter" : "shorter", bytes);
    if (truncate(path, bytes) != 0 || !(*f = fopen(path, "a")) || fseek(*f, 0, SEEK_END) != 0) {
        int e = errno;
        if (*f)
            fclose(*f);
        *f = NULL;
        return mps_err_set(err, MPS_EIO, "cannot continue '%s': %s", path, strerror(e));
    }
    return MPS_OK;
}

enum mps_status mps_probes_resume(struct mps_probes **out, const char *path, long bytes, int n,
                                  struct mps_err *err)
{
    struct mps_probes *p;
    enum mps_status st = alloc_probes(out, path, n, err);
    if (st)
        return st;
    p = *out;
    *out = NULL;
    if ((st = mps_table_continue(&p->f, path, bytes, err))) {
        mps_probes_close(&p);
        return st;
    }
    *out = p;
    return MPS_OK;
}

enum mps_status mps_probes_write(struct mps_probes *p, double time, const double *values,
                                 struct mps_err *err)
{
    fprintf(p->f, "%.9g", time);
    for (int k = 0; k < p->n; k++)
        fprintf(p->f, ",%.9g", values[k]);
    fputc('\n', p->f);
    return flush_row(p, err);
}

void mps_probes_close(struct mps_probes **p)
{
    if (!p || !*p)
        return;
    if ((*p)->f)
        fclose((*p)->f);
    free((*p)->path);
    free(*p);
    *p = NULL;
}
