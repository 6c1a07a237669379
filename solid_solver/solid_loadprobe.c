#include "solid_loadprobe.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int solid_probe_is_load(enum solid_probe_kind kind)
{
    return kind == SOLID_PROBE_FORCE_X || kind == SOLID_PROBE_FORCE_Y ||
           kind == SOLID_PROBE_MOMENT;
}

void solid_load_probes_init(struct solid_load_probes *lp, const struct solid_scene *s)
{
    memset(lp, 0, sizeof *lp);
    for (int k = 0; k < s->nprobes; k++)
        lp->active |= solid_probe_is_load(s->probes[k].kind);
}

void solid_load_probes_free(struct solid_load_probes *lp)
{
    free(lp->idx);
    free(lp->force);
    memset(lp, 0, sizeof *lp);
}

enum mps_status solid_load_probes_set(struct solid_load_probes *lp, const struct solid_loads *f,
                                      struct mps_err *err)
{
    lp->n = 0;
    if (!lp->active || !f || f->n == 0)
        return MPS_OK;
    if (f->n > lp->cap) {
        size_t *idx = realloc(lp->idx, f->n * sizeof *idx);
        if (idx)
            lp->idx = idx;
        double(*fo)[MPS_DIM] = realloc(lp->force, f->n * sizeof *fo);
        if (fo)
            lp->force = fo;
        if (!idx || !fo)
            return mps_err_set(err, MPS_ENOMEM, "solid: out of memory for %zu load probes", f->n);
        lp->cap = f->n;
    }
    for (size_t k = 0; k < f->n; k++) {
        lp->idx[k] = (size_t)f->id[k];
        memcpy(lp->force[k], f->force[k], sizeof lp->force[k]);
    }
    lp->n = f->n;
    return MPS_OK;
}

/* The load of probe k now: the force on its body (or all), or its moment
 * M = sum (x_i - x0) x F_i about the probe's point. */
static double load_now(const struct solid_load_probes *lp, const struct solid_probe_def *d,
                       const int *body, const double (*x)[MPS_DIM])
{
    double v = 0.0;
    for (size_t k = 0; k < lp->n; k++) {
        size_t i = lp->idx[k];
        if (d->body >= 0 && body[i] != d->body)
            continue;
        const double *F = lp->force[k];
        switch (d->kind) {
        case SOLID_PROBE_FORCE_X: v += F[0]; break;
        case SOLID_PROBE_FORCE_Y: v += F[1]; break;
        default: v += (x[i][0] - d->x) * F[1] - (x[i][1] - d->y) * F[0]; break;
        }
    }
    return v;
}

void solid_load_probes_step(struct solid_load_probes *lp, const struct solid_scene *s,
                            const int *body, const double (*x)[MPS_DIM], double dt)
{
    if (!lp->active)
        return;
    for (int k = 0; k < s->nprobes; k++)
        if (solid_probe_is_load(s->probes[k].kind))
            lp->sum[k] += dt * load_now(lp, &s->probes[k], body, x);
    lp->time += dt;
}

double solid_load_probes_value(const struct solid_load_probes *lp, const struct solid_scene *s,
                               int k, const int *body, const double (*x)[MPS_DIM])
{
    return lp->time > 0.0 ? lp->sum[k] / lp->time : load_now(lp, &s->probes[k], body, x);
}

void solid_load_probes_restart(struct solid_load_probes *lp)
{
    memset(lp->sum, 0, sizeof lp->sum);
    lp->time = 0.0;
}
