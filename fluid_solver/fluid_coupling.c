/* The fluid side of the partitioned coupling (paper 4.5): solid particles as a
 * moving boundary, and the loads on the solid surface (Eq. 50-51). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "fluid_shadow.h"
#include "mps_kernel.h"

/* Eq. 50 on the initial lattice, for a surface particle of a flat solid face
 * with fluid at uniform pressure P on one side, gives sum_j P r_y/r^2 w times
 * 2d/n~ with n~ the weights of the fluid and surface neighbours: 1.46 P/dp at
 * re = 2.1 dp, where the exact traction on a particle of width dp is P/dp per
 * unit volume. We divide by that flat-face value so a flat face under uniform
 * pressure receives exactly P dp per particle (tests/fluid checks it). */
static double flat_face_factor(double dp, double re)
{
    int k = (int)ceil(re / dp) + 1;
    double sum_y = 0.0, ntil = 0.0;
    for (int a = -k; a <= k; a++)
        for (int b = 0; b <= k; b++) {
            if (a == 0 && b == 0)
                continue;
            double rx = a * dp, ry = b * dp, r = sqrt(rx * rx + ry * ry);
            double w = mps_weight(r, re);
            if (w <= 0.0)
                continue;
            ntil += w;             /* fluid above (b > 0) and surface row (b = 0) */
            sum_y += ry / (r * r) * w;
        }
    return (2.0 * MPS_DIM / ntil) * sum_y * dp; /* in units of P / dp * dp^2 = P dp */
}

static enum mps_status remove_walls_under_solid(struct fluid *f, size_t n, const double (*x)[MPS_DIM],
                                                struct mps_err *err)
{
    /* A wall or dummy particle whose lattice cell (a square of side dp around
     * it) holds a solid particle is replaced by the solid: a plate clamped into
     * the floor takes the floor's place there. */
    const double h = 0.5 * f->prm.dp * (1.0 - 1e-9);
    size_t ntot = f->ps.n, keep = 0, drop = 0;
    size_t *perm = malloc(ntot * sizeof *perm), *dropped = malloc(ntot * sizeof *dropped);
    if (!perm || !dropped) {
        free(perm);
        free(dropped);
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory placing the solid");
    }
    for (size_t i = 0; i < ntot; i++) {
        int covered = 0;
        if (i >= f->nfluid && i < f->nfixed_end)
            for (size_t k = 0; k < n && !covered; k++)
                covered = fabs(x[k][0] - f->x[i][0]) <= h && fabs(x[k][1] - f->x[i][1]) <= h;
        if (covered)
            dropped[drop++] = i;
        else
            perm[keep++] = i;
    }
    memcpy(perm + keep, dropped, drop * sizeof *perm);
    enum mps_status st = drop ? mps_particles_permute(&f->ps, perm, ntot, err) : MPS_OK;
    free(perm);
    free(dropped);
    if (st)
        return st;
    f->nfixed_end -= drop;
    return mps_particles_resize(&f->ps, ntot - drop, err);
}

/* Inside the tank's walls (below the floor, beside the side walls, above a
 * lid): a solid clamped into the floor sits there in place of wall and dummy
 * particles. Its faces there see no fluid, only walls, so as PPE unknowns
 * they would hold pressures set by nothing but the wall terms; they count
 * as inner particles instead (number density only, like the dummies). */
static int in_walls(const struct fluid *f, const double *x)
{
    const struct fluid_params *p = &f->prm;
    return x[1] < 0.0 || x[0] < 0.0 || x[0] > p->tank_w || (p->tank_lid && x[1] > p->tank_h);
}

enum mps_status fluid_set_solid(struct fluid *f, size_t n, const int *id,
                                const double (*x)[MPS_DIM], const double (*v)[MPS_DIM],
                                const unsigned char *surface, struct mps_err *err)
{
    enum mps_status st;
    if (!f->solid_placed) {
        /* only walls: the solid segment is still empty */
        if ((st = mps_particles_resize(&f->ps, f->nfixed_end, err)) ||
            (st = remove_walls_under_solid(f, n, x, err)))
            return st;
        f->load_scale = 1.0 / flat_face_factor(f->prm.dp, f->prm.re_n * f->prm.dp);
        f->solid_placed = 1;
    }
    for (size_t k = 0; k < n; k++)
        for (int d = 0; d < MPS_DIM; d++)
            if (!isfinite(x[k][d]) || !isfinite(v[k][d]))
                return mps_err_set(err, MPS_EDIVERGED,
                                   "solid particle %d arrived with a non-finite state", id[k]);
    if ((st = mps_particles_resize(&f->ps, f->nfixed_end + n, err)))
        return st;
    for (size_t k = 0; k < n; k++) {
        size_t i = f->nfixed_end + k;
        memcpy(f->x[i], x[k], sizeof f->x[i]);
        memcpy(f->v[i], v[k], sizeof f->v[i]);
        f->type[i] = in_walls(f, x[k]) ? SOLID_SUNK_P : surface[k] ? SOLID_SURF_P : SOLID_INNER_P;
        f->id[i] = id[k];
    }
    fluid_update_masks(f);
    return MPS_OK;
}

/* The load on surface particle i as the pressure on the face it stands
 * for: -P_i dp^(d-1) n, n the unit normal from the particle toward its fluid
 * neighbours (the weighted sum of their offsets). Eq. 50 instead sums
 * (P_i + P_j)/2 r_ij / r^2 w over the neighbours, which scales as the
 * inverse square of the fluid's distance from the face: calibrated on the
 * lattice (flat_face_factor), it read +28% (force) / +22% (moment) on a
 * rigid plate in still water whose water sits 0.63-0.83 dp from it, though
 * P_i itself there is hydrostatic within 2% (docs/pressure.md). Only the
 * fluid on the particle's own side counts: at 6 mm the dam break's plate is
 * two particles thick, and a face particle sees the water beyond the other
 * face within re; its own side is where its solid neighbours are not (the
 * weighted sum of their offsets, negated). A lone particle (a fragment)
 * has no solid neighbour and takes all its fluid. No fluid neighbour, no
 * load. */
static void face_load(const struct fluid *f, size_t i, double re, double force[MPS_DIM])
{
    const double re2 = re * re;
    double out[MPS_DIM], toward[MPS_DIM] = {0};
    fluid_body_outward(f, i, out);
    for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
        int j = f->nl.j[k];
        if (!f->is_fluid[j])
            continue;
        double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx);
        if (r2 >= re2 || r2 <= 0.0)
            continue;
        double w = mps_weight(sqrt(r2), re), side = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            side += dx[d] * out[d];
        if (side < 0.0)
            continue; /* beyond the body: another face's water */
        for (int d = 0; d < MPS_DIM; d++)
            toward[d] += w * dx[d];
    }
    double norm = 0.0;
    for (int d = 0; d < MPS_DIM; d++)
        norm += toward[d] * toward[d];
    norm = sqrt(norm);
    const double face = pow(f->prm.dp, MPS_DIM - 1);
    for (int d = 0; d < MPS_DIM; d++)
        force[d] = norm > 0.0 ? -f->p[i] * face * toward[d] / norm : 0.0;
}

/* Eq. 50-51 (fluid.solid_load: eq50): j* are the fluid and solid surface
 * neighbours (walls, dummy and inner solid particles excluded), n~ their
 * weights, normalised on a flat face of the lattice (load_scale). The
 * pressure pushes the solid away from the fluid: the sum points into the
 * fluid, so the force is its negative. No fluid neighbour, no load. */
static void eq50_load(const struct fluid *f, size_t i, double re, double force[MPS_DIM])
{
    const double re2 = re * re, vol = pow(f->prm.dp, MPS_DIM);
    double acc[MPS_DIM] = {0}, ntil = 0.0;
    int fluid_nbrs = 0;
    for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
        int j = f->nl.j[k];
        if (!f->is_fluid[j] && f->type[j] != SOLID_SURF_P)
            continue; /* walls do not load the solid */
        double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx);
        if (r2 >= re2 || r2 <= 0.0)
            continue;
        double w = mps_weight(sqrt(r2), re), pij = 0.5 * (f->p[i] + f->p[j]);
        ntil += w;
        fluid_nbrs += f->is_fluid[j];
        for (int d = 0; d < MPS_DIM; d++)
            acc[d] += pij * dx[d] / r2 * w;
    }
    double s = (fluid_nbrs > 0 && ntil > 0.0) ? -2.0 * MPS_DIM / ntil * vol * f->load_scale : 0.0;
    for (int d = 0; d < MPS_DIM; d++)
        force[d] = s * acc[d];
}

size_t fluid_solid_loads(const struct fluid *f, int *id, double *pressure,
                         double (*force)[MPS_DIM], size_t max)
{
    const double re = f->prm.re_n * f->prm.dp;
    const int have_list = f->nl.n == f->ps.n;
    size_t m = 0;
    for (size_t i = f->nfixed_end; i < f->ps.n && m < max; i++) {
        if (f->type[i] != SOLID_SURF_P)
            continue;
        id[m] = f->id[i];
        pressure[m] = f->p[i];
        if (!have_list)
            memset(force[m], 0, sizeof force[m]);
        else if (f->prm.solid_load == FLUID_LOAD_FACE)
            face_load(f, i, re, force[m]);
        else
            eq50_load(f, i, re, force[m]);
        m++;
    }
    return m;
}
