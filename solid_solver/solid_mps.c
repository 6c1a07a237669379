#include "solid_mps.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mps_kernel.h"
#include "mps_nbr.h"
#include "solid_mps_fracture.h"

static const char *const phase_names[SOLID_PH_N] = {"strain", "force", "update", "contact"};

/* The columns added to the case probes when fracture or contact is on. */
static const char *const extra_probes[SOLID_MPS_NEXTRA] = {
    "momentum_x", "momentum_y", "min_gap", "broken_bonds", "surface_particles"};

static void register_fields(struct solid_mps *s)
{
    struct mps_particles *ps = &s->ps;
    mps_particles_init(ps);
    /* hot: read every step */
    mps_particles_add_field(ps, "x", MPS_DIM, MPS_F64, (void **)&s->x, "m", 0);
    mps_particles_add_field(ps, "velocity", MPS_DIM, MPS_F64, (void **)&s->v, "m/s", 1);
    mps_particles_add_field(ps, "theta", 1, MPS_F64, (void **)&s->theta, "rad", 1);
    mps_particles_add_field(ps, "omega", 1, MPS_F64, (void **)&s->omega, "rad/s", 1);
    mps_particles_add_field(ps, "hc", 1, MPS_F64, (void **)&s->hc, "", 0);
    mps_particles_add_field(ps, "hs", 1, MPS_F64, (void **)&s->hs, "", 0);
    mps_particles_add_field(ps, "kq", 1, MPS_F64, (void **)&s->kq, "", 0);
    mps_particles_add_field(ps, "q", 1, MPS_F64, (void **)&s->q, "", 0);
    mps_particles_add_field(ps, "load_acceleration", MPS_DIM, MPS_F64, (void **)&s->aload,
                            "m/s^2", 1); /* fluid load / (rho dp^2) */
    mps_particles_add_field(ps, "fixed", 1, MPS_U8, (void **)&s->fixed, "", 1);
    /* cold */
    mps_particles_add_field(ps, "x0", MPS_DIM, MPS_F64, (void **)&s->x0, "m", 0);
    mps_particles_add_field(ps, "displacement", MPS_DIM, MPS_F64, (void **)&s->disp, "m", 1);
    mps_particles_add_field(ps, "pressure", 1, MPS_F64, (void **)&s->pressure, "Pa", 1);
    mps_particles_add_field(ps, "n0", 1, MPS_F64, (void **)&s->n0, "", 0);
    mps_particles_add_field(ps, "id", 1, MPS_I32, (void **)&s->id, "", 1);
    mps_particles_add_field(ps, "body", 1, MPS_I32, (void **)&s->body, "", 1);
    mps_particles_add_field(ps, "surface", 1, MPS_U8, (void **)&s->surface, "", 1);
    solid_model_legends(ps);
    if (s->scene.eps_max > 0.0) /* fracture only: nothing allocated otherwise */
        mps_particles_add_field(ps, "number_density", 1, MPS_F64, (void **)&s->nden, "", 1);
}

/* Fills the lattices: each body column by column if it is wider than tall
 * (row by row otherwise), so bonded particles are close in memory. */
static void fill_bodies(struct solid_mps *s)
{
    const struct solid_scene *sc = &s->scene;
    size_t k = 0;
    for (int b = 0; b < sc->nbodies; b++) {
        const struct solid_body_def *d = &sc->bodies[b];
        long nx, ny;
        solid_scene_lattice(sc, b, &nx, &ny);
        int cols = nx >= ny;
        long na = cols ? nx : ny, nb = cols ? ny : nx;
        for (long a = 0; a < na; a++)
            for (long c = 0; c < nb; c++, k++) {
                long i = cols ? a : c, j = cols ? c : a;
                s->x[k][0] = s->x0[k][0] = d->x0 + s->dp * (0.5 + (double)i);
                s->x[k][1] = s->x0[k][1] = d->y0 + s->dp * (0.5 + (double)j);
                s->v[k][0] = d->v[0];
                s->v[k][1] = d->v[1];
                s->hc[k] = 1.0;
                s->body[k] = b;
                s->id[k] = (int)k;
            }
    }
    for (int c = 0; c < sc->nclamps; c++) {
        const struct solid_clamp_def *d = &sc->clamps[c];
        for (size_t i = 0; i < s->n; i++)
            if (s->body[i] == d->body && s->x0[i][0] >= d->x0 && s->x0[i][0] <= d->x1 &&
                s->x0[i][1] >= d->y0 && s->x0[i][1] <= d->y1) {
                s->fixed[i] = 1;
                s->v[i][0] = s->v[i][1] = 0.0;
            }
    }
    s->nfree = 0;
    for (size_t i = 0; i < s->n; i++)
        s->nfree += !s->fixed[i];
}

/* Eq. 15's correction matrix, used as a per-bond weight: a_ij = e^T B_i^-1 e
 * with B_i = sum_k w_ik e_ik e_ik^T over the initial bonds (e = r0/|r0|).
 * Inside the lattice B = n0/d I, so a_ij = d/n0, the paper's factor; at a
 * surface it weights the bonds along the surface by what the particle really
 * has in that direction, where d/n0_i would also count the missing bonds
 * across it (see solid_mps.h). Falls back to d/n0_i when B is singular. */
static void bond_weights(const struct solid_mps *s, size_t i, double *a)
{
    double bxx = 0.0, bxy = 0.0, byy = 0.0;
    for (size_t b = s->bstart[i]; b < s->bstart[i + 1]; b++) {
        double il = 1.0 / s->blen[b], ex = s->br0[b][0] * il, ey = s->br0[b][1] * il;
        double w = mps_weight(s->blen[b], SOLID_MPS_RE * s->dp);
        bxx += w * ex * ex;
        bxy += w * ex * ey;
        byy += w * ey * ey;
    }
    double det = bxx * byy - bxy * bxy, tr = bxx + byy;
    for (size_t b = s->bstart[i]; b < s->bstart[i + 1]; b++) {
        double il = 1.0 / s->blen[b], ex = s->br0[b][0] * il, ey = s->br0[b][1] * il;
        if (det > 1e-6 * tr * tr)
            a[b - s->bstart[i]] = (byy * ex * ex - 2.0 * bxy * ex * ey + bxx * ey * ey) / det;
        else
            a[b - s->bstart[i]] = MPS_DIM / s->n0[i];
    }
}

/* Bonds to the initial neighbours of the same body within re (Eq. 7), with
 * the per-bond constants folded once (fixed bonds: no search per step). */
static enum mps_status build_bonds(struct solid_mps *s, struct mps_err *err)
{
    const double re = SOLID_MPS_RE * s->dp;
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list l = {0};
    double *a = NULL;
    enum mps_status st = mps_nbr_grid_build(&g, s->n, (const double(*)[MPS_DIM])s->x0, re, err);
    if (st == MPS_OK)
        st = mps_nbr_list_build(&l, &g, (const double(*)[MPS_DIM])s->x0, s->n, re, err);
    if (st != MPS_OK)
        goto done;
    s->bstart = malloc((s->n + 1) * sizeof *s->bstart);
    size_t nb = 0, most = 0;
    if (s->bstart)
        for (size_t i = 0; i < s->n; i++) {
            s->bstart[i] = nb;
            for (size_t e = l.start[i]; e < l.start[i + 1]; e++)
                nb += s->body[l.j[e]] == s->body[i];
            if (nb - s->bstart[i] > most)
                most = nb - s->bstart[i];
        }
    s->nbonds = nb;
    s->bj = malloc((nb + 1) * sizeof *s->bj);
    s->br0 = malloc((nb + 1) * sizeof *s->br0);
    s->blen = malloc((nb + 1) * sizeof *s->blen);
    s->bk = malloc((nb + 1) * sizeof *s->bk);
    s->bb = malloc((nb + 1) * sizeof *s->bb);
    s->bbr = malloc((nb + 1) * sizeof *s->bbr);
    a = malloc((nb + 1) * sizeof *a);
    if (!s->bstart || !s->bj || !s->br0 || !s->blen || !s->bk || !s->bb || !s->bbr || !a) {
        st = mps_err_set(err, MPS_ENOMEM, "solid: no memory for %zu bonds", nb);
        goto done;
    }
    s->bstart[s->n] = nb;
    for (size_t i = 0; i < s->n; i++) {
        size_t b = s->bstart[i];
        s->n0[i] = 0.0;
        for (size_t e = l.start[i]; e < l.start[i + 1]; e++) {
            int j = l.j[e];
            if (s->body[j] != s->body[i])
                continue;
            s->bj[b] = j;
            s->br0[b][0] = s->x0[j][0] - s->x0[i][0];
            s->br0[b][1] = s->x0[j][1] - s->x0[i][1];
            s->blen[b] = sqrt(l.r2[e]);
            s->n0[i] += mps_weight(s->blen[b], re); /* Eq. 8 on the initial lattice */
            b++;
        }
    }
    for (size_t i = 0; i < s->n; i++) {
        bond_weights(s, i, a + s->bstart[i]);
        s->surface[i] = s->n0[i] < s->n0_lattice - SOLID_MPS_NC; /* Eq. 48 */
    }
    for (size_t i = 0; i < s->n; i++) {
        const struct solid_mps_material *m = &s->mat[s->body[i]];
        s->kq[i] = -m->lambda / m->rho;
        for (size_t b = s->bstart[i]; b < s->bstart[i + 1]; b++) {
            int j = s->bj[b];
            size_t r = s->bstart[j]; /* the same bond seen from j */
            while (s->bj[r] != (int)i)
                r++;
            double w = mps_weight(s->blen[b], re), len = s->blen[b];
            s->bb[b] = a[b] * w / len;  /* Eq. 30 */
            s->bbr[b] = a[r] * w / len;
            /* Eq. 36-37 with 2d/n0 as the pair sum a_ij + a_ji: k_ij = k_ji. */
            s->bk[b] = (2.0 * m->mu / m->rho) * (a[b] + a[r]) * w / (len * len);
        }
    }
    /* Spin frequency bound (Gershgorin on the spin block): the spins of i and
     * its neighbours in phase give I w^2 = 1/2 sum m k |r0|^2 (Eq. 43-44). */
    s->spin_omega = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        double sum = 0.0;
        for (size_t b = s->bstart[i]; b < s->bstart[i + 1]; b++)
            sum += s->bk[b] * s->blen[b] * s->blen[b];
        s->spin_omega = fmax(s->spin_omega, sqrt(3.0 * sum) / s->dp);
    }
done:
    free(a);
    mps_nbr_list_free(&l);
    mps_nbr_grid_free(&g);
    return st;
}

/* Probe k averages the particles nearest its point (ties: a tip probe between
 * two rows takes the mean of both). */
static void find_probes(struct solid_mps *s)
{
    s->nprobes = s->scene.nprobes;
    solid_probes_locate(&s->scene, s->n, (const double(*)[MPS_DIM])s->x0, s->probe_n, s->probe_i);
    solid_load_probes_init(&s->loadprobes, &s->scene);
}

enum mps_status solid_mps_create(struct solid_mps **out, const struct solid_scene *scene,
                                 struct mps_err *err)
{
    *out = NULL;
    struct solid_mps *s = calloc(1, sizeof *s);
    if (!s)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    s->scene = *scene;
    s->dp = scene->dp;
    s->courant = scene->courant;
    s->n0_lattice = mps_lattice_consts(s->dp, SOLID_MPS_RE * s->dp).n0;
    solid_iface_cache_init(&s->iface);
    size_t n = 0;
    for (int b = 0; b < scene->nbodies; b++) {
        struct solid_mps_material *m = &s->mat[b];
        m->rho = scene->bodies[b].rho;
        m->E = solid_scene_modulus(scene, b);
        m->nu = scene->bodies[b].nu;
        solid_scene_lame(scene, b, &m->lambda, &m->mu);
        m->wave_speed = sqrt((m->lambda + 2.0 * m->mu) / m->rho);
        long nx, ny;
        solid_scene_lattice(scene, b, &nx, &ny);
        n += (size_t)nx * (size_t)ny;
    }
    register_fields(s);
    enum mps_status st = mps_particles_resize(&s->ps, n, err);
    if (st == MPS_OK) {
        s->n = n;
        fill_bodies(s);
        st = build_bonds(s, err);
    }
    if (st == MPS_OK)
        st = solid_mps_frac_create(s, err);
    for (int k = 0; st == MPS_OK && s->frac && k < scene->nprobes; k++)
        for (int e = 0; e < SOLID_MPS_NEXTRA; e++)
            if (strcmp(scene->probes[k].name, extra_probes[e]) == 0)
                st = mps_err_set(err, MPS_EINPUT, "solid.probes.%d.name = %s: the name of a "
                                 "column added under fracture or contact", k, extra_probes[e]);
    if (st != MPS_OK) {
        solid_mps_destroy(&s);
        return st;
    }
    find_probes(s);
    if (scene->mps_damping > 0.0 && s->spin_omega > 0.0) {
        s->damp_tau = 2.0 * scene->mps_damping / s->spin_omega;
        s->vold = malloc(s->n * sizeof *s->vold);
        s->wold = malloc(s->n * sizeof *s->wold);
        if (!s->vold || !s->wold) {
            solid_mps_destroy(&s);
            return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
        }
    }
    int contact = s->frac && scene->contact != SOLID_CONTACT_NONE;
    mps_timer_init(&s->timer, phase_names, contact ? SOLID_PH_N : SOLID_PH_CONTACT);
    *out = s;
    return MPS_OK;
}

void solid_mps_destroy(struct solid_mps **sp)
{
    if (!sp || !*sp)
        return;
    struct solid_mps *s = *sp;
    mps_particles_free(&s->ps);
    solid_load_probes_free(&s->loadprobes);
    solid_mps_frac_destroy(&s->frac);
    free(s->bstart);
    free(s->bj);
    free(s->br0);
    free(s->blen);
    free(s->bk);
    free(s->bb);
    free(s->bbr);
    free(s->vold);
    free(s->wold);
    solid_iface_cache_free(&s->iface);
    mps_motion_destroy(&s->motion);
    free(s);
    *sp = NULL;
}

double solid_mps_stable_dt(const struct solid_mps *s)
{
    double c = 0.0;
    for (int b = 0; b < s->scene.nbodies; b++)
        c = fmax(c, s->mat[b].wave_speed);
    double dt_wave = c > 0.0 ? s->dp / c : INFINITY;
    double z = s->scene.mps_damping;
    double dt_spin = s->spin_omega > 0.0 ? 2.0 * (sqrt(1.0 + z * z) - z) / s->spin_omega
                                         : INFINITY;
    return s->courant * fmin(dt_wave, dt_spin);
}

/* Eq. 25: u_ij = r_ij - R(theta_ij) r0_ij with theta_ij the mean rotation; cos
 * and sin of the mean come from the half angles, so no trigonometry per bond. */
#define BOND_U(i, b)                                                          \
    int j = bj[b];                                                            \
    double C = ci * hc[j] - si * hs[j], S = si * hc[j] + ci * hs[j];          \
    double rx = x[j][0] - xi, ry = x[j][1] - yi;                              \
    double ux = rx - (C * br0[b][0] - S * br0[b][1]);                         \
    double uy = ry - (S * br0[b][0] + C * br0[b][1]);                         \
    double r = sqrt(rx * rx + ry * ry)

/* Volumetric strain pass (Eq. 30, 33): q_i = p_i / rho = -(lambda/rho) tr_i,
 * tr_i = sum_j beta_ij (|r_ij| - |r0_ij|), the bond stretch standing for
 * u_ij . r_ij / |r_ij| (equal to first order, and without the spurious
 * second-order dilatation of a sheared bond; its exact gradient is the
 * pressure force, so the update conserves energy). */
static void strain_pass(struct solid_mps *s)
{
    const size_t n = s->n;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    const double *bb = s->bb, *blen = s->blen, *kq = s->kq;
    const size_t *bstart = s->bstart;
    const int *bj = s->bj;
    double *q = s->q;
#pragma omp parallel for schedule(static) if (n >= SOLID_MPS_OMP_MIN)
    for (size_t i = 0; i < n; i++) {
        double xi = x[i][0], yi = x[i][1], sum = 0.0;
        for (size_t b = bstart[i]; b < bstart[i + 1]; b++) {
            int j = bj[b];
            double rx = x[j][0] - xi, ry = x[j][1] - yi;
            sum += bb[b] * (sqrt(rx * rx + ry * ry) - blen[b]);
        }
        q[i] = kq[i] * sum;
    }
}

enum mps_status solid_mps_advance(struct solid_mps *s, double dt, struct mps_err *err)
{
    const size_t n = s->n;
    double(*x)[MPS_DIM] = s->x;
    double(*v)[MPS_DIM] = s->v;
    const double *hc = s->hc, *hs = s->hs, *bk = s->bk, *bb = s->bb, *bbr = s->bbr;
    const double *q = s->q;
    const double(*br0)[MPS_DIM] = (const double(*)[MPS_DIM])s->br0;
    const double(*aload)[MPS_DIM] = (const double(*)[MPS_DIM])s->aload;
    const size_t *bstart = s->bstart;
    const int *bj = s->bj;
    const unsigned char *fixed = s->fixed;
    double *omega = s->omega, *theta = s->theta;
    const double gx = s->scene.g[0], gy = s->scene.g[1];
    const double spin = 3.0 / (s->dp * s->dp); /* rho V / (2 I), Eq. 43-44 */
    /* a moving tank: the frame's body force (mps_motion.h) at mid-step; a
     * particle's spin is relative to the frame, whose own angular
     * acceleration it then lags: -omega_dot */
    const int moving = mps_motion_moving(s->motion);
    const struct mps_motion_frame fr =
        moving ? mps_motion_at(s->motion, s->time + 0.5 * dt) : (struct mps_motion_frame){0};

    mps_timer_switch(&s->timer, SOLID_PH_STRAIN);
    if (s->nden)
        solid_mps_frac_strain(s); /* Eq. 47-48 */
    else
        strain_pass(s);

    mps_timer_switch(&s->timer, SOLID_PH_FORCE);
    /* the damping reads the velocities of the step's start (v and omega are
     * updated in place below) */
    const double tau = s->damp_tau;
    const double(*vo)[MPS_DIM] = (const double(*)[MPS_DIM])s->vold;
    const double *wo = s->wold;
    if (tau > 0.0) {
        memcpy(s->vold, v, n * sizeof *v);
        memcpy(s->wold, omega, n * sizeof *omega);
    }
#pragma omp parallel for schedule(static) if (n >= SOLID_MPS_OMP_MIN)
    for (size_t i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        double xi = x[i][0], yi = x[i][1], ci = hc[i], si = hs[i], qi = q[i];
        double ax = 0.0, ay = 0.0, tq = 0.0;
        for (size_t b = bstart[i]; b < bstart[i + 1]; b++) {
            BOND_U(i, b);
            if (tau > 0.0) { /* Kelvin-Voigt: u + tau du/dt (header) */
                double wm = 0.5 * (wo[i] + wo[j]);
                double ax0 = rx - ux, ay0 = ry - uy; /* R r0 */
                ux += tau * (vo[j][0] - vo[i][0] + wm * ay0);
                uy += tau * (vo[j][1] - vo[i][1] - wm * ax0);
            }
            /* Eq. 36-37 (normal + shear stress) and Eq. 38 as -grad p; one add
             * per bond into each sum keeps the dependency chains short. */
            double k = bk[b], f = (qi * bb[b] + q[j] * bbr[b]) / r;
            ax += k * ux - f * rx;
            ay += k * uy - f * ry;
            tq += k * (rx * uy - ry * ux); /* Eq. 41-43 */
        }
        double b[MPS_DIM] = {gx, gy};
        if (moving)
            mps_motion_accel(&fr, x[i], v[i], b);
        v[i][0] += dt * (ax + b[0] + aload[i][0]); /* Eq. 39 */
        v[i][1] += dt * (ay + b[1] + aload[i][1]);
        omega[i] += dt * spin * tq; /* Eq. 45 */
        if (moving)
            omega[i] -= dt * fr.omega_dot;
    }
    if (s->frac && s->scene.contact != SOLID_CONTACT_NONE) {
        mps_timer_switch(&s->timer, SOLID_PH_CONTACT);
        enum mps_status st = solid_mps_frac_contact(s, dt, err);
        if (st != MPS_OK) {
            mps_timer_stop(&s->timer);
            return st;
        }
    }

    mps_timer_switch(&s->timer, SOLID_PH_UPDATE);
    double *hcw = s->hc, *hsw = s->hs;
    long bad = 0;
#pragma omp parallel for schedule(static) if (n >= SOLID_MPS_OMP_MIN) reduction(+ : bad)
    for (size_t i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        x[i][0] += dt * v[i][0]; /* Eq. 40 */
        x[i][1] += dt * v[i][1];
        theta[i] += dt * omega[i]; /* Eq. 46 */
        hcw[i] = cos(0.5 * theta[i]);
        hsw[i] = sin(0.5 * theta[i]);
        bad += !isfinite(x[i][0] + x[i][1] + theta[i]);
    }
    mps_timer_stop(&s->timer);
    s->time += dt;
    s->steps++;
    if (bad) {
        size_t i = 0;
        while (i < n && isfinite(x[i][0] + x[i][1] + theta[i]))
            i++;
        return mps_err_set(err, MPS_EDIVERGED,
                           "solid: particle %zu (body '%s') has a non-finite state at t = %g s "
                           "(step %ld, dt = %g s): the step is above the stability limit or "
                           "the loads are unphysical",
                           i, s->scene.bodies[s->body[i]].name, s->time, s->steps, dt);
    }
    return MPS_OK;
}

void solid_mps_diag(const struct solid_mps *s, struct solid_mps_diag *dg)
{
    memset(dg, 0, sizeof *dg);
    const double V = s->dp * s->dp;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    const double *hc = s->hc, *hs = s->hs;
    const double(*br0)[MPS_DIM] = (const double(*)[MPS_DIM])s->br0;
    const int *bj = s->bj;
    for (size_t i = 0; i < s->n; i++) {
        const struct solid_mps_material *m = &s->mat[s->body[i]];
        double mass = m->rho * V, inertia = mass * s->dp * s->dp / 6.0; /* Eq. 44 */
        const double *vi = s->v[i];
        dg->momentum[0] += mass * vi[0];
        dg->momentum[1] += mass * vi[1];
        dg->angular += mass * (x[i][0] * vi[1] - x[i][1] * vi[0]) + inertia * s->omega[i];
        dg->kinetic += 0.5 * mass * (vi[0] * vi[0] + vi[1] * vi[1]) +
                       0.5 * inertia * s->omega[i] * s->omega[i];
        dg->gravity -= mass * (s->scene.g[0] * x[i][0] + s->scene.g[1] * x[i][1]);
        double xi = x[i][0], yi = x[i][1], ci = hc[i], si = hs[i], tr = 0.0;
        for (size_t b = s->bstart[i]; b < s->bstart[i + 1]; b++) {
            BOND_U(i, b);
            tr += s->bb[b] * (r - s->blen[b]);
            /* each bond is seen from both ends: 1/2 of 1/2 k |u|^2 */
            dg->elastic += 0.25 * mass * s->bk[b] * (ux * ux + uy * uy);
        }
        dg->elastic += 0.5 * m->lambda * tr * tr * V;
    }
    dg->contact = solid_mps_frac_energy(s);
}

double solid_mps_probe(const struct solid_mps *s, int k)
{
    struct solid_mps_diag d;
    switch (s->scene.probes[k].kind) {
    case SOLID_PROBE_TANK_ANGLE: return solid_probe_tank_angle(s->motion, s->time);
    case SOLID_PROBE_ENERGY: solid_mps_diag(s, &d); return d.kinetic + d.elastic;
    default: break;
    }
    return solid_probe_value(&s->scene, k, s->probe_n, (const size_t(*)[SOLID_PROBE_TIES])s->probe_i,
                             (const double(*)[MPS_DIM])s->x, (const double(*)[MPS_DIM])s->x0,
                             &s->loadprobes, s->body);
}

/* ---- solid_model_ops ---- */

static enum mps_status op_create(void **self, const struct mps_case *c, struct mps_err *err)
{
    struct solid_scene *sc = malloc(sizeof *sc);
    if (!sc)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    enum mps_status st = solid_scene_read(sc, c, err);
    struct solid_mps *s = NULL;
    if (st == MPS_OK)
        st = solid_mps_create(&s, sc, err);
    if (st == MPS_OK && (st = mps_motion_read(&s->motion, c, err)))
        solid_mps_destroy(&s);
    free(sc);
    *self = s;
    return st;
}

static double op_stable_dt(const void *self)
{
    return solid_mps_stable_dt(self);
}

static enum mps_status op_set_loads(void *self, const struct solid_loads *f, struct mps_err *err)
{
    struct solid_mps *s = self;
    enum mps_status st = solid_loads_accel(&s->scene, s->body, s->n, f, s->aload, err);
    return st ? st : solid_load_probes_set(&s->loadprobes, f, err);
}

static enum mps_status op_advance(void *self, double dt, struct mps_err *err)
{
    struct solid_mps *s = self;
    /* the loads act over this step from the positions it starts at */
    solid_load_probes_step(&s->loadprobes, &s->scene, s->body, (const double(*)[MPS_DIM])s->x, dt);
    return solid_mps_advance(s, dt, err);
}

static void op_probe_restart(void *self)
{
    solid_load_probes_restart(&((struct solid_mps *)self)->loadprobes);
}

/* Surface particles (Eq. 48) and the particles within depth of one, found on
 * the initial lattice once per depth, and again when fracture made new
 * surface particles (the inner ones near a crack are those near it in x0). */
static enum mps_status op_interface(void *self, double depth, struct solid_iface *out,
                                    struct mps_err *err)
{
    struct solid_mps *s = self;
    if (depth != s->iface.depth || s->iface_rev != s->surface_rev) {
        enum mps_status st = solid_iface_cache_build(
            &s->iface, s->n, (const double(*)[MPS_DIM])s->x0, s->surface, s->id, s->fixed,
            depth, err);
        if (st != MPS_OK)
            return st;
        s->iface_rev = s->surface_rev;
    }
    solid_iface_cache_fill(&s->iface, (const double(*)[MPS_DIM])s->x,
                           (const double(*)[MPS_DIM])s->v, out);
    return MPS_OK;
}

/* Under fracture or contact the case probes are followed by extra_probes:
 * total momentum (kg m/s per metre), the smallest distance between particles
 * of different surfaces now (m, up to 2 dp), broken bonds, surface particles. */
static int op_probe_count(const void *self)
{
    const struct solid_mps *s = self;
    return s->nprobes + (s->frac ? SOLID_MPS_NEXTRA : 0);
}

static const char *op_probe_name(const void *self, int k)
{
    const struct solid_mps *s = self;
    return k < s->nprobes ? s->scene.probes[k].name : extra_probes[k - s->nprobes];
}

static double op_probe_value(const void *self, int k)
{
    const struct solid_mps *s = self;
    if (k < s->nprobes)
        return solid_mps_probe(s, k);
    struct solid_mps_diag d;
    struct solid_mps_frac_stats st;
    switch (k - s->nprobes) {
    case 0:
    case 1:
        solid_mps_diag(s, &d);
        return d.momentum[k - s->nprobes];
    case 2: return solid_mps_min_gap(s, 2.0 * s->dp);
    case 3: solid_mps_frac_stats(s, &st); return (double)st.broken;
    default: solid_mps_frac_stats(s, &st); return (double)st.surface;
    }
}

static size_t op_snapshot(void *self, const double (**x)[MPS_DIM], struct mps_field *fields,
                          int max_fields, int *nfields)
{
    struct solid_mps *s = self;
    strain_pass(s); /* q of the current state */
    for (size_t i = 0; i < s->n; i++) {
        const struct solid_mps_material *m = &s->mat[s->body[i]];
        s->pressure[i] = s->q[i] * m->rho;
        for (int a = 0; a < MPS_DIM; a++)
            s->disp[i][a] = s->x[i][a] - s->x0[i][a];
    }
    *x = (const double(*)[MPS_DIM])s->x;
    *nfields = mps_particles_output(&s->ps, fields, max_fields);
    return s->n;
}

static void op_summary(const void *self, struct mps_json *j)
{
    const struct solid_mps *s = self;
    mps_json_str(j, "model", "mps");
    if (s->motion) {
        mps_json_object(j, "motion");
        mps_motion_summary(s->motion, j);
        mps_json_close(j);
    }
    mps_json_int(j, "bonds", (long long)s->nbonds);
    mps_json_int(j, "fixed_particles", (long long)(s->n - s->nfree));
    mps_json_num(j, "dt_stable", solid_mps_stable_dt(s));
    mps_json_num(j, "courant", s->courant);
    mps_json_str(j, "plane", s->scene.plane == SOLID_PLANE_STRAIN ? "strain" : "stress");
    mps_json_num(j, "plane_factor", s->scene.plane_factor);
    struct solid_mps_diag d;
    solid_mps_diag(s, &d);
    mps_json_object(j, "final");
    mps_json_num(j, "kinetic_energy", d.kinetic);
    mps_json_num(j, "elastic_energy", d.elastic);
    mps_json_num(j, "gravity_energy", d.gravity);
    mps_json_num(j, "momentum_x", d.momentum[0]);
    mps_json_num(j, "momentum_y", d.momentum[1]);
    mps_json_num(j, "angular_momentum", d.angular);
    mps_json_close(j);
    if (s->frac)
        solid_mps_frac_summary(s, j);
    mps_json_object(j, "phase_seconds");
    for (int p = 0; p < s->timer.nphases; p++)
        mps_json_num(j, s->timer.names[p], s->timer.seconds[p]);
    mps_json_close(j);
}

/* The state (solid_model_ops.state_put). The damping history (vold, wold)
 * is rewritten at the start of every step and the loads by set_loads, so
 * without fracture the particle fields, time, steps and the load probes'
 * means are the whole state. Fracture adds the bonds' stiffnesses (zero
 * once broken), the surface counter and the contact list
 * (solid_mps_frac_put); the surface flags and the number densities of the
 * intact bonds are particle fields. */
struct mps_scalars {
    double time;
    int64_t steps, surface_rev;
};

static enum mps_status op_state_put(const void *self, struct mps_ckpt *c, struct mps_err *err)
{
    const struct solid_mps *s = self;
    struct mps_scalars sc = {s->time, s->steps, s->surface_rev};
    struct solid_load_probes_mark m;
    memset(&m, 0, sizeof m);
    solid_load_probes_keep(&s->loadprobes, &m);
    enum mps_status st;
    if ((st = mps_particles_put(&s->ps, c, err)) ||
        (st = mps_ckpt_put(c, "mps", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_put(c, "load_probes", &m, sizeof m, err)) || !s->frac)
        return st;
    const size_t nb = s->nbonds * sizeof(double);
    if ((st = mps_ckpt_put(c, "bonds.k", s->bk, nb, err)) ||
        (st = mps_ckpt_put(c, "bonds.beta", s->bb, nb, err)) ||
        (st = mps_ckpt_put(c, "bonds.beta_r", s->bbr, nb, err)))
        return st;
    return solid_mps_frac_put(s, c, err);
}

static enum mps_status op_state_get(void *self, struct mps_ckpt *c, struct mps_err *err)
{
    struct solid_mps *s = self;
    struct mps_scalars sc;
    struct solid_load_probes_mark m;
    enum mps_status st;
    if ((st = mps_particles_get(&s->ps, c, err)) ||
        (st = mps_ckpt_get(c, "mps", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_get(c, "load_probes", &m, sizeof m, err)))
        return st;
    s->time = sc.time;
    s->steps = (long)sc.steps;
    s->surface_rev = (long)sc.surface_rev;
    s->iface_rev = -1; /* the interface is listed again from the state read */
    solid_load_probes_back(&s->loadprobes, &m);
    if (!s->frac)
        return MPS_OK;
    const size_t nb = s->nbonds * sizeof(double);
    if ((st = mps_ckpt_get(c, "bonds.k", s->bk, nb, err)) ||
        (st = mps_ckpt_get(c, "bonds.beta", s->bb, nb, err)) ||
        (st = mps_ckpt_get(c, "bonds.beta_r", s->bbr, nb, err)))
        return st;
    return solid_mps_frac_get(s, c, err);
}

/* Fracture changes bonds, surface and contact lists, and the interface's
 * size within a step: a coupling iteration would see a solid of another
 * shape at each repeat. */
static enum mps_status op_rollback_check(const void *self, struct mps_err *err)
{
    const struct solid_mps *s = self;
    if (s->frac)
        return mps_err_set(err, MPS_EINPUT,
                           "solid: fracture or contact (solid.eps_max, solid.contact) cannot be "
                           "rolled back: implicit coupling (coupling.scheme: implicit) needs "
                           "them off");
    return MPS_OK;
}

static void op_particles(const void *self, struct solid_particles_view *out)
{
    const struct solid_mps *s = self;
    *out = (struct solid_particles_view){s->n, s->id, s->body,
                                         (const double(*)[MPS_DIM])s->x0,
                                         (const double(*)[MPS_DIM])s->x,
                                         (const double(*)[MPS_DIM])s->v, s->surface, s->fixed};
}

static void op_destroy(void **self)
{
    struct solid_mps *s = *self;
    solid_mps_destroy(&s);
    *self = NULL;
}

const struct solid_model_ops solid_mps_ops = {
    .name = "mps",
    .create = op_create,
    .stable_dt = op_stable_dt,
    .set_loads = op_set_loads,
    .advance = op_advance,
    .interface = op_interface,
    .probe_count = op_probe_count,
    .probe_name = op_probe_name,
    .probe_value = op_probe_value,
    .probe_restart = op_probe_restart,
    .snapshot = op_snapshot,
    .summary = op_summary,
    .destroy = op_destroy,
    .particles = op_particles,
    .state_put = op_state_put,
    .state_get = op_state_get,
    .rollback_check = op_rollback_check,
};
