#include "fluid_checkpoint.h"

#include <stdint.h>
#include <string.h>

/* The scalars, as one block (the order is the format). */
struct fluid_scalars {
    uint64_t nfluid, nfixed_end;
    double time, dt_last, dt_kappa, dt_kappa_expansion, load_scale;
    int64_t step, lost, wall_guard, solid_placed;
};

/* The tank guard's log (fluid_summary.json), a block of its own. */
struct fluid_guard_log {
    int64_t face[4], first_face;
    double first[3];
};

/* The lists, and the state past the particles without them: fluid_state_put
 * writes the file's order (particles, lists, the rest), the rollback two
 * images. */
static enum mps_status put_lists(const struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    enum mps_status st = mps_nbr_list_put(&f->nl, "nl", c, err);
    return st ? st : mps_nbr_list_put(&f->nl_tank, "nl_tank", c, err);
}

static enum mps_status put_rest(const struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    struct fluid_scalars sc = {f->nfluid, f->nfixed_end, f->time, f->dt_last, f->dt_kappa,
                               f->dt_kappa_expansion, f->load_scale,
                               f->step, f->lost, f->wall_guard, f->solid_placed};
    struct fluid_guard_log g = {{f->wall_guard_face[0], f->wall_guard_face[1],
                                 f->wall_guard_face[2], f->wall_guard_face[3]},
                                f->wall_guard_first_face,
                                {f->wall_guard_first[0], f->wall_guard_first[1],
                                 f->wall_guard_first[2]}};
    struct fluid_sensors_mark m;
    memset(&m, 0, sizeof m); /* padding: the image's bytes depend only on the state */
    fluid_sensors_keep(f, &m);
    enum mps_status st;
    if ((st = mps_ckpt_put(c, "fluid", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_put(c, "guard", &g, sizeof g, err)))
        return st;
    return mps_ckpt_put(c, "sensors", &m, sizeof m, err);
}

static enum mps_status get_lists(struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    enum mps_status st = mps_nbr_list_get(&f->nl, "nl", c, err);
    return st ? st : mps_nbr_list_get(&f->nl_tank, "nl_tank", c, err);
}

static enum mps_status get_rest(struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    struct fluid_scalars sc;
    struct fluid_guard_log g;
    struct fluid_sensors_mark m;
    enum mps_status st;
    if ((st = mps_ckpt_get(c, "fluid", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_get(c, "guard", &g, sizeof g, err)) ||
        (st = mps_ckpt_get(c, "sensors", &m, sizeof m, err)))
        return st;
    f->nfluid = (size_t)sc.nfluid;
    f->nfixed_end = (size_t)sc.nfixed_end;
    f->time = sc.time;
    f->dt_last = sc.dt_last;
    f->dt_kappa = sc.dt_kappa;
    f->dt_kappa_expansion = sc.dt_kappa_expansion;
    f->load_scale = sc.load_scale;
    f->step = (long)sc.step;
    f->lost = (long)sc.lost;
    f->wall_guard = (long)sc.wall_guard;
    for (int k = 0; k < 4; k++)
        f->wall_guard_face[k] = (long)g.face[k];
    f->wall_guard_first_face = (int)g.first_face;
    memcpy(f->wall_guard_first, g.first, sizeof g.first);
    f->solid_placed = (int)sc.solid_placed;
    fluid_sensors_back(f, &m);
    return MPS_OK;
}

enum mps_status fluid_state_put(const struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    enum mps_status st;
    if ((st = mps_particles_put(&f->ps, c, err)) || (st = put_lists(f, c, err)))
        return st;
    return put_rest(f, c, err);
}

enum mps_status fluid_state_get(struct fluid *f, struct mps_ckpt *c, struct mps_err *err)
{
    enum mps_status st;
    if ((st = mps_particles_get(&f->ps, c, err)) || (st = get_lists(f, c, err)))
        return st;
    f->nl_gen = ++f->nl_gen_next; /* lists from a file: like no other */
    return get_rest(f, c, err);
}

enum mps_status fluid_ckpt_save(const struct fluid *f, struct fluid_ckpt *c, struct mps_err *err)
{
    if (strcmp(fluid_linsolve_method(f->ls), "cholmod_reuse") == 0)
        return mps_err_set(err, MPS_EINPUT,
                           "fluid.ppe_solver = cholmod_reuse keeps the ordering of earlier "
                           "solves, so a repeated step would not repeat bit for bit: use "
                           "another solver with coupling.scheme: implicit");
    c->valid = 0;
    mps_ckpt_clear(&c->img);
    enum mps_status st = mps_particles_put(&f->ps, &c->img, err);
    if (!st)
        st = put_rest(f, &c->img, err);
    if (!st && (!c->lists_valid || c->lists_gen != f->nl_gen)) {
        c->lists_valid = 0;
        mps_ckpt_clear(&c->lists);
        if (!(st = put_lists(f, &c->lists, err))) {
            c->lists_valid = 1;
            c->lists_gen = f->nl_gen;
        }
    }
    c->valid = st == MPS_OK;
    return st;
}

enum mps_status fluid_ckpt_restore(struct fluid *f, struct fluid_ckpt *c, struct mps_err *err)
{
    if (!c->valid)
        return mps_err_set(err, MPS_EINPUT, "fluid: restore without a save");
    mps_ckpt_rewind(&c->img);
    enum mps_status st = mps_particles_get(&f->ps, &c->img, err);
    if (!st)
        st = get_rest(f, &c->img, err);
    if (!st && f->nl_gen != c->lists_gen) {
        mps_ckpt_rewind(&c->lists);
        if (!(st = get_lists(f, &c->lists, err)))
            f->nl_gen = c->lists_gen;
    }
    return st;
}

void fluid_ckpt_free(struct fluid_ckpt *c)
{
    mps_ckpt_free(&c->img);
    mps_ckpt_free(&c->lists);
    c->valid = 0;
    c->lists_valid = 0;
}
