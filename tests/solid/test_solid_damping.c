/* Spin damping of the MPS solid (solid.mps.damping, solid_mps.h):
 *  - a checkerboard of spins (the spin mode, the lattice's highest frequency)
 *    keeps its energy undamped and loses it at the rate zeta w_s damped;
 *  - linear and angular momentum stay conserved to round-off with damping
 *    (the damping forces are pair forces, the torques those of Eq. 41-43);
 *  - a slow, smooth deformation (a bending-like shear wave far below w_s)
 *    loses almost nothing over a period;
 *  - the damping force of one step against k (u + tau du/dt) written out,
 *    tau = 2 zeta / w_s. */
#include <math.h>

#include "solid_test_util.h"
#include "test_util.h"

static const double PI = 3.14159265358979323846;

static double spin_energy(const struct solid_mps *m)
{
    struct solid_mps_diag d;
    solid_mps_diag(m, &d);
    return d.kinetic + d.elastic;
}

/* Energy left after `periods` spin periods from a checkerboard of spins. */
static double spin_decay(double zeta, double periods)
{
    struct solid_scene sc;
    block_scene(&sc, 12, 12, 0.01, 1e8, 0.3, 0.9);
    sc.mps_damping = zeta;
    struct solid_mps *m = make_model(&sc);
    for (size_t i = 0; i < m->n; i++) {
        long ix = lround(m->x0[i][0] / m->dp - 0.5), iy = lround(m->x0[i][1] / m->dp - 0.5);
        m->omega[i] = ((ix + iy) % 2 ? 1.0 : -1.0);
    }
    double e0 = spin_energy(m), dt = solid_mps_stable_dt(m);
    int steps = (int)ceil(periods * 2.0 * PI / m->spin_omega / dt);
    struct mps_err err = {0};
    for (int k = 0; k < steps; k++)
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
    double e = spin_energy(m);
    printf("zeta %.2f: spin-mode energy after %.0f spin periods (%d steps): %.3g of initial\n",
           zeta, periods, steps, e / e0);
    solid_mps_destroy(&m);
    return e / e0;
}

static void momentum_with_damping(void)
{
    struct solid_scene sc;
    block_scene(&sc, 20, 8, 0.01, 1e8, 0.3, 0.9);
    sc.mps_damping = 0.2;
    struct solid_mps *m = make_model(&sc);
    unsigned long seed = 5;
    double pscale = 0.0, lscale = 0.0;
    const double mass = m->mat[0].rho * m->dp * m->dp;
    for (size_t i = 0; i < m->n; i++) {
        m->v[i][0] = 2.0 + 0.5 * test_rand(&seed);
        m->v[i][1] = -1.0 + 0.5 * test_rand(&seed);
        m->omega[i] = 50.0 * test_rand(&seed);
        pscale += mass * hypot(m->v[i][0], m->v[i][1]);
        lscale += mass * hypot(m->x[i][0], m->x[i][1]) * hypot(m->v[i][0], m->v[i][1]);
    }
    struct solid_mps_diag d0, d;
    solid_mps_diag(m, &d0);
    double dt = solid_mps_stable_dt(m);
    struct mps_err err = {0};
    for (int k = 0; k < 5000; k++)
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
    solid_mps_diag(m, &d);
    double dP = hypot(d.momentum[0] - d0.momentum[0], d.momentum[1] - d0.momentum[1]);
    double dL = fabs(d.angular - d0.angular);
    printf("damped: |dP| = %.3g (scale %.3g), |dL| = %.3g (scale %.3g) over 5000 steps\n", dP,
           pscale, dL, lscale);
    CHECK(dP <= 1e-12 * pscale);
    CHECK(dL <= 1e-12 * lscale);
    solid_mps_destroy(&m);
}

/* A long block (2 m x 0.05 m) with a smooth transverse velocity sin(pi x/L):
 * its lowest shear/bending response is ~1e-3 of w_s, where the damping
 * ratio is zeta w / w_s; the energy after the run must match the undamped. */
static double smooth_energy(double zeta)
{
    struct solid_scene sc;
    block_scene(&sc, 100, 5, 0.01, 1e8, 0.3, 0.9);
    sc.mps_damping = zeta;
    struct solid_mps *m = make_model(&sc);
    for (size_t i = 0; i < m->n; i++)
        m->v[i][1] = 0.01 * sin(PI * m->x0[i][0] / 1.0);
    double e0 = spin_energy(m), dt = solid_mps_stable_dt(m);
    struct mps_err err = {0};
    for (int k = 0; k < 4000; k++)
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
    double e = spin_energy(m);
    solid_mps_destroy(&m);
    return e / e0;
}

/* The damping force itself: Kelvin-Voigt on each bond, k_ij (u_ij + tau
 * du_ij/dt) with tau = 2 zeta / w_s (solid_mps.h: zeta is the damping ratio
 * of a mode at the spin frequency w_s). At rest in the reference state
 * (u = 0, no stretch, no rotation) with random velocities, one step changes
 * each velocity by dt sum_j k_ij tau (v_j - v_i) and nothing else: the sum
 * is written out here from the bond arrays, tau from its definition. */
static void kelvin_voigt_force(void)
{
    struct solid_scene sc;
    block_scene(&sc, 9, 7, 0.01, 1e8, 0.3, 0.9);
    const double zeta = 0.3;
    sc.mps_damping = zeta;
    struct solid_mps *m = make_model(&sc);
    const double tau = 2.0 * zeta / m->spin_omega, dt = 0.5 * solid_mps_stable_dt(m);
    unsigned long seed = 17;
    double(*v0)[MPS_DIM] = malloc(m->n * sizeof *v0);
    CHECK(v0 != NULL && tau > 0.0);
    for (size_t i = 0; v0 && i < m->n; i++)
        for (int d = 0; d < MPS_DIM; d++)
            m->v[i][d] = v0[i][d] = 1e-3 * test_rand(&seed);
    struct mps_err err = {0};
    CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
    double worst = 0.0, big = 0.0;
    for (size_t i = 0; v0 && i < m->n; i++) {
        double a[MPS_DIM] = {0.0, 0.0};
        for (size_t b = m->bstart[i]; b < m->bstart[i + 1]; b++)
            for (int d = 0; d < MPS_DIM; d++)
                a[d] += m->bk[b] * tau * (v0[m->bj[b]][d] - v0[i][d]);
        for (int d = 0; d < MPS_DIM; d++) {
            worst = fmax(worst, fabs(m->v[i][d] - v0[i][d] - dt * a[d]));
            big = fmax(big, fabs(dt * a[d]));
        }
    }
    printf("Kelvin-Voigt force, zeta %.1f (tau %.3g s): |dv - dt sum k tau dv_ij| <= %.3g of "
           "%.3g m/s\n", zeta, tau, worst, big);
    CHECK(big > 0.0 && worst <= 1e-9 * big);
    free(v0);
    solid_mps_destroy(&m);
}

int main(void)
{
    kelvin_voigt_force();
    /* undamped: the spin mode keeps its energy (symplectic, bounded) */
    CHECK(spin_decay(0.0, 100.0) > 0.5);
    /* zeta = 0.1: a pure spin mode keeps exp(-4 pi zeta periods), 3e-55 after
     * 100 periods; the checkerboard also excites slower lattice modes, damped
     * at zeta w / w_s, so ask only for 1e-2 */
    CHECK(spin_decay(0.1, 100.0) < 1e-2);
    momentum_with_damping();
    double e0 = smooth_energy(0.0), e1 = smooth_energy(0.1);
    printf("smooth motion, 4000 steps: energy ratio %.6f undamped, %.6f with zeta 0.1\n", e0, e1);
    CHECK(fabs(e1 - e0) < 0.01 * e0);
    return test_summary("test_solid_damping");
}
