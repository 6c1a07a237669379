/* The MPS solid's constitutive law (Eq. 25-33, 36-38) against the analytic
 * stress of a homogeneous deformation, with both sets of 2D Lame constants
 * (Eq. 4: plane strain and plane stress).
 *
 * A block is given x = F x0 (F symmetric, so no rotation, theta = 0) and one
 * step from rest; the acceleration of each particle is then the force on it
 * per mass. Inside the lattice a homogeneous state is in equilibrium, so the
 * net force on a set of particles is the traction across the set's boundary.
 * The set is a strip of columns (or rows) in the middle of the block, from
 * a cut through the interior to the free surface: the tractions on its two
 * sides cancel (lattice translation), the free surface carries none, so
 *     sum_i m_i a_i = -sigma . n W,     W = strip width, n = the cut's normal
 * pointing out of the strip. For pair forces on a square lattice that is the
 * virial stress exactly (the lattice sums of w e e^T are isotropic), so the
 * only error is the strain's second order (strain 1e-6: relative 1e-6).
 *
 * The expected stress is linear elasticity written out here, not read from
 * the code: sigma = 2 mu eps + lambda tr(eps) I, mu = E / (2 (1 + nu)),
 * lambda = E nu / ((1 + nu)(1 - 2 nu)) in plane strain and E nu / (1 - nu^2)
 * in plane stress (nu = 0.3: 0.577 E against 0.330 E, so swapping them is off
 * by 43-75%; a 10% error in mu moves every component by 4-10%). */
#include <math.h>

#include "solid_test_util.h"
#include "test_util.h"

#define NX 40
#define NY 40
#define DP 0.01
#define E_MOD 1e8
#define NU 0.3
#define STRAIN 1e-6
#define REL_TOL 1e-4 /* second order in the strain (1e-6) plus round-off; a
                      * 10% error in a Lame constant is a 4-10% error */

struct stress { double xx, yy, xy; };

/* Eq. 4, written out (not solid_scene_lame: a fault there must show) */
static double lame_lambda(int plane)
{
    return plane == SOLID_PLANE_STRAIN ? E_MOD * NU / ((1.0 + NU) * (1.0 - 2.0 * NU))
                                       : E_MOD * NU / (1.0 - NU * NU);
}

static struct stress analytic(int plane, double exx, double eyy, double exy)
{
    double mu = E_MOD / (2.0 * (1.0 + NU)), lambda = lame_lambda(plane);
    double tr = exx + eyy;
    return (struct stress){2.0 * mu * exx + lambda * tr, 2.0 * mu * eyy + lambda * tr,
                           2.0 * mu * exy};
}

/* Net force per metre of thickness on the particles with x0 in the middle
 * half of the columns and y0 above the middle (upper = 1) or, by columns,
 * x0 right of the middle and y0 in the middle half (upper = 0). */
static void strip_force(const struct solid_mps *m, int upper, double f[2])
{
    const double L = NX * DP, H = NY * DP, mass = 1000.0 * DP * DP;
    f[0] = f[1] = 0.0;
    for (size_t i = 0; i < m->n; i++) {
        double x = m->x0[i][0], y = m->x0[i][1];
        int in = upper ? (x > 0.25 * L && x < 0.75 * L && y > 0.5 * H)
                       : (y > 0.25 * H && y < 0.75 * H && x > 0.5 * L);
        if (in) {
            f[0] += mass * m->v[i][0]; /* one step of dt = 1 from rest: v = a */
            f[1] += mass * m->v[i][1];
        }
    }
}

static void deformation_test(int plane, const char *name, double exx, double eyy, double exy)
{
    struct solid_scene sc;
    block_scene(&sc, NX, NY, DP, E_MOD, NU, 0.9);
    sc.plane = plane;
    struct solid_mps *m = make_model(&sc);
    /* x = F x0 about the block's centre, F = I + eps (symmetric) */
    const double cx = 0.5 * NX * DP, cy = 0.5 * NY * DP;
    for (size_t i = 0; i < m->n; i++) {
        double X = m->x0[i][0] - cx, Y = m->x0[i][1] - cy;
        m->x[i][0] = m->x0[i][0] + exx * X + exy * Y;
        m->x[i][1] = m->x0[i][1] + exy * X + eyy * Y;
    }
    struct mps_err err = {0};
    CHECK(solid_mps_advance(m, 1.0, &err) == MPS_OK);
    struct stress s = analytic(plane, exx, eyy, exy);
    const double W = 0.5 * NX * DP; /* the strip holds 20 of the 40 columns */
    double top[2], right[2];
    strip_force(m, 1, top);   /* cut y = H/2, outward normal -y: f = -(sxy, syy) W */
    strip_force(m, 0, right); /* cut x = L/2, outward normal -x: f = -(sxx, sxy) W */
    double got_xx = -right[0] / W, got_xy = -right[1] / W;
    double got_yy = -top[1] / W, got_yx = -top[0] / W;
    double scale = fmax(fmax(fabs(s.xx), fabs(s.yy)), fabs(s.xy));
    printf("%-6s %-9s sigma_xx %.6g (analytic %.6g)  sigma_yy %.6g (%.6g)  "
           "sigma_xy %.6g / %.6g (%.6g) Pa\n",
           plane == SOLID_PLANE_STRAIN ? "strain" : "stress", name, got_xx, s.xx, got_yy, s.yy,
           got_xy, got_yx, s.xy);
    CHECK_NEAR(got_xx, s.xx, REL_TOL * scale);
    CHECK_NEAR(got_yy, s.yy, REL_TOL * scale);
    CHECK_NEAR(got_xy, s.xy, REL_TOL * scale);
    CHECK_NEAR(got_yx, s.xy, REL_TOL * scale);
    /* Eq. 33: the pressure of an interior particle is -lambda tr(eps) */
    size_t mid = 0;
    for (size_t i = 0; i < m->n; i++)
        if (fabs(m->x0[i][0] - cx - 0.5 * DP) < 0.1 * DP &&
            fabs(m->x0[i][1] - cy - 0.5 * DP) < 0.1 * DP)
            mid = i;
    CHECK_NEAR(m->q[mid] * 1000.0, -lame_lambda(plane) * (exx + eyy), REL_TOL * scale);
    solid_mps_destroy(&m);
}

int main(void)
{
    const int planes[2] = {SOLID_PLANE_STRAIN, SOLID_PLANE_STRESS};
    for (int k = 0; k < 2; k++) {
        deformation_test(planes[k], "uniaxial", STRAIN, 0.0, 0.0); /* lambda and mu apart */
        deformation_test(planes[k], "dilation", STRAIN, STRAIN, 0.0);
        deformation_test(planes[k], "shear", 0.0, 0.0, STRAIN);    /* mu alone */
        deformation_test(planes[k], "mixed", STRAIN, -0.4 * STRAIN, 0.7 * STRAIN);
    }
    return test_summary("test_solid_stress");
}
