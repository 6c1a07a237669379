#include "mps_particles.h"

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
    ps->f[ps->nfields++] = (struct mps_pfield){name, ncomp, type, data, units, output};
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

enum mps_status mps_particles_permute(struct mps_particles *ps, const size_t *perm,
                                      struct mps_err *err)
{
    size_t maxb = 0;
    for (int k = 0; k < ps->nfields; k++)
        if (field_bytes(&ps->f[k]) > maxb)
            maxb = field_bytes(&ps->f[k]);
    char *tmp = malloc(ps->n * maxb + 1);
    if (!tmp)
        return mps_err_set(err, MPS_ENOMEM, "particles: no memory to reorder %zu", ps->n);
    for (int k = 0; k < ps->nfields; k++) {
        size_t b = field_bytes(&ps->f[k]);
        char *d = *ps->f[k].data;
        for (size_t i = 0; i < ps->n; i++)
            memcpy(tmp + i * b, d + perm[i] * b, b);
        memcpy(d, tmp, ps->n * b);
    }
    free(tmp);
    return MPS_OK;
}

int mps_particles_output(const struct mps_particles *ps, struct mps_field *out, int max)
{
    int m = 0;
    for (int k = 0; k < ps->nfields && m < max; k++)
        if (ps->f[k].output)
            out[m++] = (struct mps_field){ps->f[k].name, ps->f[k].ncomp, ps->f[k].type,
                                          *ps->f[k].data, ps->f[k].units};
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
