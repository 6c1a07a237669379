#include "solid_tlsph.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mps_nbr.h"

/* Below this many particles a step is too short for threads to pay off. */
#define SOLID_TLSPH_OMP_MIN 4096
/* Surface: fewer than the 8 lattice neighbours within 1.5 dp. The full
 * support (2.6 dp) would also flag the second row, which misses the
 * neighbours 2 dp across the surface. */
#define SOLID_TLSPH_SURF_R 1.5

static const char *const phase_names[SOLID_TL_N] = {"strain", "force", "update"};

/* Wendland C2 in 2D, W = 7/(4 pi h^2) (1 - q/2)^4 (2q + 1), q = r/h < 2:
 * returns |dW/dr| (the normalisation cancels in L G, it sets the scale of
 * w_ij: sum_j w_ij R_ij^2 = 2 inside the lattice, the continuum value). */
static double wendland_dw(double r, double h)
{
    double q = r / h;
    if (q >= 2.0)
        return 0.0;
    const double pi = 3.14159265358979323846;
    double t = 1.0 - 0.5 * q;
    return 7.0 / (4.0 * pi * h * h) * 5.0 * q * t * t * t / h;
}

static void register_fields(struct solid_tlsph *s)
{
    struct mps_particles *ps = &s->ps;
    mps_particles_init(ps);
    /* hot: read every step */
    mps_particles_add_field(ps, "x", MPS_DIM, MPS_F64, (void **)&s->x, "m", 0);
    mps_particles_add_field(ps, "velocity", MPS_DIM, MPS_F64, (void **)&s->v, "m/s", 1);
    mps_particles_add_field(ps, "acc", MPS_DIM, MPS_F64, (void **)&s->acc, "m/s^2", 0);
    mps_particles_add_field(ps, "F", 4, MPS_F64, (void **)&s->F, "", 0);
    mps_particles_add_field(ps, "P", 4, MPS_F64, (void **)&s->P, "Pa", 0);
    mps_particles_add_field(ps, "F_linear", 4, MPS_F64, (void **)&s->Fl, "", 0);
    mps_particles_add_field(ps, "sg", MPS_DIM, MPS_F64, (void **)&s->sg, "1/m", 0);
    mps_particles_add_field(ps, "load_acceleration", MPS_DIM, MPS_F64, (void **)&s->aload,
                            "m/s^2", 1); /* fluid load / (rho dp^2) */
    mps_particles_add_field(ps, "fixed", 1, MPS_U8, (void **)&s->fixed, "", 1);
    /* cold */
    mps_particles_add_field(ps, "x0", MPS_DIM, MPS_F64, (void **)&s->x0, "m", 0);
    mps_particles_add_field(ps, "L", 4, MPS_F64, (void **)&s->L, "", 0);
    mps_particles_add_field(ps, "displacement", MPS_DIM, MPS_F64, (void **)&s->disp, "m", 1);
    mps_particles_add_field(ps, "von_mises", 1, MPS_F64, (void **)&s->von_mises, "Pa", 1);
    mps_particles_add_field(ps, "pressure", 1, MPS_F64, (void **)&s->pressure, "Pa", 1);
    mps_particles_add_field(ps, "id", 1, MPS_I32, (void **)&s->id, "", 1);
    mps_particles_add_field(ps, "body", 1, MPS_I32, (void **)&s->body, "", 1);
    mps_particles_add_field(ps, "neighbours", 1, MPS_I32, (void **)&s->nnb, "", 0);
    mps_particles_add_field(ps, "surface", 1, MPS_U8, (void **)&s->surface, "", 1);
    solid_model_legends(ps);
}

/* Lattices as in solid_mps (column by column when wider than tall, so pairs
 * are close in memory), then clamps. */
static void fill_bodies(struct solid_tlsph *s)
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
                s->F[k][0] = s->F[k][3] = 1.0;
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

/* Neighbours of a particle inside the full lattice within radius r/dp. */
static int lattice_count(double r)
{
    int k = (int)ceil(r) + 1, c = 0;
    for (int a = -k; a <= k; a++)
        for (int b = -k; b <= k; b++)
            c += (a || b) && (double)(a * a + b * b) < r * r;
    return c;
}

/* Second-order corrected gradient (solid.tlsph.correction: quadratic): F_i from
 * the weighted least-squares fit x_ij ~ F X_ij + 1/2 H : X_ij X_ij, exact for
 * quadratic fields, so a bent surface row gets its own strain instead of that
 * of a point further in. pg_ij = w_ij (first two rows of A^-1) phi_ij with
 * phi = (X, Y, X^2/2, XY, Y^2/2)/h, A = sum_j w_ij phi phi^T. */
static enum mps_status quadratic_vectors(struct solid_tlsph *s, size_t i, struct mps_err *err)
{
    double A[5][7] = {{0}}; /* [A | e_0 e_1] */
    const double ih = 1.0 / s->h;
    for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
        double X = s->pX[p][0] * ih, Y = s->pX[p][1] * ih, w = s->pw[p];
        double ph[5] = {X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y};
        for (int a = 0; a < 5; a++)
            for (int b = 0; b < 5; b++)
                A[a][b] += w * ph[a] * ph[b];
    }
    A[0][5] = A[1][6] = 1.0;
    double scale = 0.0;
    for (int a = 0; a < 5; a++)
        scale = fmax(scale, A[a][a]);
    for (int c = 0; c < 5; c++) {
        int piv = c;
        for (int r = c + 1; r < 5; r++)
            if (fabs(A[r][c]) > fabs(A[piv][c]))
                piv = r;
        if (!(fabs(A[piv][c]) > 1e-9 * scale)) {
            const struct solid_body_def *d = &s->scene.bodies[s->body[i]];
            return mps_err_set(err, MPS_EINPUT, "solid: body '%s': particle at (%g, %g): the "
                               "quadratic TLSPH correction needs bodies at least 3 particles "
                               "thick (dp = %g)", d->name, s->x0[i][0], s->x0[i][1], s->dp);
        }
        for (int k = 0; k < 7; k++) {
            double t = A[c][k];
            A[c][k] = A[piv][k];
            A[piv][k] = t;
        }
        for (int r = 0; r < 5; r++)
            if (r != c) {
                double f = A[r][c] / A[c][c];
                for (int k = c; k < 7; k++)
                    A[r][k] -= f * A[c][k];
            }
    }
    double row[2][5]; /* A symmetric: rows 0, 1 of A^-1 = columns */
    for (int a = 0; a < 5; a++) {
        row[0][a] = A[a][5] / A[a][a];
        row[1][a] = A[a][6] / A[a][a];
    }
    for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
        double X = s->pX[p][0] * ih, Y = s->pX[p][1] * ih, w = s->pw[p] * ih;
        double ph[5] = {X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y};
        double g0 = 0.0, g1 = 0.0;
        for (int a = 0; a < 5; a++) {
            g0 += row[0][a] * ph[a];
            g1 += row[1][a] * ph[a];
        }
        s->pg[p][0] = w * g0;
        s->pg[p][1] = w * g1;
    }
    return MPS_OK;
}

/* Pairs within the support in the same body, the correction matrices and the
 * per-pair vectors (all from the reference configuration, once). */
static enum mps_status build_pairs(struct solid_tlsph *s, struct mps_err *err)
{
    const double rs = 2.0 * s->h, rsurf = SOLID_TLSPH_SURF_R * s->dp;
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list l = {0};
    enum mps_status st =
        mps_nbr_grid_build(&g, s->n, (const double(*)[MPS_DIM])s->x0, rs, err);
    if (st == MPS_OK)
        st = mps_nbr_list_build(&l, &g, (const double(*)[MPS_DIM])s->x0, s->n, rs, err);
    if (st != MPS_OK)
        goto done;
    s->pstart = malloc((s->n + 1) * sizeof *s->pstart);
    size_t np = 0;
    if (s->pstart)
        for (size_t i = 0; i < s->n; i++) {
            s->pstart[i] = np;
            for (size_t e = l.start[i]; e < l.start[i + 1]; e++)
                np += s->body[l.j[e]] == s->body[i] && wendland_dw(sqrt(l.r2[e]), s->h) > 0.0;
        }
    s->npairs = np;
    s->pj = malloc((np + 1) * sizeof *s->pj);
    s->pg = malloc((np + 1) * sizeof *s->pg);
    s->pgr = malloc((np + 1) * sizeof *s->pgr);
    s->pgl = s->quadratic ? malloc((np + 1) * sizeof *s->pgl) : s->pg;
    s->pX = malloc((np + 1) * sizeof *s->pX);
    s->pw = malloc((np + 1) * sizeof *s->pw);
    s->pwr = malloc((np + 1) * sizeof *s->pwr);
    if (!s->pstart || !s->pj || !s->pg || !s->pgr || !s->pgl || !s->pX || !s->pw || !s->pwr) {
        st = mps_err_set(err, MPS_ENOMEM, "solid: no memory for %zu particle pairs", np);
        goto done;
    }
    s->pstart[s->n] = np;
    for (size_t i = 0; i < s->n; i++) {
        size_t p = s->pstart[i];
        int near = 0;
        for (size_t e = l.start[i]; e < l.start[i + 1]; e++) {
            int j = l.j[e];
            double R = sqrt(l.r2[e]), dw = wendland_dw(R, s->h);
            if (s->body[j] != s->body[i] || dw <= 0.0)
                continue;
            near += R < rsurf;
            s->pj[p] = j;
            s->pX[p][0] = s->x0[j][0] - s->x0[i][0];
            s->pX[p][1] = s->x0[j][1] - s->x0[i][1];
            s->pw[p] = s->vol * dw / R;
            s->pwr[p] = s->pw[p] / (R * R);
            p++;
        }
        s->nnb[i] = (int)(p - s->pstart[i]);
        s->surface[i] = near < 8;
        /* L_i = M^-1, M = sum_j V_j G_ij (x) X_ij = sum_j w_ij X_ij (x) X_ij */
        double mxx = 0.0, mxy = 0.0, myy = 0.0;
        for (size_t q = s->pstart[i]; q < p; q++) {
            mxx += s->pw[q] * s->pX[q][0] * s->pX[q][0];
            mxy += s->pw[q] * s->pX[q][0] * s->pX[q][1];
            myy += s->pw[q] * s->pX[q][1] * s->pX[q][1];
        }
        double det = mxx * myy - mxy * mxy, tr = mxx + myy;
        if (!(det > 1e-6 * tr * tr)) {
            const struct solid_body_def *d = &s->scene.bodies[s->body[i]];
            st = mps_err_set(err, MPS_EINPUT, "solid: body '%s': particle at (%g, %g) has %d "
                             "neighbours on a line: the TLSPH solid needs bodies at least 2 "
                             "particles thick (dp = %g, body %g x %g m)", d->name, s->x0[i][0],
                             s->x0[i][1], s->nnb[i], s->dp, d->x1 - d->x0, d->y1 - d->y0);
            goto done;
        }
        s->L[i][0] = myy / det;
        s->L[i][1] = s->L[i][2] = -mxy / det;
        s->L[i][3] = mxx / det;
    }
    /* V_j L_i G_ij = L_i w_ij X_ij */
    for (size_t i = 0; i < s->n; i++) {
        const double *Li = s->L[i];
        for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
            const double *X = s->pX[p];
            double w = s->pw[p];
            s->pg[p][0] = w * (Li[0] * X[0] + Li[1] * X[1]);
            s->pg[p][1] = w * (Li[2] * X[0] + Li[3] * X[1]);
        }
    }
    if (s->quadratic) {
        memcpy(s->pgl, s->pg, np * sizeof *s->pg);
        for (size_t i = 0; i < s->n && st == MPS_OK; i++)
            st = quadratic_vectors(s, i, err);
        if (st != MPS_OK)
            goto done;
    }
    /* the pair seen from j, sign flipped: V_j L_j G_ij = -V_i L_j G_ji (uniform V) */
    for (size_t i = 0; i < s->n; i++) {
        s->sg[i][0] = s->sg[i][1] = 0.0;
        for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
            size_t r = s->pstart[s->pj[p]];
            while (s->pj[r] != (int)i)
                r++;
            s->pgr[p][0] = -s->pg[r][0];
            s->pgr[p][1] = -s->pg[r][1];
            s->sg[i][0] += s->pg[p][0];
            s->sg[i][1] += s->pg[p][1];
        }
    }
done:
    mps_nbr_list_free(&l);
    mps_nbr_grid_free(&g);
    return st;
}

static void find_probes(struct solid_tlsph *s)
{
    s->nprobes = s->scene.nprobes;
    solid_probes_locate(&s->scene, s->n, (const double(*)[MPS_DIM])s->x0, s->probe_n, s->probe_i);
    solid_load_probes_init(&s->loadprobes, &s->scene);
}

enum mps_status solid_tlsph_create(struct solid_tlsph **out, const struct solid_scene *scene,
                                   double alpha, double hourglass, int quadratic,
                                   struct mps_err *err)
{
    *out = NULL;
    if (!(alpha >= 0.0) || !(hourglass >= 0.0))
        return mps_err_set(err, MPS_EINPUT, "solid: tlsph alpha = %g, hourglass = %g: must be "
                           ">= 0", alpha, hourglass);
    struct solid_tlsph *s = calloc(1, sizeof *s);
    if (!s)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    s->scene = *scene;
    s->dp = scene->dp;
    s->h = SOLID_TLSPH_HDP * s->dp;
    s->vol = s->dp * s->dp;
    s->courant = scene->courant;
    s->alpha = alpha;
    s->hourglass = hourglass;
    s->quadratic = quadratic != 0;
    s->full_count = lattice_count(2.0 * s->h / s->dp);
    solid_iface_cache_init(&s->iface);
    size_t n = 0;
    for (int b = 0; b < scene->nbodies; b++) {
        struct solid_tlsph_material *m = &s->mat[b];
        m->rho = scene->bodies[b].rho;
        m->E = solid_scene_modulus(scene, b);
        m->nu = scene->bodies[b].nu;
        solid_scene_lame(scene, b, &m->lambda, &m->mu);
        m->wave_speed = sqrt((m->lambda + 2.0 * m->mu) / m->rho);
        m->kv = alpha * m->wave_speed * s->h;
        m->kh = hourglass * m->E / m->rho;
        long nx, ny;
        solid_scene_lattice(scene, b, &nx, &ny);
        n += (size_t)nx * (size_t)ny;
    }
    register_fields(s);
    enum mps_status st = mps_particles_resize(&s->ps, n, err);
    if (st == MPS_OK) {
        s->n = n;
        fill_bodies(s);
        st = build_pairs(s, err);
    }
    if (st != MPS_OK) {
        solid_tlsph_destroy(&s);
        return st;
    }
    find_probes(s);
    mps_timer_init(&s->timer, phase_names, SOLID_TL_N);
    solid_tlsph_deform(s);
    *out = s;
    return MPS_OK;
}

void solid_tlsph_destroy(struct solid_tlsph **sp)
{
    if (!sp || !*sp)
        return;
    struct solid_tlsph *s = *sp;
    mps_particles_free(&s->ps);
    solid_load_probes_free(&s->loadprobes);
    free(s->pstart);
    free(s->pj);
    if (s->pgl != s->pg)
        free(s->pgl);
    free(s->pg);
    free(s->pgr);
    free(s->pX);
    free(s->pw);
    free(s->pwr);
    solid_iface_cache_free(&s->iface);
    mps_motion_destroy(&s->motion);
    free(s);
    *sp = NULL;
}

/* The CFL step with the explicit viscous term in the denominator, in the form
 * of Monaghan's (1992) dt = C h / (c + 1.2 alpha c + ...); the 0.6 is measured
 * for this operator: with it C = 1 is at or below the limit for alpha up to
 * 2 (test_tlsph_stability, solid_tlsph.h). */
double solid_tlsph_stable_dt(const struct solid_tlsph *s)
{
    double c = 0.0;
    for (int b = 0; b < s->scene.nbodies; b++)
        c = fmax(c, s->mat[b].wave_speed);
    double speed = (1.0 + SOLID_TLSPH_VISC_CFL * s->alpha) * c + s->vmax;
    double h = s->quadratic ? SOLID_TLSPH_QUAD_DT * s->h : s->h;
    return speed > 0.0 ? s->courant * h / speed : INFINITY;
}

/* St Venant-Kirchhoff: E = (F^T F - I)/2, S = lambda tr(E) I + 2 mu E, P = F S. */
static inline void svk_pk1(const double *F, double lambda, double mu, double *P)
{
    double exx = 0.5 * (F[0] * F[0] + F[2] * F[2] - 1.0);
    double eyy = 0.5 * (F[1] * F[1] + F[3] * F[3] - 1.0);
    double exy = 0.5 * (F[0] * F[1] + F[2] * F[3]);
    double lt = lambda * (exx + eyy);
    double sxx = lt + 2.0 * mu * exx, syy = lt + 2.0 * mu * eyy, sxy = 2.0 * mu * exy;
    P[0] = F[0] * sxx + F[1] * sxy;
    P[1] = F[0] * sxy + F[1] * syy;
    P[2] = F[2] * sxx + F[3] * sxy;
    P[3] = F[2] * sxy + F[3] * syy;
}

/* F_i = sum_j x_ij (x) V_j L_i G_ij (pg: s->pg, or s->pgl for the linear fit) */
static inline void particle_F(const struct solid_tlsph *s, const double (*pg)[MPS_DIM], size_t i,
                              double *F)
{
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    double xi = x[i][0], yi = x[i][1];
    double fxx = 0.0, fxy = 0.0, fyx = 0.0, fyy = 0.0;
    for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
        int j = s->pj[p];
        double dx = x[j][0] - xi, dy = x[j][1] - yi;
        fxx += dx * pg[p][0];
        fxy += dx * pg[p][1];
        fyx += dy * pg[p][0];
        fyy += dy * pg[p][1];
    }
    F[0] = fxx;
    F[1] = fxy;
    F[2] = fyx;
    F[3] = fyy;
}

/* Quadratic mode: F (stress) and F_lin (hourglass) in one pass over the pairs. */
static inline void particle_F2(const struct solid_tlsph *s, size_t i, double *F, double *Fl)
{
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    const double(*pg)[MPS_DIM] = (const double(*)[MPS_DIM])s->pg;
    const double(*pgl)[MPS_DIM] = (const double(*)[MPS_DIM])s->pgl;
    double xi = x[i][0], yi = x[i][1], f[4] = {0.0}, l[4] = {0.0};
    for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
        int j = s->pj[p];
        double dx = x[j][0] - xi, dy = x[j][1] - yi;
        f[0] += dx * pg[p][0];
        f[1] += dx * pg[p][1];
        f[2] += dy * pg[p][0];
        f[3] += dy * pg[p][1];
        l[0] += dx * pgl[p][0];
        l[1] += dx * pgl[p][1];
        l[2] += dy * pgl[p][0];
        l[3] += dy * pgl[p][1];
    }
    memcpy(F, f, sizeof f);
    memcpy(Fl, l, sizeof l);
}

void solid_tlsph_deform(struct solid_tlsph *s)
{
    const size_t n = s->n;
    const int *body = s->body;
    double(*F)[4] = s->F, (*P)[4] = s->P;
    const struct solid_tlsph_material *mat = s->mat;
#pragma omp parallel for schedule(static) if (n >= SOLID_TLSPH_OMP_MIN)
    for (size_t i = 0; i < n; i++) {
        if (s->quadratic)
            particle_F2(s, i, F[i], s->Fl[i]);
        else
            particle_F(s, (const double(*)[MPS_DIM])s->pg, i, F[i]);
        svk_pk1(F[i], mat[body[i]].lambda, mat[body[i]].mu, P[i]);
    }
}

enum mps_status solid_tlsph_advance(struct solid_tlsph *s, double dt, struct mps_err *err)
{
    const size_t n = s->n;
    double(*x)[MPS_DIM] = s->x;
    double(*v)[MPS_DIM] = s->v;
    double(*acc)[MPS_DIM] = s->acc;
    /* the hourglass term uses the linear fit (its residual is the energy) */
    const double(*F)[4] = (const double(*)[4])(s->quadratic ? s->Fl : s->F);
    const double(*P)[4] = (const double(*)[4])s->P;
    const double(*sg)[MPS_DIM] = (const double(*)[MPS_DIM])s->sg;
    const double(*pgr)[MPS_DIM] = (const double(*)[MPS_DIM])s->pgr;
    const double(*pX)[MPS_DIM] = (const double(*)[MPS_DIM])s->pX;
    const double(*aload)[MPS_DIM] = (const double(*)[MPS_DIM])s->aload;
    const double *pw = s->pw, *pwr = s->pwr;
    const size_t *pstart = s->pstart;
    const int *pj = s->pj, *body = s->body;
    const unsigned char *fixed = s->fixed;
    const struct solid_tlsph_material *mat = s->mat;
    const double gx = s->scene.g[0], gy = s->scene.g[1];
    /* a moving tank: the frame's body force (mps_motion.h) at mid-step */
    const int moving = mps_motion_moving(s->motion);
    const struct mps_motion_frame fr =
        moving ? mps_motion_at(s->motion, s->time + 0.5 * dt) : (struct mps_motion_frame){0};

    mps_timer_switch(&s->timer, SOLID_TL_STRAIN);
    solid_tlsph_deform(s);

    mps_timer_switch(&s->timer, SOLID_TL_FORCE);
#pragma omp parallel for schedule(static) if (n >= SOLID_TLSPH_OMP_MIN)
    for (size_t i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        const struct solid_tlsph_material *m = &mat[body[i]];
        const double *Fi = F[i], *Pi = P[i];
        double xi = x[i][0], yi = x[i][1], vxi = v[i][0], vyi = v[i][1];
        /* P_i sum_j V_j L_i G_ij: zero inside the lattice */
        double sx = Pi[0] * sg[i][0] + Pi[1] * sg[i][1];
        double sy = Pi[2] * sg[i][0] + Pi[3] * sg[i][1];
        double hx = 0.0, hy = 0.0, cx = 0.0, cy = 0.0;
        for (size_t p = pstart[i]; p < pstart[i + 1]; p++) {
            int j = pj[p];
            const double *Fj = F[j], *Pj = P[j], *X = pX[p];
            double rx = x[j][0] - xi, ry = x[j][1] - yi;
            /* Eq. 12: the pair's stress term, P_j V_j L_j G_ij (P_i part above) */
            sx += Pj[0] * pgr[p][0] + Pj[1] * pgr[p][1];
            sy += Pj[2] * pgr[p][0] + Pj[3] * pgr[p][1];
            /* hourglass: residual of both linear fits along this pair */
            double ex = 2.0 * rx - (Fi[0] + Fj[0]) * X[0] - (Fi[1] + Fj[1]) * X[1];
            double ey = 2.0 * ry - (Fi[2] + Fj[2]) * X[0] - (Fi[3] + Fj[3]) * X[1];
            hx += pw[p] * ex;
            hy += pw[p] * ey;
            /* viscosity: relative velocity along the pair, reference length */
            double vr = ((v[j][0] - vxi) * rx + (v[j][1] - vyi) * ry) * pwr[p];
            cx += vr * rx;
            cy += vr * ry;
        }
        double ir = 1.0 / m->rho, b[MPS_DIM] = {gx, gy};
        if (moving)
            mps_motion_accel(&fr, x[i], v[i], b);
        acc[i][0] = sx * ir + m->kh * hx + m->kv * cx + b[0] + aload[i][0];
        acc[i][1] = sy * ir + m->kh * hy + m->kv * cy + b[1] + aload[i][1];
    }

    mps_timer_switch(&s->timer, SOLID_TL_UPDATE);
    long bad = 0;
    double v2max = 0.0;
#pragma omp parallel for schedule(static) if (n >= SOLID_TLSPH_OMP_MIN) \
    reduction(+ : bad) reduction(max : v2max)
    for (size_t i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        v[i][0] += dt * acc[i][0];
        v[i][1] += dt * acc[i][1];
        x[i][0] += dt * v[i][0];
        x[i][1] += dt * v[i][1];
        double v2 = v[i][0] * v[i][0] + v[i][1] * v[i][1];
        v2max = v2 > v2max ? v2 : v2max;
        bad += !isfinite(x[i][0] + x[i][1] + v2);
    }
    mps_timer_stop(&s->timer);
    s->vmax = sqrt(v2max);
    s->time += dt;
    s->steps++;
    if (bad) {
        size_t i = 0;
        while (i < n && isfinite(x[i][0] + x[i][1] + v[i][0] + v[i][1]))
            i++;
        return mps_err_set(err, MPS_EDIVERGED,
                           "solid: particle %zu (body '%s') has a non-finite state at t = %g s "
                           "(step %ld, dt = %g s): the step is above the stability limit or "
                           "the loads are unphysical",
                           i, s->scene.bodies[s->body[i]].name, s->time, s->steps, dt);
    }
    return MPS_OK;
}

void solid_tlsph_diag(const struct solid_tlsph *s, struct solid_tlsph_diag *d)
{
    memset(d, 0, sizeof *d);
    double res = 0.0, ref = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        const struct solid_tlsph_material *m = &s->mat[s->body[i]];
        const double *vi = s->v[i], *xi = s->x[i];
        double Fi[4], Fq[4];
        particle_F(s, (const double(*)[MPS_DIM])s->pgl, i, Fi);
        if (s->quadratic)
            particle_F(s, (const double(*)[MPS_DIM])s->pg, i, Fq);
        else
            memcpy(Fq, Fi, sizeof Fq);
        double mass = m->rho * s->vol;
        d->momentum[0] += mass * vi[0];
        d->momentum[1] += mass * vi[1];
        d->angular += mass * (xi[0] * vi[1] - xi[1] * vi[0]);
        d->kinetic += 0.5 * mass * (vi[0] * vi[0] + vi[1] * vi[1]);
        d->gravity -= mass * (s->scene.g[0] * xi[0] + s->scene.g[1] * xi[1]);
        double exx = 0.5 * (Fq[0] * Fq[0] + Fq[2] * Fq[2] - 1.0);
        double eyy = 0.5 * (Fq[1] * Fq[1] + Fq[3] * Fq[3] - 1.0);
        double exy = 0.5 * (Fq[0] * Fq[1] + Fq[2] * Fq[3]);
        double tr = exx + eyy;
        d->elastic += s->vol * (0.5 * m->lambda * tr * tr +
                                m->mu * (exx * exx + eyy * eyy + 2.0 * exy * exy));
        double hg = 0.0;
        for (size_t p = s->pstart[i]; p < s->pstart[i + 1]; p++) {
            const double *X = s->pX[p], *xj = s->x[s->pj[p]];
            double ex = xj[0] - xi[0] - Fi[0] * X[0] - Fi[1] * X[1];
            double ey = xj[1] - xi[1] - Fi[2] * X[0] - Fi[3] * X[1];
            hg += s->pw[p] * (ex * ex + ey * ey);
            ref += s->pw[p] * (X[0] * X[0] + X[1] * X[1]);
        }
        res += hg;
        d->hourglass += 0.5 * s->hourglass * m->E * s->vol * hg;
    }
    d->hg_residual = ref > 0.0 ? sqrt(res / ref) : 0.0;
}

double solid_tlsph_probe(const struct solid_tlsph *s, int k)
{
    struct solid_tlsph_diag d;
    switch (s->scene.probes[k].kind) {
    case SOLID_PROBE_TANK_ANGLE: return solid_probe_tank_angle(s->motion, s->time);
    case SOLID_PROBE_ENERGY: solid_tlsph_diag(s, &d); return d.kinetic + d.elastic + d.hourglass;
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
    struct solid_tlsph *s = NULL;
    /* the model's limit, not the keys': under the coupler a plain input error
     * naming the solver, since a --model of its command chose the model */
    if (st == MPS_OK && (sc->eps_max > 0.0 || sc->contact != SOLID_CONTACT_NONE))
        st = mps_case_fail(c, err, sc->eps_max > 0.0 ? "solid.eps_max" : "solid.contact",
                           "fracture and contact are in the mps model only (solid.model = %s)",
                           mps_case_string(c, "solid.model"));
    if (st == MPS_OK)
        st = solid_tlsph_create(
            &s, sc, mps_case_double(c, "solid.tlsph.alpha"),
            mps_case_double(c, "solid.tlsph.hourglass"),
            strcmp(mps_case_string(c, "solid.tlsph.correction"), "quadratic") == 0, err);
    if (st == MPS_OK && (st = mps_motion_read(&s->motion, c, err)))
        solid_tlsph_destroy(&s);
    free(sc);
    *self = s;
    return st;
}

static double op_stable_dt(const void *self)
{
    return solid_tlsph_stable_dt(self);
}

static enum mps_status op_set_loads(void *self, const struct solid_loads *f, struct mps_err *err)
{
    struct solid_tlsph *s = self;
    enum mps_status st = solid_loads_accel(&s->scene, s->body, s->n, f, s->aload, err);
    return st ? st : solid_load_probes_set(&s->loadprobes, f, err);
}

static enum mps_status op_advance(void *self, double dt, struct mps_err *err)
{
    struct solid_tlsph *s = self;
    /* the loads act over this step from the positions it starts at */
    solid_load_probes_step(&s->loadprobes, &s->scene, s->body, (const double(*)[MPS_DIM])s->x, dt);
    return solid_tlsph_advance(s, dt, err);
}

static void op_probe_restart(void *self)
{
    solid_load_probes_restart(&((struct solid_tlsph *)self)->loadprobes);
}

/* Surface particles and those within depth of one, on the reference lattice
 * (the pairs never change, so neither does the topology). */
static enum mps_status op_interface(void *self, double depth, struct solid_iface *out,
                                    struct mps_err *err)
{
    struct solid_tlsph *s = self;
    if (depth != s->iface.depth) {
        enum mps_status st = solid_iface_cache_build(
            &s->iface, s->n, (const double(*)[MPS_DIM])s->x0, s->surface, s->id, s->fixed,
            depth, err);
        if (st != MPS_OK)
            return st;
    }
    solid_iface_cache_fill(&s->iface, (const double(*)[MPS_DIM])s->x,
                           (const double(*)[MPS_DIM])s->v, out);
    return MPS_OK;
}

static int op_probe_count(const void *self)
{
    return ((const struct solid_tlsph *)self)->nprobes;
}

static const char *op_probe_name(const void *self, int k)
{
    return ((const struct solid_tlsph *)self)->scene.probes[k].name;
}

static double op_probe_value(const void *self, int k)
{
    return solid_tlsph_probe(self, k);
}

/* Cauchy stress sigma = P F^T / J (F_zz = 1); sigma_zz = lambda tr(E) / J in
 * plane strain, 0 in plane stress. pressure = -tr(sigma)/3. */
static size_t op_snapshot(void *self, const double (**x)[MPS_DIM], struct mps_field *fields,
                          int max_fields, int *nfields)
{
    struct solid_tlsph *s = self;
    solid_tlsph_deform(s);
    for (size_t i = 0; i < s->n; i++) {
        const struct solid_tlsph_material *m = &s->mat[s->body[i]];
        const double *F = s->F[i], *P = s->P[i];
        double J = F[0] * F[3] - F[1] * F[2], iJ = J != 0.0 ? 1.0 / J : 0.0;
        double sxx = iJ * (P[0] * F[0] + P[1] * F[1]);
        double syy = iJ * (P[2] * F[2] + P[3] * F[3]);
        double sxy = iJ * (P[0] * F[2] + P[1] * F[3]);
        double szz = 0.0;
        if (s->scene.plane == SOLID_PLANE_STRAIN)
            szz = iJ * m->lambda * 0.5 *
                  (F[0] * F[0] + F[2] * F[2] + F[1] * F[1] + F[3] * F[3] - 2.0);
        s->von_mises[i] = sqrt(0.5 * ((sxx - syy) * (sxx - syy) + (syy - szz) * (syy - szz) +
                                      (szz - sxx) * (szz - sxx)) + 3.0 * sxy * sxy);
        s->pressure[i] = -(sxx + syy + szz) / 3.0;
        for (int a = 0; a < MPS_DIM; a++)
            s->disp[i][a] = s->x[i][a] - s->x0[i][a];
    }
    *x = (const double(*)[MPS_DIM])s->x;
    *nfields = mps_particles_output(&s->ps, fields, max_fields);
    return s->n;
}

static void op_summary(const void *self, struct mps_json *j)
{
    const struct solid_tlsph *s = self;
    mps_json_str(j, "model", "tlsph");
    if (s->motion) {
        mps_json_object(j, "motion");
        mps_motion_summary(s->motion, j);
        mps_json_close(j);
    }
    mps_json_int(j, "pairs", (long long)s->npairs);
    mps_json_int(j, "fixed_particles", (long long)(s->n - s->nfree));
    mps_json_num(j, "dt_stable", solid_tlsph_stable_dt(s));
    mps_json_num(j, "courant", s->courant);
    mps_json_num(j, "h", s->h);
    mps_json_num(j, "alpha", s->alpha);
    mps_json_num(j, "hourglass", s->hourglass);
    mps_json_str(j, "correction", s->quadratic ? "quadratic" : "linear");
    mps_json_str(j, "plane", s->scene.plane == SOLID_PLANE_STRAIN ? "strain" : "stress");
    mps_json_num(j, "plane_factor", s->scene.plane_factor);
    struct solid_tlsph_diag d;
    solid_tlsph_diag(s, &d);
    mps_json_object(j, "final");
    mps_json_num(j, "kinetic_energy", d.kinetic);
    mps_json_num(j, "elastic_energy", d.elastic);
    mps_json_num(j, "hourglass_energy", d.hourglass);
    mps_json_num(j, "gravity_energy", d.gravity);
    mps_json_num(j, "hourglass_residual", d.hg_residual);
    mps_json_num(j, "momentum_x", d.momentum[0]);
    mps_json_num(j, "momentum_y", d.momentum[1]);
    mps_json_num(j, "angular_momentum", d.angular);
    mps_json_close(j);
    mps_json_object(j, "phase_seconds");
    for (int p = 0; p < s->timer.nphases; p++)
        mps_json_num(j, s->timer.names[p], s->timer.seconds[p]);
    mps_json_close(j);
}

/* The state (solid_model_ops.state_put): every particle field, vmax (the
 * stable step reads it), time, steps and the load probes' means; the pairs
 * never change. */
struct tlsph_scalars {
    double vmax, time;
    int64_t steps;
};

static enum mps_status op_state_put(const void *self, struct mps_ckpt *c, struct mps_err *err)
{
    const struct solid_tlsph *s = self;
    struct tlsph_scalars sc = {s->vmax, s->time, s->steps};
    struct solid_load_probes_mark m;
    memset(&m, 0, sizeof m);
    solid_load_probes_keep(&s->loadprobes, &m);
    enum mps_status st;
    if ((st = mps_particles_put(&s->ps, c, err)) ||
        (st = mps_ckpt_put(c, "tlsph", &sc, sizeof sc, err)))
        return st;
    return mps_ckpt_put(c, "load_probes", &m, sizeof m, err);
}

static enum mps_status op_state_get(void *self, struct mps_ckpt *c, struct mps_err *err)
{
    struct solid_tlsph *s = self;
    struct tlsph_scalars sc;
    struct solid_load_probes_mark m;
    enum mps_status st;
    if ((st = mps_particles_get(&s->ps, c, err)) ||
        (st = mps_ckpt_get(c, "tlsph", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_get(c, "load_probes", &m, sizeof m, err)))
        return st;
    s->vmax = sc.vmax;
    s->time = sc.time;
    s->steps = (long)sc.steps;
    solid_load_probes_back(&s->loadprobes, &m);
    return MPS_OK;
}

static void op_particles(const void *self, struct solid_particles_view *out)
{
    const struct solid_tlsph *s = self;
    *out = (struct solid_particles_view){s->n, s->id, s->body,
                                         (const double(*)[MPS_DIM])s->x0,
                                         (const double(*)[MPS_DIM])s->x,
                                         (const double(*)[MPS_DIM])s->v, s->surface, s->fixed};
}

static void op_destroy(void **self)
{
    struct solid_tlsph *s = *self;
    solid_tlsph_destroy(&s);
    *self = NULL;
}

const struct solid_model_ops solid_tlsph_ops = {
    .name = "tlsph",
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
};
