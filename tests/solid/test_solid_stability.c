/* The stable step (solid_mps.h): C = 1 in solid_mps_stable_dt is at or below
 * the measured linear stability limit of blocks at least 3 particles thick,
 * for several Poisson ratios in plane stress and strain, and the default
 * C = 0.9 is stable for a strip 2 particles thick (the worst shape found,
 * limit 0.96). A block with a random velocity stays bounded below the limit
 * and blows up above it; the measured limits are printed. */
#include <math.h>

#include "solid_test_util.h"
#include "test_util.h"

struct shape {
    double nu;
    enum solid_plane plane;
    int nx, ny;
};

/* Energy growth factor after nsteps at Courant number c. Near the limit the
 * energy sampled at the steps swings by large factors without growing (the
 * modified energy of the symplectic update), so "unstable" means growth by
 * more than 100x, which an unstable mode reaches within a few hundred steps. */
static double growth(const struct shape *sh, double c, int nsteps)
{
    struct solid_scene sc;
    block_scene(&sc, sh->nx, sh->ny, 0.01, 1e8, sh->nu, c);
    sc.plane = sh->plane;
    struct solid_mps *m = make_model(&sc);
    unsigned long seed = 7;
    for (size_t i = 0; i < m->n; i++) {
        m->v[i][0] = 1e-3 * test_rand(&seed);
        m->v[i][1] = 1e-3 * test_rand(&seed);
        m->omega[i] = 1e-1 * test_rand(&seed);
    }
    double e0 = total_energy(m), dt = solid_mps_stable_dt(m);
    struct mps_err err = {0};
    for (int k = 0; k < nsteps; k++)
        if (solid_mps_advance(m, dt, &err) != MPS_OK)
            break;
    double e = total_energy(m);
    solid_mps_destroy(&m);
    return isfinite(e) ? e / e0 : INFINITY;
}

static double threshold(const struct shape *sh)
{
    double lo = 0.8, hi = 1.3;
    for (int it = 0; it < 7; it++) {
        double mid = 0.5 * (lo + hi);
        if (growth(sh, mid, 2000) < 100.0)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

int main(void)
{
    const struct shape blocks[] = {
        {-0.5, SOLID_PLANE_STRESS, 16, 12},
        {0.0, SOLID_PLANE_STRESS, 16, 12},
        {0.3, SOLID_PLANE_STRESS, 16, 12},
        {0.3, SOLID_PLANE_STRAIN, 30, 3},
        {0.45, SOLID_PLANE_STRAIN, 16, 12},
        {0.49, SOLID_PLANE_STRAIN, 16, 12},
    };
    for (size_t k = 0; k < sizeof blocks / sizeof blocks[0]; k++) {
        const struct shape *sh = &blocks[k];
        double below = growth(sh, 0.98, 3000), above = growth(sh, 1.15, 3000);
        double lim = threshold(sh);
        printf("nu = %5.2f plane %s %dx%d: energy ratio after 3000 steps: C = 0.98 -> %.3g, "
               "C = 1.15 -> %.3g; measured limit C = %.3f\n",
               sh->nu, sh->plane == SOLID_PLANE_STRAIN ? "strain" : "stress", sh->nx, sh->ny,
               below, above, lim);
        CHECK(below < 100.0);
        CHECK(above > 1e3);
        CHECK(lim >= 1.0);
    }
    /* Thin strips: below C = 1, but the default 0.9 holds. */
    const struct shape strips[] = {{0.3, SOLID_PLANE_STRESS, 16, 2},
                                   {0.3, SOLID_PLANE_STRESS, 16, 1}};
    for (int k = 0; k < 2; k++) {
        double g = growth(&strips[k], 0.9, 20000);
        printf("strip %dx%d: energy ratio after 20000 steps at C = 0.9: %.3g; measured limit "
               "C = %.3f\n", strips[k].nx, strips[k].ny, g, threshold(&strips[k]));
        CHECK(g < 100.0);
    }
    return test_summary("test_solid_stability");
}
