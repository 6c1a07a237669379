/* TLSPH operators on fields with known answers (solid_tlsph.h):
 *  - the corrected gradient reproduces any affine map: F_i = A at every
 *    particle, surfaces, corners and clamped particles included;
 *  - a rigid rotation (90 degrees) gives F = R and zero stress (St
 *    Venant-Kirchhoff is frame invariant: the model is geometrically exact);
 *  - patch test: a uniform stretch gives the same stress at every particle,
 *    equal to the analytical one, and zero force on every particle farther
 *    than two supports from the surface;
 *  - the affine maps leave the hourglass residual at zero;
 *  - surface flags: the outer ring of a block; the interface export.
 * With the argument "quadratic" the same runs with the second-order
 * correction (solid.tlsph.correction: quadratic). */
#include <math.h>

#include "test_util.h"
#include "tlsph_test_util.h"

static void set_affine(struct solid_tlsph *m, const double A[4], double bx, double by)
{
    for (size_t i = 0; i < m->n; i++) {
        double X = m->x0[i][0], Y = m->x0[i][1];
        m->x[i][0] = A[0] * X + A[1] * Y + bx;
        m->x[i][1] = A[2] * X + A[3] * Y + by;
    }
}

static void linear_field_test(void)
{
    struct solid_scene sc;
    tl_block_scene(&sc, 12, 7, 0.01, 1e8, 0.3, 0.9);
    sc.nclamps = 1; /* left 3 columns fixed: their F is still computed */
    sc.clamps[0] = (struct solid_clamp_def){0, 0.0, 0.0, 0.03, 0.07};
    struct solid_tlsph *m = tl_make(&sc, 1.0, 0.05);
    const double A[4] = {1.02, 0.31, -0.27, 0.95};
    set_affine(m, A, 0.5, -0.2);
    solid_tlsph_deform(m);
    double err = 0.0;
    for (size_t i = 0; i < m->n; i++)
        for (int k = 0; k < 4; k++)
            err = fmax(err, fabs(m->F[i][k] - A[k]));
    printf("affine map: max |F - A| = %.3g over %zu particles (%zu fixed)\n", err, m->n,
           m->n - m->nfree);
    CHECK(err < 1e-12);
    CHECK(m->n - m->nfree == 21);
    struct solid_tlsph_diag d;
    solid_tlsph_diag(m, &d);
    CHECK(d.hg_residual < 1e-12);
    CHECK(d.hourglass < 1e-20);
    solid_tlsph_destroy(&m);
}

static void rotation_test(void)
{
    struct solid_scene sc;
    tl_block_scene(&sc, 9, 5, 0.01, 1e8, 0.3, 0.9);
    struct solid_tlsph *m = tl_make(&sc, 1.0, 0.05);
    const double R[4] = {0.0, -1.0, 1.0, 0.0};
    set_affine(m, R, 0.3, 0.1);
    solid_tlsph_deform(m);
    double perr = 0.0;
    for (size_t i = 0; i < m->n; i++)
        for (int k = 0; k < 4; k++)
            perr = fmax(perr, fabs(m->P[i][k]));
    printf("rigid rotation by 90 degrees: max |P| = %.3g Pa (E = 1e8 Pa)\n", perr);
    CHECK(perr < 1e-4); /* round-off of E * 1e-12 */
    struct solid_tlsph_diag d;
    solid_tlsph_diag(m, &d);
    CHECK(d.elastic < 1e-12);
    solid_tlsph_destroy(&m);
}

static void patch_test(void)
{
    const int nx = 20, ny = 16;
    const double dp = 0.01, E = 1e8, nu = 0.3, sx = 1.01, sy = 0.995;
    struct solid_scene sc;
    tl_block_scene(&sc, nx, ny, dp, E, nu, 0.9);
    struct solid_tlsph *m = tl_make(&sc, 1.0, 0.05);
    const double A[4] = {sx, 0.0, 0.0, sy};
    set_affine(m, A, 0.0, 0.0);
    solid_tlsph_deform(m);
    /* analytical SVK (plane stress Lame constants, as solid_scene_lame) */
    double lambda = E * nu / (1.0 - nu * nu), mu = E / (2.0 * (1.0 + nu));
    double exx = 0.5 * (sx * sx - 1.0), eyy = 0.5 * (sy * sy - 1.0);
    double Pxx = sx * (lambda * (exx + eyy) + 2.0 * mu * exx);
    double Pyy = sy * (lambda * (exx + eyy) + 2.0 * mu * eyy);
    double perr = 0.0;
    for (size_t i = 0; i < m->n; i++)
        perr = fmax(perr, fmax(fmax(fabs(m->P[i][0] - Pxx), fabs(m->P[i][3] - Pyy)),
                               fmax(fabs(m->P[i][1]), fabs(m->P[i][2]))));
    printf("patch test: P = diag(%.6g, %.6g) Pa, max deviation %.3g Pa\n", Pxx, Pyy, perr);
    CHECK(perr < 1e-6 * fabs(Pxx));
    /* Forces: one step with v = 0 and dt tiny; the interior stays at rest. */
    struct mps_err err = {0};
    CHECK(solid_tlsph_advance(m, 1e-12, &err) == MPS_OK);
    double margin = 2.0 * 2.0 * m->h + 1e-9, amax_in = 0.0, amax_out = 0.0;
    double acc_scale = fabs(Pxx) / (1000.0 * dp); /* stress / (rho dp) */
    for (size_t i = 0; i < m->n; i++) {
        double X = m->x0[i][0], Y = m->x0[i][1];
        double a = hypot(m->acc[i][0], m->acc[i][1]);
        int inner = X > margin && X < nx * dp - margin && Y > margin && Y < ny * dp - margin;
        if (inner)
            amax_in = fmax(amax_in, a);
        else
            amax_out = fmax(amax_out, a);
    }
    printf("patch test: max |a| inside %.3g, near the surface %.3g m/s^2 (scale %.3g)\n",
           amax_in, amax_out, acc_scale);
    CHECK(amax_in < 1e-9 * acc_scale);
    CHECK(amax_out > 0.1 * acc_scale); /* the free surface is pulled in */
    solid_tlsph_destroy(&m);
}

static void surface_test(void)
{
    struct solid_scene sc;
    tl_block_scene(&sc, 12, 8, 0.01, 1e8, 0.3, 0.9);
    struct solid_tlsph *m = tl_make(&sc, 1.0, 0.05);
    size_t ns = 0;
    for (size_t i = 0; i < m->n; i++)
        ns += m->surface[i];
    printf("surface: %zu of %zu particles (ring: %d); interior neighbours %d\n", ns, m->n,
           2 * (12 + 8) - 4, m->full_count);
    CHECK(ns == 2 * (12 + 8) - 4);
    CHECK(m->full_count == 20);
    struct solid_iface f;
    struct mps_err err = {0};
    CHECK(solid_tlsph_ops.interface(m, 0.0, &f, &err) == MPS_OK);
    CHECK(f.n == ns);
    /* depth 2 dp: the ring plus two more rings of inner particles */
    CHECK(solid_tlsph_ops.interface(m, 2.0 * 0.01, &f, &err) == MPS_OK);
    size_t nsurf = 0;
    for (size_t k = 0; k < f.n; k++)
        nsurf += f.surface[k];
    CHECK(nsurf == ns);
    CHECK(f.n == (size_t)(12 * 8 - 6 * 2));
    solid_tlsph_destroy(&m);

    /* a single row has no 2D neighbourhood: an error naming the body */
    tl_block_scene(&sc, 12, 1, 0.01, 1e8, 0.3, 0.9);
    struct solid_tlsph *bad = NULL;
    CHECK(solid_tlsph_create(&bad, &sc, 1.0, 0.05, 0, &err) == MPS_EINPUT);
    CHECK(bad == NULL);
    CHECK(strstr(err.msg, "'block'") != NULL);
    printf("single row: %s\n", err.msg);
}

/* With alpha = 0 the forces are minus the gradient of U + U_hg (central
 * differences on a randomly deformed block, surface particles included). */
static void gradient_test(void)
{
    struct solid_scene sc;
    tl_block_scene(&sc, 7, 5, 0.01, 1e8, 0.3, 0.9);
    struct solid_tlsph *m = tl_make(&sc, 0.0, 0.5);
    unsigned long seed = 5;
    for (size_t i = 0; i < m->n; i++) {
        m->x[i][0] += 2e-4 * tl_rand(&seed) + 0.01 * m->x0[i][1];
        m->x[i][1] += 2e-4 * tl_rand(&seed);
    }
    struct mps_err err = {0};
    CHECK(solid_tlsph_advance(m, 1e-30, &err) == MPS_OK); /* fills acc, moves nothing */
    const double mass = 1000.0 * 0.01 * 0.01, eps = 1e-7;
    double worst = 0.0, scale = 0.0;
    for (size_t i = 0; i < m->n; i++)
        for (int a = 0; a < 2; a++) {
            struct solid_tlsph_diag dp_, dm_;
            double x = m->x[i][a];
            m->x[i][a] = x + eps;
            solid_tlsph_diag(m, &dp_);
            m->x[i][a] = x - eps;
            solid_tlsph_diag(m, &dm_);
            m->x[i][a] = x;
            double f = -((dp_.elastic + dp_.hourglass) - (dm_.elastic + dm_.hourglass)) /
                       (2.0 * eps);
            worst = fmax(worst, fabs(f - mass * m->acc[i][a]));
            scale = fmax(scale, fabs(f));
        }
    printf("forces = -grad(U + U_hg): max deviation %.3g N/m (largest force %.3g N/m)\n", worst,
           scale);
    CHECK(worst < 1e-5 * scale);
    solid_tlsph_destroy(&m);
}

/* Bending stiffness: the exact pure-bending field u = (-k X Y, k X^2 / 2) on a
 * beam of b/dp rows (nu = 0), elastic energy of the middle metre against the
 * continuum E I k^2 / 2. F is exact inside (the neighbourhood is symmetric)
 * but at the outer two rows the one-sided fit returns the strain of a point
 * further in, so the beam is too soft, by a second-order amount: this is the
 * error of the TLSPH cantilever at coarse resolution (docs/solid_models.md).
 * The quadratic correction is exact for this field: only the lattice's own
 * second moment of area remains. */
static double bending_ratio(int rows)
{
    const double b = 0.1, dp = b / rows, len = 2.0, kap = 1e-3, E = 1e8;
    struct solid_scene sc;
    tl_block_scene(&sc, (int)(len / dp + 0.5), rows, dp, E, 0.0, 0.9);
    sc.bodies[0].y0 = -0.5 * b;
    sc.bodies[0].y1 = 0.5 * b;
    struct solid_tlsph *m = tl_make(&sc, 1.0, 0.05);
    for (size_t i = 0; i < m->n; i++) {
        double X = m->x0[i][0] - 0.5 * len, Y = m->x0[i][1];
        m->x[i][0] = m->x0[i][0] - kap * X * Y;
        m->x[i][1] = m->x0[i][1] + 0.5 * kap * X * X;
    }
    solid_tlsph_deform(m);
    double u = 0.0, mu = 0.5 * E; /* nu = 0: lambda = 0 */
    for (size_t i = 0; i < m->n; i++) {
        if (fabs(m->x0[i][0] - 0.5 * len) > 0.5)
            continue;
        const double *F = m->F[i];
        double exx = 0.5 * (F[0] * F[0] + F[2] * F[2] - 1.0);
        double eyy = 0.5 * (F[1] * F[1] + F[3] * F[3] - 1.0);
        double exy = 0.5 * (F[0] * F[1] + F[2] * F[3]);
        u += m->vol * mu * (exx * exx + eyy * eyy + 2.0 * exy * exy);
    }
    solid_tlsph_destroy(&m);
    return u / (0.5 * E * b * b * b / 12.0 * kap * kap);
}

static void bending_test(void)
{
    double r5 = bending_ratio(5), r10 = bending_ratio(10), r20 = bending_ratio(20);
    double order = log((1.0 - r5) / (1.0 - r10)) / log(2.0);
    printf("bending stiffness EI_h / EI: b/dp = 5: %.4f, 10: %.4f, 20: %.4f (order %.2f)\n",
           r5, r10, r20, order);
    if (tl_quadratic) { /* exact: the lattice's own sum dp y^2 = (1 - (dp/b)^2) b^3/12 */
        CHECK(fabs(r5 - 0.96) < 1e-3);
        CHECK(fabs(r10 - 0.99) < 1e-3);
        CHECK(fabs(r20 - 0.9975) < 1e-3);
    } else {
        /* no closed form for the linear correction: the values this
         * function measured when the model was written (2026-11), printed
         * above by `build/tests/test_tlsph_operators`; the convergence order
         * below is the part that follows from the method (second order) */
        CHECK(fabs(r5 - 0.762) < 0.005);
        CHECK(fabs(r10 - 0.930) < 0.005);
        CHECK(fabs(r20 - 0.981) < 0.003);
    }
    CHECK(order > 1.7);
}

int main(int argc, char **argv)
{
    tl_quadratic = argc > 1 && strcmp(argv[1], "quadratic") == 0;
    printf("correction: %s\n", tl_quadratic ? "quadratic" : "linear");
    bending_test();
    gradient_test();
    linear_field_test();
    rotation_test();
    patch_test();
    surface_test();
    return test_summary("test_tlsph_operators");
}
