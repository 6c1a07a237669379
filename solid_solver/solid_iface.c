#include "solid_iface.h"
#include <stdlib.h>
#include "mps_nbr.h"

static void free_arrays(struct solid_iface_cache *c)
{
    free(c->idx);
    free(c->id);
    free(c->x);
    free(c->v);
    free(c->surface);
    free(c->fixed);
}

void solid_iface_cache_init(struct solid_iface_cache *c)
{
    *c = (struct solid_iface_cache){0};
    c->depth = -1.0;
}

enum mps_status solid_iface_cache_build(struct solid_iface_cache *c, size_t n,
                                        const double (*x0)[MPS_DIM],
                                        const unsigned char *surface, const int *id,
                                        const unsigned char *fixed, double depth,
                                        struct mps_err *err)
{
    unsigned char *keep = calloc(n + 1, 1);
    if (!keep)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    enum mps_status st = MPS_OK;
    for (size_t i = 0; i < n; i++)
        keep[i] = surface[i];
    if (depth > 0.0) {
        struct mps_nbr_grid g = {0};
        struct mps_nbr_list l = {0};
        double rad = depth * (1.0 + 1e-9);
        st = mps_nbr_grid_build(&g, n, x0, rad, err);
        if (st == MPS_OK)
            st = mps_nbr_list_build(&l, &g, x0, n, rad, err);
        for (size_t i = 0; st == MPS_OK && i < n; i++)
            for (size_t e = l.start[i]; !keep[i] && e < l.start[i + 1]; e++)
                keep[i] = surface[l.j[e]] ? 2 : 0;
        mps_nbr_list_free(&l);
        mps_nbr_grid_free(&g);
    }
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        m += keep[i] != 0;
    free_arrays(c);
    c->idx = malloc((m + 1) * sizeof *c->idx);
    c->id = malloc((m + 1) * sizeof *c->id);
    c->x = malloc((m + 1) * sizeof *c->x);
    c->v = malloc((m + 1) * sizeof *c->v);
    c->surface = malloc(m + 1);
    c->fixed = malloc(m + 1);
    if (st == MPS_OK && (!c->idx || !c->id || !c->x || !c->v || !c->surface || !c->fixed))
        st = mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    if (st == MPS_OK) {
        m = 0;
        for (size_t i = 0; i < n; i++)
            if (keep[i]) {
                c->idx[m] = i;
                c->id[m] = id[i];
                c->surface[m] = keep[i] == 1;
                c->fixed[m] = fixed[i];
                m++;
            }
        c->n = m;
        c->depth = depth;
    } else {
        c->n = 0;
        c->depth = -1.0;
    }
    free(keep);
    return st;
}

void solid_iface_cache_fill(struct solid_iface_cache *c, const double (*x)[MPS_DIM],
                            const double (*v)[MPS_DIM], struct solid_iface *out)
{
    for (size_t k = 0; k < c->n; k++) {
        size_t i = c->idx[k];
        for (int a = 0; a < MPS_DIM; a++) {
            c->x[k][a] = x[i][a];
            c->v[k][a] = v[i][a];
        }
    }
    *out = (struct solid_iface){c->n, c->id, (const double(*)[MPS_DIM])c->x,
                                (const double(*)[MPS_DIM])c->v, c->surface, c->fixed};
}

void solid_iface_cache_free(struct solid_iface_cache *c)
{
    free_arrays(c);
    solid_iface_cache_init(c);
}
