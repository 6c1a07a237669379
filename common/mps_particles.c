#include "mps_particles.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static size_t field_bytes(const struct mps_pfield *f)
{
    size_t s = f->type == MPS_F64 ? sizeof(double) : f->type == MPS_I32 ? sizeof(int) : 1;
    return s * (size_t)f->ncomp;
}

void mps_particles_init(struct mps_particles *ps)
{
    memset(ps, 0, sizeof *ps);
}

void mps_particles_add_field(struct mps_particles *ps, const char *name, int ncomp,
                             enum mps_field_type type, void **data, const char *units,
                             int output)
{
    if (ps->nfields >= MPS_PARTICLES_MAX_FIELDS)
        abort(); /* programmer error: raise MPS_PARTICLES_MAX_FIELDS */
    ps->f[ps->nfields++] = (struct mps_pfield){name, ncomp, type, data, units, output, NULL};
}

void mps_particles_set_legend(struct mps_particles *ps, const char *name, const char *legend)
{
    for (int k = 0; k < ps->nfields; k++)
        if (strcmp(ps->f[k].name, name) == 0) {
            ps->f[k].legend = legend;
            return;
        }
    abort(); /* programmer error: no such field */
}

enum mps_status mps_particles_resize(struct mps_particles *ps, size_t n, struct mps_err *err)
{
    if (n > ps->cap) {
        size_t cap = ps->cap ? ps->cap : 64;
        while (cap < n)
            cap *= 2;
        for (int k = 0; k < ps->nfields; k++) {
            struct mps_pfield *f = &ps->f[k];
            size_t b = field_bytes(f);
            void *p = realloc(*f->data, cap * b);
            if (!p)
                return mps_err_set(err, MPS_ENOMEM, "particles: cannot grow field %s to %zu",
                                   f->name, cap);
            memset((char *)p + ps->cap * b, 0, (cap - ps->cap) * b);
            *f->data = p;
        }
        ps->cap = cap;
    }
    if (n > ps->n)
        for (int k = 0; k < ps->nfields; k++) {
            size_t b = field_bytes(&ps->f[k]);
            memset((char *)*ps->f[k].data + ps->n * b, 0, (n - ps->n) * b);
        }
    ps->n = n;
    return MPS_OK;
}

/* new[i] = old[perm[i]] for one array of m elements of b bytes, through tmp.
 * The common sizes are copied as whole words: a memcpy call per element
 * (its size only known at run time) made the reordering cost more than
 * what it saves the neighbour search. */
static void permute_array(char *restrict d, char *restrict tmp, size_t b, const size_t *perm,
                          size_t m)
{
    switch (b) {
    case 1:
        for (size_t i = 0; i < m; i++)
            tmp[i] = d[perm[i]];
        break;
    case 4:
        for (size_t i = 0; i < m; i++)
            memcpy(tmp + 4 * i, d + 4 * perm[i], 4);
        break;
    case 8:
        for (size_t i = 0; i < m; i++)
            memcpy(tmp + 8 * i, d + 8 * perm[i], 8);
        break;
    case 16:
        for (size_t i = 0; i < m; i++)
            memcpy(tmp + 16 * i, d + 16 * perm[i], 16);
        break;
    default:
        for (size_t i = 0; i < m; i++)
            memcpy(tmp + b * i, d + b * perm[i], b);
    }
    memcpy(d, tmp, m * b);
}

enum mps_status mps_particles_permute(struct mps_particles *ps, const size_t *perm, size_t m,
                                      struct mps_err *err)
{
    if (m > ps->n)
        return mps_err_set(err, MPS_EINPUT, "particles: reordering %zu of %zu", m, ps->n);
    size_t maxb = 0;
    for (int k = 0; k < ps->nfields; k++)
        if (field_bytes(&ps->f[k]) > maxb)
            maxb = field_bytes(&ps->f[k]);
    /* the fields are independent: one per thread at a time, each thread
     * with its own buffer */
    const int nt = omp_get_max_threads();
    char *tmp = malloc((size_t)nt * (m * maxb + 64));
    if (!tmp)
        return mps_err_set(err, MPS_ENOMEM, "particles: no memory to reorder %zu", m);
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1) if (m >= 4096)
    for (int k = 0; k < ps->nfields; k++)
        permute_array(*ps->f[k].data, tmp + (size_t)omp_get_thread_num() * (m * maxb + 64),
                      field_bytes(&ps->f[k]), perm, m);
    free(tmp);
    return MPS_OK;
}

int mps_particles_output(const struct mps_particles *ps, struct mps_field *out, int max)
{
    int m = 0;
    for (int k = 0; k < ps->nfields && m < max; k++)
        if (ps->f[k].output)
            out[m++] = (struct mps_field){ps->f[k].name, ps->f[k].ncomp, ps->f[k].type,
                                          *ps->f[k].data, ps->f[k].units, ps->f[k].legend};
    return m;
}

void mps_particles_free(struct mps_particles *ps)
{
    for (int k = 0; k < ps->nfields; k++) {
        free(*ps->f[k].data);
        *ps->f[k].data = NULL;
    }
    ps->n = ps->cap = 0;
}

enum mps_status mps_particles_put(const struct mps_particles *ps, struct mps_ckpt *c,
                                  struct mps_err *err)
{
    uint64_t n = ps->n;
    enum mps_status st = mps_ckpt_put(c, "particles", &n, sizeof n, err);
    for (int k = 0; k < ps->nfields && !st; k++)
        st = mps_ckpt_put(c, ps->f[k].name, *ps->f[k].data, ps->n * field_bytes(&ps->f[k]), err);
    return st;
}

enum mps_status mps_particles_get(struct mps_particles *ps, struct mps_ckpt *c,
                                  struct mps_err *err)
{
    uint64_t n;
    enum mps_status st = mps_ckpt_get(c, "particles", &n, sizeof n, err);
    if (st || (st = mps_particles_resize(ps, (size_t)n, err)))
        return st;
    for (int k = 0; k < ps->nfields && !st; k++)
        st = mps_ckpt_get(c, ps->f[k].name, *ps->f[k].data, ps->n * field_bytes(&ps->f[k]), err);
    return st;
}
