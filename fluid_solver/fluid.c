#include "fluid.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_ppe.h"
#include "fluid_shadow.h"
#include "fluid_scene.h"
#include "mps_kernel.h"
#include "mps_omp.h"
#include "mps_ops.h"

static const char *const phase_names[PH_COUNT] = {
    "neighbours", "predict", "density", "ppe_assemble", "ppe_solve", "correct", "sensors",
    "other"};

/* Skin added to the Laplacian radius so one neighbour list serves several
 * steps (a Verlet list): it is rebuilt once some particle has moved more
 * than half the skin since the list was built. 1 dp: at 4 mm the dam break
 * rebuilds every 3 steps instead of 1.5 and runs 8% faster than with 0.5 dp
 * (2 runs each; the longer list costs more in the PPE assembly). */
#define SKIN_FRACTION 1.0

static void register_fields(struct fluid *f)
{
    struct mps_particles *ps = &f->ps;
    mps_particles_init(ps);
    mps_particles_add_field(ps, "velocity", MPS_DIM, MPS_F64, (void **)&f->v, "m/s", 1);
    mps_particles_add_field(ps, "pressure", 1, MPS_F64, (void **)&f->p, "Pa", 1);
    mps_particles_add_field(ps, "type", 1, MPS_I32, (void **)&f->type, "", 1);
    /* the codes of enum fluid_ptype that snapshots hold: a coupled solid's
     * particles (3, 4) are written by the solid (fluid_solver/main.c) */
    mps_particles_set_legend(ps, "type", "0 fluid, 1 wall (first layer), 2 dummy (outer wall "
                                         "layers)");
    mps_particles_add_field(ps, "id", 1, MPS_I32, (void **)&f->id, "", 1);
    mps_particles_add_field(ps, "number_density", 1, MPS_F64, (void **)&f->nd, "", 1);
    mps_particles_add_field(ps, "free_surface", 1, MPS_U8, (void **)&f->surface, "", 1);
    mps_particles_add_field(ps, "position", MPS_DIM, MPS_F64, (void **)&f->x, "m", 0);
    mps_particles_add_field(ps, "x_list", MPS_DIM, MPS_F64, (void **)&f->xref, "m", 0);
    mps_particles_add_field(ps, "vstar", MPS_DIM, MPS_F64, (void **)&f->vstar, "m/s", 0);
    mps_particles_add_field(ps, "laplacian", MPS_DIM, MPS_F64, (void **)&f->lap, "", 0);
    mps_particles_add_field(ps, "grad_p", MPS_DIM, MPS_F64, (void **)&f->grad, "Pa/m", 0);
    mps_particles_add_field(ps, "body_acc", MPS_DIM, MPS_F64, (void **)&f->acc, "m/s^2", 0);
    mps_particles_add_field(ps, "div_vstar", 1, MPS_F64, (void **)&f->div, "1/s", 0);
    mps_particles_add_field(ps, "density_quadratic", 1, MPS_F64, (void **)&f->nq, "", 0);
    mps_particles_add_field(ps, "ncount", 1, MPS_I32, (void **)&f->ncount, "", 0);
    mps_particles_add_field(ps, "row", 1, MPS_I32, (void **)&f->row, "", 0);
    mps_particles_add_field(ps, "ppe_nbrs", 1, MPS_I32, (void **)&f->nwlap, "", 0);
    mps_particles_add_field(ps, "ppe_flags", 1, MPS_U8, (void **)&f->ppe_flag, "", 0);
    mps_particles_add_field(ps, "has_p", 1, MPS_U8, (void **)&f->has_p, "", 0);
    mps_particles_add_field(ps, "is_fluid", 1, MPS_U8, (void **)&f->is_fluid, "", 0);
    mps_particles_add_field(ps, "nbr_query", 1, MPS_U8, (void **)&f->nbr_query, "", 0);
    mps_particles_add_field(ps, "unknown", 1, MPS_U8, (void **)&f->unknown, "", 0);
    mps_particles_add_field(ps, "ghost", 1, MPS_U8, (void **)&f->ghost, "", 0);
    mps_particles_add_field(ps, "grad_use", 1, MPS_U8, (void **)&f->grad_use, "", 0);
    mps_particles_add_field(ps, "grad_fallback", 1, MPS_U8, (void **)&f->fallback, "", 0);
    mps_particles_add_field(ps, "body_normal", MPS_DIM, MPS_F64, (void **)&f->body_n, "", 0);
    mps_particles_add_field(ps, "in_body", 1, MPS_U8, (void **)&f->in_body, "", 0);
    mps_particles_add_field(ps, "ppe_held", 1, MPS_U8, (void **)&f->ppe_held, "", 0);
}

void fluid_update_masks(struct fluid *f)
{
    /* With Neumann walls nothing reads the neighbours of a tank particle
     * but its own pressure, which only needs the fluid around it
     * (fluid_ppe_boundary_pressure): nl_tank has those. The tank is 40% of
     * the particles of the 3 mm dam break. */
    const enum fluid_wall_bc bc = f->prm.wall_bc;
    for (size_t i = 0; i < f->ps.n; i++) {
        int t = f->type[i];
        int tank = t == WALL_P || t == DUMMY_P, solid = t == SOLID_SURF_P || t == SOLID_INNER_P || t == SOLID_SUNK_P;
        f->is_fluid[i] = t == FLUID_P;
        f->has_p[i] = t == FLUID_P || t == WALL_P || t == SOLID_SURF_P;
        f->nbr_query[i] = bc == FLUID_WALL_PPE || !tank;
        switch (bc) {
        case FLUID_WALL_NEUMANN:
            f->unknown[i] = t == FLUID_P;
            f->ghost[i] = tank || solid;
            break;
        case FLUID_WALL_PPE:
            f->unknown[i] = f->has_p[i];
            f->ghost[i] = 0;
            break;
        case FLUID_WALL_SOLID_PPE:
            f->unknown[i] = t == FLUID_P || t == SOLID_SURF_P;
            f->ghost[i] = tank || t == SOLID_SUNK_P;
            break;
        }
        /* the paper's dummies and inner solid particles carry no pressure */
        f->grad_use[i] = f->unknown[i] || f->ghost[i];
    }
}

/* Hydrostatic pressure at t = 0: rho |g_y| times the depth below the top
 * particle of the water above (the free surface sits at the surface
 * particles, where the PPE puts P = 0). Blocks are lattice-aligned boxes, so
 * the top of the water at x is the highest block top covering x. */
static void initial_pressure(struct fluid *f)
{
    const struct fluid_params *p = &f->prm;
    for (size_t i = 0; i < f->nfluid; i++) {
        double top = -INFINITY;
        for (int b = 0; b < p->nblocks; b++) {
            const double *bl = p->block[b];
            double yt = bl[1] + (floor((bl[3] - bl[1]) / p->dp + 1e-6) - 0.5) * p->dp;
            if (f->x[i][0] >= bl[0] && f->x[i][0] <= bl[2] && f->x[i][1] <= yt + p->dp && yt > top)
                top = yt;
        }
        f->p[i] = isfinite(top) ? -p->rho * f->acc[i][1] * (top - f->x[i][1]) : 0.0;
        if (f->p[i] < 0.0)
            f->p[i] = 0.0;
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
    /* every user of the fluid's lists recomputes distances at the positions
     * of the moment: the lists keep indices only */
    f->nl.no_r2 = f->nl_n.no_r2 = f->nl_tank.no_r2 = 1;
    mps_timer_init(&f->timer, phase_names, PH_COUNT);

    struct fluid_scene_pt *pts = NULL;
    size_t nf = 0, nw = 0;
    enum mps_status st;
    /* A narrow tank's side walls, which a 2D run does not have, carry
     * oscillating boundary layers of thickness delta = sqrt(2 nu / omega)
     * (Stokes' second problem). Their shear on a flow U cos(omega t) is
     * rho sqrt(nu omega) U, 45 degrees ahead of it; the in-phase half,
     * rho sqrt(nu omega / 2) U on each wall, spread over the breadth b,
     * retards the flow at sqrt(2 nu omega) / b per unit velocity. It is
     * the sloshing's damping that the 2D model leaves out (zeta about 0.06
     * for the oil tank of docs/sloshing.md, "Side walls"). The reactive
     * half, of the same size, is an inertia: the layers' fluid moves with
     * the flow, delta / b more of it (11-13% there), and it lowers the
     * sloshing frequency by about zeta. It multiplies the flow's whole
     * inertia, so the pressure correction accelerates rho (1 + delta / b)
     * (fluid_ppe.c, the projection) while the pressure stays the physical
     * one: hydrostatic under gravity, the loads as they are. */
    if (prm->side_wall_breadth > 0.0) {
        const double period = prm->side_wall_period > 0.0 ? prm->side_wall_period
                              : prm->motion                ? prm->motion->period
                                                           : 0.0;
        if (!(period > 0.0)) {
            st = mps_err_set(err, MPS_EINPUT,
                             "fluid.side_walls.breadth needs fluid.side_walls.period (s) or a "
                             "sinusoidal motion.period");
            goto fail;
        }
        const double omega = 6.283185307179586 / period;
        /* the model is of thin layers on the two walls; layers that fill the
         * breadth (a period of 1e300 s, a breadth of 1e-300 m) made an
         * infinite inertia and a non-finite PPE */
        const double delta = sqrt(2.0 * prm->nu / omega);
        if (!(delta < 0.5 * prm->side_wall_breadth)) {
            st = mps_err_set(err, MPS_EINPUT,
                             "fluid.side_walls.breadth = %g m: the side walls' boundary layers, "
                             "delta = sqrt(2 nu / omega) = %.3g m at a period of %g s, fill it; "
                             "the model holds while delta < breadth / 2",
                             prm->side_wall_breadth, delta, period);
            goto fail;
        }
        f->side_wall_rate = sqrt(2.0 * prm->nu * omega) / prm->side_wall_breadth;
        if (prm->side_wall_inertia)
            f->side_wall_inertia = delta / prm->side_wall_breadth;
    }
    f->rho_inertial = prm->rho * (1.0 + f->side_wall_inertia);
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
    fluid_body_accel(f, 0.0);
    if (prm->initial_hydrostatic)
        initial_pressure(f);
    fluid_update_masks(f);

    struct mps_lattice_consts cn = mps_lattice_consts(prm->dp, prm->re_n * prm->dp);
    struct mps_lattice_consts cl = mps_lattice_consts(prm->dp, prm->re_lap * prm->dp);
    f->n0 = cn.n0;
    f->count0 = cn.count;
    f->n0_lap = cl.n0;
    f->nq0 = cn.nq0;
    f->lambda_lap = cl.lambda;
    f->shift_gain = prm->shift_smooth
                        ? mps_lattice_gradient_response(prm->dp, prm->re_n * prm->dp, 0) /
                              mps_lattice_gradient_response(prm->dp, prm->re_n * prm->dp, 1)
                        : 1.0;
    f->skin = SKIN_FRACTION * prm->dp;

    st = fluid_sensors_create(&f->sens, prm, err);
    if (!st)
        st = fluid_linsolve_create(&f->ls, prm->ppe_solver, prm->ppe_rtol, prm->ppe_max_iter, 0,
                                   err);
    if (!st)
        st = fluid_linsolve_set_drop(f->ls, prm->ppe_drop, err);
    /* fluid_ppe_assemble writes sorted rows with their diagonal */
    if (!st)
        fluid_linsolve_trust_structure(f->ls, 1);
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
    mps_nbr_list_free(&f->nl_tank);
    free(f->wlap);
    free(f->wcol);
    free(f->shadow_use);
    free(f->agg);
    free(f->aggkey);
    free(f->aggmap);
    free(f->rowptr);
    free(f->col);
    free(f->val);
    free(f->rhs);
    free(f->sol);
    free(f->ppe_terms);
    free(f->val_assembled);
    free(f->rhs_assembled);
    free(f->row_is_fluid);
    free(f->row_held);
    free(f->row_held_next);
    free(f->row_list);
    free(f->row_touched);
    free(f->row_seed);
    fluid_linsolve_destroy(&f->ls);
    fluid_sensors_destroy(&f->sens);
    free(f);
    *pf = NULL;
}

/* Eq. 52. With fluid.droplet_neighbours = k > 0, a fluid particle with fewer
 * than k neighbours within re_n at the last step (a droplet: on the free
 * surface, P = 0, moving ballistically) is held to one spacing per step
 * (Courant 1) instead: measured on the 3 mm plate, droplets of one to three
 * particles otherwise set a third of the steps (docs/dambreak_plate.md). */
double fluid_cfl_dt(const struct fluid *f)
{
    double vmax2 = 0.0, vdrop2 = 0.0;
    const int k = f->step > 0 ? f->prm.droplet_neighbours : 0;
#pragma omp parallel for reduction(max : vmax2, vdrop2)
    for (size_t i = 0; i < f->nfluid; i++) {
        double s = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            s += f->v[i][d] * f->v[i][d];
        if (f->ncount[i] < k) {
            if (s > vdrop2)
                vdrop2 = s;
        } else if (s > vmax2) {
            vmax2 = s;
        }
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
    if (vdrop2 > 0.0 && f->prm.dp / sqrt(vdrop2) < dt)
        dt = f->prm.dp / sqrt(vdrop2);
    return fmin(dt, fluid_viscous_dt(&f->prm));
}

/* Numbers the fluid segment in the grid's cell order (the grid follows). */
static enum mps_status reorder_fluid(struct fluid *f, struct mps_err *err)
{
    size_t *perm = malloc((f->nfluid > 0 ? f->nfluid : 1) * sizeof *perm);
    if (!perm)
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory reordering");
    enum mps_status st = mps_nbr_grid_cell_order(&f->grid, f->nfluid, perm, err);
    if (!st)
        st = mps_particles_permute(&f->ps, perm, f->nfluid, err);
    free(perm);
    return st;
}

/* Rebuilds the lists at the current positions, the fluid first numbered in
 * the order of the grid's cells: the list build then finds most windows
 * of cells already sorted (mps_nbr.c, visit) instead of merging nine runs.
 * Before, the fluid was sorted every tenth build, but only by the call at
 * the start of a step, which rarely rebuilds (the one after the
 * prediction does), so it mostly kept its initial numbering. Measured (2
 * threads, 2-4 runs each, minimum): 3 mm dam break to 1 s, neighbours 1.76
 * to 0.99 ms per step and the step 5.85 to 4.95 ms; 3.5 mm to 0.2 s, step
 * 3.94 to 3.67 ms; 1.8 mm to 0.08 s, 16.5 to 15.9 ms; 0.8 mm to 0.04 s
 * (the lattice numbering still intact) 92.2 to 91.5 ms, the PPE solve
 * 6% slower there. */
static enum mps_status build_neighbours(struct fluid *f, struct mps_err *err)
{
    const double radius = f->prm.re_lap * f->prm.dp + f->skin;
    enum mps_status st = mps_nbr_grid_build(&f->grid, f->ps.n, (const double(*)[MPS_DIM])f->x,
                                            radius, err);
    if (st || (st = reorder_fluid(f, err)))
        return st;
    f->nbr_rebuilds++;
    f->nl_gen = ++f->nl_gen_next;
    f->last.neighbour_build = 1;
    memcpy(f->xref, f->x, f->ps.n * sizeof *f->x);
    st = mps_nbr_list_build_masked(&f->nl, &f->grid, (const double(*)[MPS_DIM])f->x, f->ps.n,
                                   f->nbr_query, radius, err);
    if (st || f->prm.wall_bc == FLUID_WALL_PPE)
        return st;
    return mps_nbr_list_reverse(&f->nl_tank, &f->nl, 0, f->nfluid, f->nfluid, f->nfixed_end, err);
}

/* Rebuilds the list if the particles changed (solid placed) or one of them
 * moved more than half the skin since the last build. */
static enum mps_status update_neighbours(struct fluid *f, struct mps_err *err)
{
    const size_t n = f->ps.n;
    int stale = f->nl.n != n || f->step == 0;
    if (!stale) {
        double m2 = 0.0;
        /* the tank [nfluid, nfixed_end) does not move */
#pragma omp parallel for schedule(static) reduction(max : m2)
        for (size_t q = 0; q < n - (f->nfixed_end - f->nfluid); q++) {
            size_t i = q < f->nfluid ? q : q - f->nfluid + f->nfixed_end;
            double d2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = f->x[i][d] - f->xref[i][d];
                d2 += dx * dx;
            }
            if (d2 > m2)
                m2 = d2;
        }
        stale = 4.0 * m2 > f->skin * f->skin;
    }
    return stale ? build_neighbours(f, err) : MPS_OK;
}

/* Keeps fluid particles from interpenetrating: pairs closer than
 * collision_dist * dp that approach each other exchange momentum with the
 * given restitution (Koshizuka's collision model; fixed and solid particles
 * act as infinitely heavy). Computed from a frozen copy so the result does
 * not depend on loop order. */
long fluid_collide(struct fluid *f, double dt)
{
    const double cd = f->prm.collision_dist * f->prm.dp, cd2 = cd * cd;
    const double e = f->prm.collision_restitution;
    long pairs = 0;
    if (cd <= 0.0)
        return 0;
    double(*vs)[MPS_DIM] = f->vstar;
    double(*dv)[MPS_DIM] = f->grad; /* scratch: grad is recomputed later */
#pragma omp parallel for schedule(static) reduction(+ : pairs)
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
            pairs++;
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
    return pairs;
}

/* Particle shifting (Lind et al. 2012, with Skillen et al. 2013's scaling and
 * the free-surface treatment of the optimised scheme in the second paper):
 * each fluid particle moves down the gradient of the number density,
 *   dr_i = -A dp |v_i| dt grad n_i / n0,  grad n_i = sum_j w'(r_ij) e_ji,
 * which spreads clusters and fills gaps (boundary particles count, so it also
 * keeps particles off walls). On and next to the free surface only the part
 * tangential to the surface is kept, n = -grad n / |grad n|, so the surface
 * does not diffuse outwards. The step is capped at shift_max * dp.
 * fluid.shifting_weight smooth follows the gradient of (1 - r/re)^2 instead,
 * as Lind et al. follow a smooth kernel's: Eq. 3's weight is singular at
 * r = 0, so its gradient is mostly the nearest neighbour's distance. Scaled
 * by shift_gain, a particle off its lattice site is shifted as much as with
 * Eq. 3's weight. At 3 mm the plate's step-to-step load noise fell from 14.1
 * to 8.4 N/m with it (docs/pressure.md, "The particle shifting's weight"). */
void fluid_shift(struct fluid *f, double dt)
{
    const struct fluid_params *p = &f->prm;
    const double A = p->shift_coef, re = p->re_n * p->dp, re2 = re * re;
    const double cap = p->shift_max * p->dp;
    const int smooth = p->shift_smooth;
    if (A <= 0.0)
        return;
    double(*dr)[MPS_DIM] = f->grad; /* scratch: grad is not needed any more */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->nfluid; i++) {
        double g[MPS_DIM] = {0}, sp2 = 0.0;
        int near_surf = f->surface[i];
        for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1]; k++) {
            int j = f->nl_n.j[k];
            double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx);
            if (r2 >= re2 || r2 <= 0.0)
                continue;
            /* grad n_i = sum -w'(r) e_ij, -w'(r) = re / r^2 and e_ij = dx / r,
             * from one division (divisions bound the loop) */
            double ir = 1.0 / sqrt(r2);
            double dw_r = smooth ? 2.0 * (1.0 - 1.0 / (ir * re)) / re * ir : re * ir * ir * ir;
            for (int d = 0; d < MPS_DIM; d++)
                g[d] += dw_r * dx[d];
            near_surf |= f->is_fluid[j] && f->surface[j];
        }
        for (int d = 0; d < MPS_DIM; d++)
            sp2 += f->v[i][d] * f->v[i][d];
        double s = -A * p->dp * sqrt(sp2) * dt * f->shift_gain / f->n0, d2 = 0.0;
        double v[MPS_DIM];
        for (int d = 0; d < MPS_DIM; d++)
            v[d] = s * g[d];
        if (near_surf) {
            double gn = 0.0, vn = 0.0;
            for (int d = 0; d < MPS_DIM; d++)
                gn += g[d] * g[d];
            gn = sqrt(gn);
            if (gn > 0.0) {
                for (int d = 0; d < MPS_DIM; d++)
                    vn += v[d] * g[d] / gn;
                for (int d = 0; d < MPS_DIM; d++)
                    v[d] -= vn * g[d] / gn;
            }
        }
        for (int d = 0; d < MPS_DIM; d++)
            d2 += v[d] * v[d];
        if (d2 > cap * cap) {
            double sc = cap / sqrt(d2);
            for (int d = 0; d < MPS_DIM; d++)
                v[d] *= sc;
        }
        for (int d = 0; d < MPS_DIM; d++)
            dr[i][d] = v[d];
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->nfluid; i++)
        for (int d = 0; d < MPS_DIM; d++)
            f->x[i][d] += dr[i][d];
}

/* Confirms the free-surface candidates of the double check (paper 4.3) by
 * looking for empty space next to them (after Marrone et al. 2010's umbrella
 * scan): with m_i = sum_j w_ij r_ij the weighted centroid direction of the
 * neighbours and n = -m_i / |m_i|, the point T = x_i + dp n must be farther
 * than surface_scan * dp from every neighbour (fluid or boundary). A
 * candidate with a neighbour near T has no empty side: it sits at a small gap
 * (next to a wall, or inside the water after particles rearranged) and keeps
 * its PPE row. Without the scan such gaps get P = 0, which pulls the water
 * apart further. fluid.surface_scan_density: candidates sparser than that
 * share of n0 are not scanned; in the spray after an impact a particle at
 * 0.5-0.7 n0 nearly always has some neighbour near T, so the scan kept it in
 * the PPE, where it came out under tension and was clamped: 18% of the
 * 6 mm plate's interior at P = 0, the plate's load flickering with it
 * (docs/pressure.md, "Spray and tension"). A candidate with a wall or solid
 * particle within re_n is scanned whatever its density: at a contact line
 * or in a corner the wall, not spray, is what thins the neighbourhood, and
 * without the scan there the front's tip was flung out of the 4 mm dam
 * break's corner at 45 m/s and the plate at rest bent 9% further. */
static int boundary_within(const struct fluid *f, size_t i, double re2)
{
    for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1]; k++) {
        int j = f->nl_n.j[k];
        double dx[MPS_DIM];
        if (!f->is_fluid[j] && mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx) < re2)
            return 1;
    }
    return 0;
}

static void surface_scan(struct fluid *f)
{
    const double re = f->prm.re_n * f->prm.dp, re2 = re * re;
    const double rs = f->prm.surface_scan * f->prm.dp, rs2 = rs * rs;
    const double nmin = f->prm.surface_scan_density * f->n0;
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < f->nfluid; i++) {
        if (!f->surface[i] || (f->nd[i] < nmin && !boundary_within(f, i, re2)))
            continue;
        double m[MPS_DIM] = {0};
        for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1]; k++) {
            int j = f->nl_n.j[k];
            double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx);
            if (r2 >= re2 || r2 <= 0.0)
                continue;
            double w = mps_weight(sqrt(r2), re);
            for (int d = 0; d < MPS_DIM; d++)
                m[d] += w * dx[d];
        }
        double mn = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            mn += m[d] * m[d];
        mn = sqrt(mn);
        if (mn == 0.0)
            continue; /* isolated or perfectly symmetric: keep the flag */
        double t[MPS_DIM];
        for (int d = 0; d < MPS_DIM; d++)
            t[d] = f->x[i][d] - f->prm.dp * m[d] / mn;
        int occupied = 0;
        for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1] && !occupied; k++) {
            int j = f->nl_n.j[k];
            double r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                double dx = f->x[j][d] - t[d];
                r2 += dx * dx;
            }
            occupied = r2 < rs2;
        }
        if (occupied)
            f->surface[i] = 0;
    }
}

/* A flow along a wall made of fixed particles otherwise reads as a
 * divergence that depends on where the particle sits over the wall's
 * lattice, u/dp times that asymmetry (docs/pressure.md, "Walls that slip in
 * Eq. 10"). The pressure only holds the normal component at a wall anyway.
 * A particle of a tank corner (outside both faces) keeps its own velocity;
 * solids keep theirs. */
void fluid_divergence_slip_walls(struct fluid *f, const unsigned char *rows)
{
    const struct fluid_params *p = &f->prm;
    const double re = p->re_n * p->dp, re2 = re * re, coef = MPS_DIM / f->n0;
    const double rf = p->divergence_floor * p->dp, rf2 = rf * rf;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    const double(*vs)[MPS_DIM] = (const double(*)[MPS_DIM])f->vstar;
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < f->ps.n; i++) {
        if (!rows[i])
            continue;
        double acc = 0.0;
        for (size_t k = f->nl_n.start[i]; k < f->nl_n.start[i + 1]; k++) {
            const int j = f->nl_n.j[k];
            double dx[MPS_DIM], r2 = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                dx[d] = x[j][d] - x[i][d];
                r2 += dx[d] * dx[d];
            }
            if (r2 >= re2 || r2 <= 0.0)
                continue;
            double rel[MPS_DIM], nrm[MPS_DIM] = {0.0};
            for (int d = 0; d < MPS_DIM; d++)
                rel[d] = vs[j][d] - vs[i][d];
            if (f->type[j] == WALL_P || f->type[j] == DUMMY_P) {
                const double *xj = x[j];
                if (xj[1] < 0.0 && xj[0] >= 0.0 && xj[0] <= p->tank_w)
                    nrm[1] = 1.0;
                else if (xj[0] < 0.0 && xj[1] >= 0.0)
                    nrm[0] = 1.0;
                else if (xj[0] > p->tank_w && xj[1] >= 0.0)
                    nrm[0] = -1.0;
                else if (p->tank_lid && xj[1] > p->tank_h)
                    nrm[1] = -1.0;
                double rn = 0.0;
                for (int d = 0; d < MPS_DIM; d++)
                    rn += rel[d] * nrm[d];
                if (nrm[0] != 0.0 || nrm[1] != 0.0)
                    for (int d = 0; d < MPS_DIM; d++)
                        rel[d] = rn * nrm[d];
            }
            double dv = 0.0;
            for (int d = 0; d < MPS_DIM; d++)
                dv += rel[d] * dx[d];
            if (r2 < rf2)
                acc += mps_divergence_floor_factor(r2, re, rf) * dv;
            else
                acc += (re / sqrt(r2) - 1.0) * dv / r2;
        }
        f->div[i] = coef * acc;
    }
}

/* Counts one use of the guard on face (0 floor, 1 left, 2 right, 3 lid) by
 * the particle at x (before it is put back); the first use is kept whole,
 * for the summary: a leak shows where and when it started. */
static void guard_count(struct fluid *f, int face, const double *x)
{
    if (f->wall_guard == 0) {
        f->wall_guard_first[0] = f->time;
        f->wall_guard_first[1] = x[0];
        f->wall_guard_first[2] = x[1];
        f->wall_guard_first_face = face;
    }
    f->wall_guard++;
    f->wall_guard_face[face]++;
}

/* Last-resort guard against leaking through the tank: a fluid particle whose
 * centre has crossed an inner face of the tank (below the top of the side
 * walls) is put back half a spacing inside and its normal velocity reflected
 * with the collision restitution. Each use is counted (f->wall_guard, in the
 * summary, per face, with the first use) so a run that leans on it shows.
 * What it used to catch (3 mm dam break to 0.5 s, 20 uses, logged): one or
 * two particles creeping down through the bottom-right corner, where the
 * floor's lattice stopped 1.67 dp short of the side wall (0.584 m is 194.67
 * spacings of 3 mm); fluid_scene.c closes such corners now, and the 3 mm
 * plate to 1 s went from 29 uses to none. */
static void guard_tank(struct fluid *f)
{
    const struct fluid_params *p = &f->prm;
    const double h = 0.5 * p->dp, e = p->collision_restitution;
    for (size_t i = 0; i < f->nfluid; i++) {
        double *x = f->x[i], *v = f->v[i];
        int below_top = x[1] < p->tank_h;
        if (x[1] < 0.0 && x[0] > 0.0 && x[0] < p->tank_w) {
            guard_count(f, 0, x);
            x[1] = h;
            v[1] = v[1] < 0.0 ? -e * v[1] : v[1];
        }
        if (below_top && x[0] < 0.0 && x[1] > 0.0) {
            guard_count(f, 1, x);
            x[0] = h;
            v[0] = v[0] < 0.0 ? -e * v[0] : v[0];
        } else if (below_top && x[0] > p->tank_w && x[1] > 0.0) {
            guard_count(f, 2, x);
            x[0] = p->tank_w - h;
            v[0] = v[0] > 0.0 ? -e * v[0] : v[0];
        }
        if (p->tank_lid && x[1] > p->tank_h && x[0] > 0.0 && x[0] < p->tank_w) {
            guard_count(f, 3, x);
            x[1] = p->tank_h - h;
            v[1] = v[1] > 0.0 ? -e * v[1] : v[1];
        }
    }
}

/* Open tank: fluid particles that splashed out over a side wall (outside the
 * walls, higher than the wall's thickness below its top, so clipping the top
 * corner counts) leave the simulation and are counted in f->lost. A particle
 * outside the walls lower down went through a wall: that stays an error
 * (check_domain). */
static enum mps_status remove_lost(struct fluid *f, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    if (p->tank_lid)
        return MPS_OK;
    const double m = p->wall_layers * p->dp;
    const size_t n = f->ps.n, nf = f->nfluid;
    size_t nlost = 0;
    for (size_t i = 0; i < nf; i++)
        nlost += (f->x[i][0] < -m || f->x[i][0] > p->tank_w + m) && f->x[i][1] > p->tank_h - m;
    if (nlost == 0)
        return MPS_OK;
    size_t *perm = malloc(n * sizeof *perm);
    if (!perm)
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory removing lost particles");
    size_t k = 0, l = n - nlost;
    for (size_t i = 0; i < n; i++) {
        int lost = i < nf && (f->x[i][0] < -m || f->x[i][0] > p->tank_w + m) &&
                   f->x[i][1] > p->tank_h - m;
        perm[lost ? l++ : k++] = i;
    }
    enum mps_status st = mps_particles_permute(&f->ps, perm, n, err);
    free(perm);
    if (st)
        return st;
    f->nfluid -= nlost;
    f->nfixed_end -= nlost;
    f->lost += (long)nlost;
    return mps_particles_resize(&f->ps, n - nlost, err);
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

enum mps_status fluid_check_step(const struct fluid *f, double dt, struct mps_err *err)
{
    if (!(dt > 0.0) || dt < f->prm.dt_min)
        return mps_err_set(err, MPS_EDIVERGED,
                           "fluid step %.3g s at t = %.6g s is below fluid.dt_min = %.3g s: the "
                           "flow, or a solid's surface in it, is too fast for the CFL condition "
                           "(Eq. 52)",
                           dt, f->time, f->prm.dt_min);
    return MPS_OK;
}

enum mps_status fluid_step(struct fluid *f, double dt, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    const size_t n = f->ps.n, nf = f->nfluid;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    enum mps_status st;

    if ((st = fluid_check_step(f, dt, err)))
        return st;

    /* the step the CFL condition allows here: a step shortened below it
     * (the last one, landing on end_time) scales Eq. 23's correction with
     * it (fluid_ppe.c) */
    f->last = (struct fluid_step_stats){.dt = dt, .dt_cfl = fluid_cfl_dt(f)};
    /* body force at the step's middle (a moving tank's changes in time) */
    mps_timer_switch(&f->timer, PH_PREDICT);
    fluid_body_accel(f, f->time + 0.5 * dt);

    /* neighbours (Verlet list with skin) */
    mps_timer_switch(&f->timer, PH_NBR);
    if ((st = update_neighbours(f, err)))
        return st;

    /* Eq. 16-17: viscosity and gravity, explicit */
    mps_timer_switch(&f->timer, PH_PREDICT);
    struct mps_ops_in lap_in = {&f->nl, x, p->re_lap * p->dp, NULL, f->is_fluid, NULL};
    if (p->nu > 0.0)
        mps_ops_laplacian_vec(&lap_in, f->n0_lap, f->lambda_lap,
                              (const double(*)[MPS_DIM])f->v, f->lap);
    /* the side walls (fluid_create): (1 + m) dv/dt = visc + acc - c v, the
     * drag implicit so stable at any step; without them m = c = 0 and the
     * factors are exactly 1 */
    const double side_mass = 1.0 + f->side_wall_inertia;
    const double side_keep = 1.0 / (side_mass + dt * f->side_wall_rate);
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nf; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            double visc = p->nu > 0.0 ? p->nu * f->lap[i][d] : 0.0;
            f->vstar[i][d] = (side_mass * f->v[i][d] + dt * (visc + f->acc[i][d])) * side_keep;
            f->x[i][d] += dt * f->vstar[i][d];
        }
    mps_timer_switch(&f->timer, PH_NBR);
    if ((st = update_neighbours(f, err)))
        return st;
    if ((st = mps_nbr_list_filter(&f->nl_n, &f->nl, x, p->re_n * p->dp, err)))
        return st;
    mps_timer_switch(&f->timer, PH_PREDICT);
    f->last.collisions = fluid_collide(f, dt);

    /* Eq. 8 at x*, and the free-surface double check (paper 4.3), for the
     * PPE unknowns (f->unknown: which they are depends on fluid.wall_bc) */
    mps_timer_switch(&f->timer, PH_DENSITY);
    const int ghosts = p->wall_bc != FLUID_WALL_PPE;
    const unsigned char *rows = f->unknown;
    struct mps_ops_in nd_in = {&f->nl_n, x, p->re_n * p->dp, NULL, rows, NULL};
    if (p->density_quadratic)
        mps_ops_number_density_quadratic(&nd_in, f->nd, f->ncount, f->nq);
    else
        mps_ops_number_density(&nd_in, f->nd, f->ncount);
    const double nlim = p->beta1 * f->n0, clim = p->beta2 * f->count0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        f->surface[i] = rows[i] && f->nd[i] < nlim && f->ncount[i] < clim;
    if (p->surface_scan > 0.0)
        surface_scan(f);
    if (p->body_shadow && n > f->nfixed_end) {
        fluid_shadow_normals(f);
        fluid_shadow_dry(f);
    }

    if (p->mixed_source) {
        /* Eq. 10 on v*: fixed particles have v* = 0, solid ones their
         * velocity. A Neumann (ghost) boundary also takes the kick dt g,
         * since its extrapolated pressure holds the fluid against gravity:
         * fluid at rest on a wall then has no divergence. */
#pragma omp parallel for schedule(static)
        for (size_t i = nf; i < n; i++)
            for (int d = 0; d < MPS_DIM; d++)
                f->vstar[i][d] = f->v[i][d] + (f->ghost[i] ? dt : 0.0) * f->acc[i][d];
        /* on the Laplacian's stencil the assembly computes it
         * (fluid_ppe.c), from the weights it has anyway */
        if (!p->divergence_wide && p->divergence_slip) {
            fluid_divergence_slip_walls(f, rows);
        } else if (!p->divergence_wide) {
            struct mps_ops_in dv_in = {&f->nl_n, x, p->re_n * p->dp, NULL, rows, NULL};
            mps_ops_divergence(&dv_in, f->n0, (const double(*)[MPS_DIM])f->vstar,
                               p->divergence_floor * p->dp, f->div);
        }
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
    f->last.ppe_iterations = ls.iterations;
    f->last.ppe_rows = f->nrows;
    int at_zero = 0;
#pragma omp parallel for schedule(static) reduction(+ : at_zero)
    for (size_t i = 0; i < n; i++)
        at_zero += f->row[i] >= 0 && f->p[i] <= 0.0;
    f->last.rows_at_zero = at_zero;

    /* Eq. 14-15 (or 9), Eq. 19 and 24 */
    mps_timer_switch(&f->timer, PH_CORRECT);
    if (ghosts)
        fluid_ppe_boundary_pressure(f);
    struct mps_ops_in g_in = {&f->nl_n, x, p->re_n * p->dp, f->grad_use, f->is_fluid, NULL};
    if (p->body_shadow && n > f->nfixed_end) {
        size_t npairs = f->nl_n.start[f->nl_n.n];
        if (npairs + 1 > f->cap_shadow) {
            unsigned char *q = realloc(f->shadow_use, npairs + npairs / 2 + 16);
            if (!q)
                return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory for %zu pairs", npairs);
            f->shadow_use = q;
            f->cap_shadow = npairs + npairs / 2 + 16;
        }
        fluid_shadow_mask(f, &f->nl_n, f->is_fluid, f->shadow_use);
        g_in.pair_use = f->shadow_use;
    }
    if (p->gradient == FLUID_GRAD_CORRECTED)
        mps_ops_gradient_corrected(&g_in, f->n0, f->p, p->gradient_min, 0.2,
                                   p->gradient_floor * p->dp, f->grad, f->fallback);
    else
        mps_ops_gradient(&g_in, f->n0, f->p, p->gradient_min, p->gradient_floor * p->dp,
                         f->grad);
    const double c = dt / f->rho_inertial;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nf; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            double dv = -c * f->grad[i][d];
            f->v[i][d] = f->vstar[i][d] + dv;
            f->x[i][d] += dt * dv;
        }

    fluid_shift(f, dt);
    if (ghosts)
        fluid_ppe_boundary_clamp(f);
    mps_timer_switch(&f->timer, PH_OTHER);
    f->time += dt;
    f->step++;
    f->dt_last = dt;
    f->dt_kappa = f->last.dt_kappa;
    f->dt_kappa_expansion = f->last.dt_kappa_expansion;
    guard_tank(f);
    st = remove_lost(f, err);
    if (!st)
        st = check_domain(f, err);
    /* the time means of the sensors and wall loads take every step */
    mps_timer_switch(&f->timer, PH_SENSORS);
    if (!st)
        fluid_sensors_accumulate(f, dt);
    mps_timer_stop(&f->timer);
    return st;
}
