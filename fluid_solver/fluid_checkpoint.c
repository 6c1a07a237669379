#include "fluid_checkpoint.h"

#include <string.h>

enum mps_status fluid_ckpt_save(const struct fluid *f, struct fluid_ckpt *c, struct mps_err *err)
{
    if (strcmp(fluid_linsolve_method(f->ls), "cholmod_reuse") == 0)
        return mps_err_set(err, MPS_EINPUT,
                           "fluid.ppe_solver = cholmod_reuse keeps the ordering of earlier "
                           "solves, so a repeated step would not repeat bit for bit: use "
                           "another solver with coupling.scheme: implicit");
    enum mps_status st;
    if ((st = mps_particles_save(&f->ps, &c->ps, err)) ||
        (st = mps_nbr_list_copy(&c->nl, &f->nl, err)) ||
        (st = mps_nbr_list_copy(&c->nl_tank, &f->nl_tank, err)))
        return st;
    c->nfluid = f->nfluid;
    c->nfixed_end = f->nfixed_end;
    c->time = f->time;
    c->dt_last = f->dt_last;
    c->load_scale = f->load_scale;
    c->step = f->step;
    c->lost = f->lost;
    c->wall_guard = f->wall_guard;
    c->solid_placed = f->solid_placed;
    fluid_sensors_keep(f, &c->sens);
    c->valid = 1;
    return MPS_OK;
}

enum mps_status fluid_ckpt_restore(struct fluid *f, const struct fluid_ckpt *c,
                                   struct mps_err *err)
{
    if (!c->valid)
        return mps_err_set(err, MPS_EINPUT, "fluid: restore without a save");
    enum mps_status st;
    if ((st = mps_particles_restore(&f->ps, &c->ps, err)) ||
        (st = mps_nbr_list_copy(&f->nl, &c->nl, err)) ||
        (st = mps_nbr_list_copy(&f->nl_tank, &c->nl_tank, err)))
        return st;
    f->nfluid = c->nfluid;
    f->nfixed_end = c->nfixed_end;
    f->time = c->time;
    f->dt_last = c->dt_last;
    f->load_scale = c->load_scale;
    f->step = c->step;
    f->lost = c->lost;
    f->wall_guard = c->wall_guard;
    f->solid_placed = c->solid_placed;
    fluid_sensors_back(f, &c->sens);
    return MPS_OK;
}

void fluid_ckpt_free(struct fluid_ckpt *c)
{
    mps_particles_ckpt_free(&c->ps);
    mps_nbr_list_free(&c->nl);
    mps_nbr_list_free(&c->nl_tank);
    memset(c, 0, sizeof *c);
}
