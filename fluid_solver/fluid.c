#include "fluid.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_ppe.h"
#include "fluid_scene.h"
#include "mps_kernel.h"
#include "mps_ops.h"

static const char *const phase_names[PH_COUNT] = {
    "neighbours", "predict", "density", "ppe_assemble", "ppe_solve", "correct", "other"};

/* Skin added to the Laplacian radius so one neighbour list, built at the start
 * of a step, serves the prediction and the positions after it; a step that
 * moves a particle by more than half the skin rebuilds the list. */
#define SKIN_FRACTION 0.5

static void register_fields(struct fluid *f)
{
    struct mps_particles *ps = &f->ps;
    mps_particles_init(ps);
    mps_particles_add_field(ps, "velocity", MPS_DIM, MPS_F64, (void **)&f->v, "m/s", 1);
    mps_particles_add_field(ps, "pressure", 1, MPS_F64, (void **)&f->p, "Pa", 1);
    mps_particles_add_field(ps, "type", 1, MPS_I32, (void **)&f->type, "", 1);
    mps_particles_add_field(ps, "id", 1, MPS_I32, (void **)&f->id, "", 1);
    mps_particles_add_field(ps, "number_density", 1, MPS_F64, (void **)&f->nd, "", 1);
    mps_particles_add_field(ps, "free_surface", 1, MPS_U8, (void **)&f->surface, "", 1);
    mps_particles_add_field(ps, "position", MPS_DIM, MPS_F64, (void **)&f->x, "m", 0);
    mps_particles_add_field(ps, "vstar", MPS_DIM, MPS_F64, (void **)&f->vstar, "m/s", 0);
    mps_particles_add_field(ps, "laplacian", MPS_DIM, MPS_F64, (void **)&f->lap, "", 0);
    mps_particles_add_field(ps, "grad_p", MPS_DIM, MPS_F64, (void **)&f->grad, "Pa/m", 0);
    mps_particles_add_field(ps, "div_vstar", 1, MPS_F64, (void **)&f->div, "1/s", 0);
    mps_particles_add_field(ps, "ncount", 1, MPS_I32, (void **)&f->ncount, "", 0);
    mps_particles_add_field(ps, "row", 1, MPS_I32, (void **)&f->row, "", 0);
    mps_particles_add_field(ps, "has_p", 1, MPS_U8, (void **)&f->has_p, "", 0);
    mps_particles_add_field(ps, "is_fluid", 1, MPS_U8, (void **)&f->is_fluid, "", 0);
    mps_particles_add_field(ps, "grad_fallback", 1, MPS_U8, (void **)&f->fallback, "", 0);
}

void fluid_update_masks(struct fluid *f)
{
    for (size_t i = 0; i < f->ps.n; i++) {
        int t = f->type[i];
        f->is_fluid[i] = t == FLUID_P;
        f->has_p[i] = t == FLUID_P || t == WALL_P || t == SOLID_SURF_P;
    }
}

enum mps_status fluid_create(struct fluid **out, const struct fluid_params *prm,
                             struct mps_err *err)
{
    *out = NULL;
    struct fluid *f = calloc(1, sizeof *f);
    if (!f)
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory");
    f->prm = *prm;
    register_fields(f);
    mps_timer_init(&f->timer, phase_names, PH_COUNT);

    struct fluid_scene_pt *pts = NULL;
    size_t nf = 0, nw = 0;
    enum mps_status st;
    if (fluid_scene_build(prm, &pts, &nf, &nw)) {
        st = mps_err_set(err, MPS_ENOMEM, "fluid: out of memory building the tank");
        goto fail;
    }
    if (nf == 0) {
        free(pts);
        st = mps_err_set(err, MPS_EINPUT, "fluid: the case holds no water (fluid.blocks is empty "
                                          "or smaller than dp)");
        goto fail;
    }
    st = mps_particles_resize(&f->ps, nf + nw, err);
    if (st) {
        free(pts);
        goto fail;
    }
    for (size_t i = 0; i < nf + nw; i++) {
        memcpy(f->x[i], pts[i].x, sizeof f->x[i]);
        f->type[i] = pts[i].type;
        f->id[i] = (int)i;
    }
    free(pts);
    f->nfluid = nf;
    f->nfixed_end = nf + nw;
    fluid_update_masks(f);

    struct mps_lattice_consts cn = mps_lattice_consts(prm->dp, prm->re_n * prm->dp);
    struct mps_lattice_consts cl = mps_lattice_consts(prm->dp, prm->re_lap * prm->dp);
    f->n0 = cn.n0;
    f->count0 = cn.count;
    f->n0_lap = cl.n0;
    f->lambda_lap = cl.lambda;
    f->skin = SKIN_FRACTION * prm->dp;

    st = fluid_linsolve_create(&f->ls, prm->ppe_solver, prm->ppe_rtol, prm->ppe_max_iter, 0, err);
    if (st)
        goto fail;
    *out = f;
    return MPS_OK;
fail:
    fluid_destroy(&f);
    return st;
}

void fluid_destroy(struct fluid **pf)
{
    struct fluid *f = pf ? *pf : NULL;
    if (!f)
        return;
    mps_particles_free(&f->ps);
    mps_nbr_grid_free(&f->grid);
    mps_nbr_list_free(&f->nl);
    mps_nbr_list_free(&f->nl_n);
    free(f->wlap);
    free(f->rowptr);
    free(f->col);
    free(f->val);
    free(f->rhs);
    free(f->sol);
    fluid_linsolve_destroy(&f->ls);
    free(f);
    *pf = NULL;
}

double fluid_cfl_dt(const struct fluid *f)
{
    double vmax2 = 0.0;
#pragma omp parallel for reduction(max : vmax2)
    for (size_t i = 0; i < f->nfluid; i++) {
        double s = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            s += f->v[i][d] * f->v[i][d];
        if (s > vmax2)
            vmax2 = s;
    }
    /* Moving solid boundaries count too: the fluid must resolve them. */
    for (size_t i = f->nfixed_end; i < f->ps.n; i++) {
        double s = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            s += f->v[i][d] * f->v[i][d];
        if (s > vmax2)
            vmax2 = s;
    }
    double dt = f->prm.dt_max;
    if (vmax2 > 0.0) {
        double cfl = f->prm.courant * f->prm.dp / sqrt(vmax2);
        if (cfl < dt)
            dt = cfl;
    }
    /* Explicit viscosity (Eq. 16) is stable for dt < dp^2 / (2 d nu) roughly. */
    if (f->prm.nu > 0.0) {
        double dv = 0.2 * f->prm.dp * f->prm.dp / f->prm.nu;
        if (dv < dt)
            dt = dv;
    }
    return dt;
}

static enum mps_status build_neighbours(struct fluid *f, struct mps_err *err)
{
    const double radius = f->prm.re_lap * f->prm.dp + f->skin;
    enum mps_status st = mps_nbr_grid_build(&f->grid, f->ps.n, (const double(*)[MPS_DIM])f->x,
                                            radius, err);
    if (st)
        return st;
    f->nbr_rebuilds++;
    return mps_nbr_list_build(&f->nl, &f->grid, (const double(*)[MPS_DIM])f->x, f->ps.n, radius,
                              err);
}

/* Reorders the fluid segment by cell so neighbours sit close in memory. */
static enum mps_status reorder_fluid(struct fluid *f, struct mps_err *err)
{
    size_t n = f->ps.n, k = 0;
    size_t *perm = malloc(n * sizeof *perm);
    if (!perm)
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory reordering");
    for (size_t c = 0; c < f->grid.n; c++) {
        size_t i = f->grid.sorted[c];
        if (i < f->nfluid)
            perm[k++] = i;
    }
    for (size_t i = f->nfluid; i < n; i++)
        perm[i] = i;
    enum mps_status st = mps_particles_permute(&f->ps, perm, err);
    free(perm);
    return st;
}

/* Keeps fluid particles from interpenetrating: pairs closer than
 * collision_dist * dp that approach each other exchange momentum with the
 * given restitution (Koshizuka's collision model; fixed and solid particles
 * act as infinitely heavy). Computed from a frozen copy so the result does
 * not depend on loop order. */
static void collide(struct fluid *f, double dt)
{
    const double cd = f->prm.collision_dist * f->prm.dp, cd2 = cd * cd;
    const double e = f->prm.collision_restitution;
    if (cd <= 0.0)
        return;
    double(*vs)[MPS_DIM] = f->vstar;
    double(*dv)[MPS_DIM] = f->grad; /* scratch: grad is recomputed later */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->nfluid; i++) {
        double acc[MPS_DIM] = {0};
        for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1]; k++) {
            int j = f->nl_n.j[k];
            if (f->type[j] == DUMMY_P || f->type[j] == SOLID_INNER_P)
                continue;
            double dx[MPS_DIM], r2 = 0.0, vn = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                dx[d] = f->x[j][d] - f->x[i][d];
                r2 += dx[d] * dx[d];
            }
            if (r2 >= cd2 || r2 <= 0.0)
                continue;
            double r = sqrt(r2);
            for (int d = 0; d < MPS_DIM; d++)
                vn += (vs[i][d] - vs[j][d]) * dx[d] / r;
            if (vn <= 0.0)
                continue; /* separating */
            /* equal masses share the impulse; a fixed partner takes none */
            double share = f->is_fluid[j] ? 0.5 : 1.0;
            for (int d = 0; d < MPS_DIM; d++)
                acc[d] -= share * (1.0 + e) * vn * dx[d] / r;
        }
        for (int d = 0; d < MPS_DIM; d++)
            dv[i][d] = acc[d];
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->nfluid; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            vs[i][d] += dv[i][d];
            f->x[i][d] += dt * dv[i][d];
        }
}

static enum mps_status check_domain(const struct fluid *f, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    const double m = p->wall_layers * p->dp;
    const double ytop = p->tank_lid ? p->tank_h + m : 100.0 * (p->tank_h + m);
    for (size_t i = 0; i < f->nfluid; i++) {
        const double *x = f->x[i];
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(f->v[i][0]) ||
            !isfinite(f->v[i][1]) || !isfinite(f->p[i]))
            return mps_err_set(err, MPS_EDIVERGED,
                               "fluid particle %d has a non-finite state at t = %.6g s "
                               "(x = %g, %g; p = %g)",
                               f->id[i], f->time, x[0], x[1], f->p[i]);
        if (x[0] < -m || x[0] > p->tank_w + m || x[1] < -m || x[1] > ytop)
            return mps_err_set(err, MPS_EDIVERGED,
                               "fluid particle %d left the tank at t = %.6g s: x = %.4g, y = %.4g "
                               "(tank [0, %g] x [0, %g] plus walls)",
                               f->id[i], f->time, x[0], x[1], p->tank_w, p->tank_h);
    }
    return MPS_OK;
}

enum mps_status fluid_step(struct fluid *f, double dt, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    const size_t n = f->ps.n, nf = f->nfluid;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    enum mps_status st;

    if (!(dt > 0.0) || dt < p->dt_min)
        return mps_err_set(err, MPS_EDIVERGED,
                           "fluid step %.3g s at t = %.6g s is below fluid.dt_min = %.3g s: the "
                           "flow is too fast for the CFL condition (Eq. 52)",
                           dt, f->time, p->dt_min);

    /* neighbours at x^n (with skin), reordering the fluid now and then */
    mps_timer_switch(&f->timer, PH_NBR);
    if (f->step % 20 == 0 && f->grid.n == n) {
        st = reorder_fluid(f, err);
        if (st)
            return st;
    }
    st = build_neighbours(f, err);
    if (st)
        return st;

    /* Eq. 16-17: viscosity and gravity, explicit */
    mps_timer_switch(&f->timer, PH_PREDICT);
    struct mps_ops_in lap_in = {&f->nl, x, p->re_lap * p->dp, NULL, f->is_fluid};
    if (p->nu > 0.0)
        mps_ops_laplacian_vec(&lap_in, f->n0_lap, f->lambda_lap,
                              (const double(*)[MPS_DIM])f->v, f->lap);
    double maxdisp2 = 0.0;
#pragma omp parallel for schedule(static) reduction(max : maxdisp2)
    for (size_t i = 0; i < nf; i++) {
        double d2 = 0.0;
        for (int d = 0; d < MPS_DIM; d++) {
            double visc = p->nu > 0.0 ? p->nu * f->lap[i][d] : 0.0;
            f->vstar[i][d] = f->v[i][d] + dt * (visc + p->g[d]);
            double dx = dt * f->vstar[i][d];
            f->x[i][d] += dx;
            d2 += dx * dx;
        }
        if (d2 > maxdisp2)
            maxdisp2 = d2;
    }
    mps_timer_switch(&f->timer, PH_NBR);
    if (2.0 * sqrt(maxdisp2) > f->skin && (st = build_neighbours(f, err)))
        return st;
    if ((st = mps_nbr_list_filter(&f->nl_n, &f->nl, x, p->re_n * p->dp, err)))
        return st;
    mps_timer_switch(&f->timer, PH_PREDICT);
    collide(f, dt);

    /* Eq. 8 at x*, and the free-surface double check (paper 4.3) */
    mps_timer_switch(&f->timer, PH_DENSITY);
    struct mps_ops_in nd_in = {&f->nl_n, x, p->re_n * p->dp, NULL, f->has_p};
    mps_ops_number_density(&nd_in, f->nd, f->ncount);
    const double nlim = p->beta1 * f->n0, clim = p->beta2 * f->count0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        f->surface[i] = f->has_p[i] && f->nd[i] < nlim && f->ncount[i] < clim;

    if (p->mixed_source) {
        /* Eq. 10 on v*: fixed particles have v* = 0, solid ones their velocity */
#pragma omp parallel for schedule(static)
        for (size_t i = nf; i < n; i++)
            for (int d = 0; d < MPS_DIM; d++)
                f->vstar[i][d] = f->v[i][d];
        struct mps_ops_in dv_in = {&f->nl_n, x, p->re_n * p->dp, NULL, f->has_p};
        mps_ops_divergence(&dv_in, f->n0, (const double(*)[MPS_DIM])f->vstar, f->div);
    }

    /* Eq. 23 */
    mps_timer_switch(&f->timer, PH_ASSEMBLE);
    st = fluid_ppe_assemble(f, dt, err);
    if (st)
        return st;
    mps_timer_switch(&f->timer, PH_SOLVE);
    struct fluid_linsolve_stats ls;
    st = fluid_ppe_solve(f, &ls, err);
    if (st)
        return st;
    f->ppe_iterations += ls.iterations;

    /* Eq. 14-15 (or 9), Eq. 19 and 24 */
    mps_timer_switch(&f->timer, PH_CORRECT);
    struct mps_ops_in g_in = {&f->nl_n, x, p->re_n * p->dp, f->has_p, f->is_fluid};
    if (p->gradient == FLUID_GRAD_CORRECTED)
        mps_ops_gradient_corrected(&g_in, f->n0, f->p, p->gradient_min, 0.2, f->grad,
                                   f->fallback);
    else
        mps_ops_gradient(&g_in, f->n0, f->p, p->gradient_min, f->grad);
    const double c = dt / p->rho;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nf; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            double dv = -c * f->grad[i][d];
            f->v[i][d] = f->vstar[i][d] + dv;
            f->x[i][d] += dt * dv;
        }

    mps_timer_switch(&f->timer, PH_OTHER);
    f->time += dt;
    f->step++;
    f->dt_last = dt;
    st = check_domain(f, err);
    mps_timer_stop(&f->timer);
    return st;
}
