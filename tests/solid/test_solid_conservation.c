/* Conservation (issue: free block, no clamp, no gravity):
 *  - with an initial velocity, a spin and a random perturbation, linear and
 *    angular momentum (orbital + particle spin) are conserved to round-off
 *    over 1e4 steps: pair forces are exactly opposite and the spin torques
 *    cancel the moment of the shear forces (Eq. 41-43);
 *  - released from an initial strain, the total energy stays bounded (no
 *    growth) over 1e5 steps: the forces are the gradient of the elastic
 *    energy and the update is symplectic. */
#include <math.h>

#include "solid_test_util.h"
#include "test_util.h"

static void momentum_test(void)
{
    struct solid_scene sc;
    block_scene(&sc, 20, 8, 0.01, 1e8, 0.3, 0.9);
    struct solid_mps *m = make_model(&sc);
    const double spin = 20.0, vx = 3.0, vy = -1.0, xc = 0.1, yc = 0.04; /* rad/s, m/s, m */
    unsigned long seed = 11;
    for (size_t i = 0; i < m->n; i++) {
        double rx = m->x[i][0] - xc, ry = m->x[i][1] - yc;
        m->v[i][0] = vx - spin * ry + 0.05 * test_rand(&seed);
        m->v[i][1] = vy + spin * rx + 0.05 * test_rand(&seed);
        m->omega[i] = spin + 10.0 * test_rand(&seed);
    }
    struct solid_mps_diag d0, d;
    solid_mps_diag(m, &d0);
    double dt = solid_mps_stable_dt(m), pscale = 0.0, lscale = 0.0, dp_max = 0.0, dl_max = 0.0;
    for (size_t i = 0; i < m->n; i++) {
        double mass = m->mat[0].rho * m->dp * m->dp;
        pscale += mass * hypot(m->v[i][0], m->v[i][1]);
        lscale += mass * hypot(m->x[i][0], m->x[i][1]) * hypot(m->v[i][0], m->v[i][1]);
    }
    struct mps_err err = {0};
    for (int k = 0; k < 10000; k++) {
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
        if (k % 100 == 99) {
            solid_mps_diag(m, &d);
            dp_max = fmax(dp_max, hypot(d.momentum[0] - d0.momentum[0],
                                        d.momentum[1] - d0.momentum[1]));
            dl_max = fmax(dl_max, fabs(d.angular - d0.angular));
        }
    }
    /* the block has moved ~0.09 m and turned ~0.5 rad */
    printf("momentum: |dP| = %.3g (scale %.3g, %.2g), |dL| = %.3g (scale %.3g, %.2g) over "
           "10000 steps\n", dp_max, pscale, dp_max / pscale, dl_max, lscale, dl_max / lscale);
    CHECK(dp_max <= 1e-12 * pscale);
    CHECK(dl_max <= 1e-12 * lscale);
    solid_mps_destroy(&m);
}

/* The update is leapfrog with v at half steps, for which
 * E_n = sum 1/2 m v_{n-1/2} . v_{n+1/2} + 1/2 I w_{n-1/2} w_{n+1/2} + U(x_n)
 * is conserved exactly for a linear system; the plain sum 1/2 m v^2 + U swings
 * by tens of percent when the modes near the stability limit are excited. */
static void energy_test(void)
{
    struct solid_scene sc;
    block_scene(&sc, 10, 6, 0.01, 1e8, 0.3, 0.9);
    struct solid_mps *m = make_model(&sc);
    /* 1% stretch along x, 0.5% shear: a large initial strain */
    for (size_t i = 0; i < m->n; i++) {
        double x = m->x0[i][0], y = m->x0[i][1];
        m->x[i][0] = x + 0.01 * x + 0.005 * y;
        m->x[i][1] = y;
    }
    const double mass = m->mat[0].rho * m->dp * m->dp, inertia = mass * m->dp * m->dp / 6.0;
    double(*vold)[MPS_DIM] = malloc(m->n * sizeof *vold);
    double *wold = malloc(m->n * sizeof *wold);
    double dt = solid_mps_stable_dt(m), e0 = -1.0, p0 = total_energy(m);
    const int nsteps = 100000, window = nsteps / 10;
    double first = 0.0, last = 0.0, pfirst = 0.0, plast = 0.0, emax = 0.0;
    struct mps_err err = {0};
    for (int k = 0; k < nsteps; k++) {
        struct solid_mps_diag d;
        int sample = k % 10 == 0;
        if (sample) {
            solid_mps_diag(m, &d); /* U(x_n), and the plain energy */
            memcpy(vold, m->v, m->n * sizeof *vold);
            memcpy(wold, m->omega, m->n * sizeof *wold);
        }
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
        if (!sample)
            continue;
        double kin = 0.0;
        for (size_t i = 0; i < m->n; i++)
            kin += 0.5 * mass * (vold[i][0] * m->v[i][0] + vold[i][1] * m->v[i][1]) +
                   0.5 * inertia * wold[i] * m->omega[i];
        double e = kin + d.elastic, pe = d.kinetic + d.elastic;
        if (e0 < 0.0)
            e0 = e;
        double dev = fabs(e - e0) / e0, pdev = fabs(pe - p0) / p0;
        emax = fmax(emax, dev);
        if (k < window) {
            first = fmax(first, dev);
            pfirst = fmax(pfirst, pdev);
        }
        if (k >= nsteps - window) {
            last = fmax(last, dev);
            plast = fmax(plast, pdev);
        }
    }
    printf("energy over %d steps: leapfrog energy E0 = %.6g J, max |E - E0|/E0 = %.3g (first "
           "tenth %.3g, last tenth %.3g); plain energy max deviation first tenth %.3g, last "
           "tenth %.3g\n", nsteps, e0, emax, first, last, pfirst, plast);
    CHECK(emax <= 1e-2);               /* bounded (within 5% over 1e7 steps) */
    CHECK(last <= 2.0 * first + 1e-9); /* no growth */
    CHECK(plast <= 1.5 * pfirst);      /* no growth of the plain energy either */
    free(vold);
    free(wold);
    solid_mps_destroy(&m);
}

int main(void)
{
    momentum_test();
    energy_test();
    return test_summary("test_solid_conservation");
}
