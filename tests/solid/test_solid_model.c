/* The MPS solid behind solid_model_ops, without a case file:
 *  - clamps: fixed particles never move under gravity;
 *  - probes: the nearest particle, or the mean of tied ones (even rows);
 *  - several bodies with their own materials: a body evolves bit for bit as
 *    it does alone, and the step is the smallest body's;
 *  - loads: set_loads adds force / (rho dp^2); unknown ids are errors;
 *  - interface: surface ring + inner particles within depth;
 *  - threads: 1 and 2 OpenMP threads give bit-identical states. */
#include <math.h>
#include <omp.h>

#include "solid_test_util.h"
#include "test_util.h"

static void clamp_probe_test(int rows)
{
    struct solid_scene sc;
    block_scene(&sc, 40, rows, 0.01, 1e7, 0.3, 0.9);
    sc.bodies[0].x0 = -0.03; /* 3 clamp layers beyond the root */
    sc.bodies[0].x1 = 0.4;
    sc.g[1] = -9.81;
    sc.nclamps = 1;
    sc.clamps[0] = (struct solid_clamp_def){0, -0.03, 0.0, 0.0, rows * 0.01};
    sc.nprobes = 3;
    sc.probes[0] = (struct solid_probe_def){"tip", SOLID_PROBE_DY, 0.4, 0.5 * rows * 0.01, -1};
    sc.probes[1] = (struct solid_probe_def){"root_y", SOLID_PROBE_Y, -0.015, 0.0, -1};
    sc.probes[2] = (struct solid_probe_def){"tip_dx", SOLID_PROBE_DX, 0.4, 0.5 * rows * 0.01, -1};
    struct solid_mps *m = make_model(&sc);
    CHECK(m->n - m->nfree == (size_t)(3 * rows));
    CHECK(m->probe_n[0] == (rows % 2 ? 1 : 2));
    CHECK(m->probe_n[1] == 1);
    CHECK_NEAR(solid_mps_probe(m, 0), 0.0, 0.0);
    CHECK_NEAR(solid_mps_probe(m, 1), 0.005, 1e-15);
    double dt = solid_mps_stable_dt(m);
    struct mps_err err = {0};
    for (int k = 0; k < 2000; k++)
        CHECK(solid_mps_advance(m, dt, &err) == MPS_OK);
    double moved = 0.0;
    for (size_t i = 0; i < m->n; i++)
        if (m->fixed[i])
            moved = fmax(moved, fabs(m->x[i][0] - m->x0[i][0]) + fabs(m->x[i][1] - m->x0[i][1]) +
                                    fabs(m->theta[i]));
    double tip = solid_mps_probe(m, 0);
    printf("clamped strip of %d rows: tip dy after 2000 steps %.4g m (mean of %d particles), "
           "clamp moved %.3g\n", rows, tip, m->probe_n[0], moved);
    CHECK(moved == 0.0);
    CHECK(tip < 0.0);
    /* the tip probes are the mean of their particles' displacement (dx:
     * the bent strip's tip moves back, by about tip^2 / length) */
    double mean = 0.0, mean_x = 0.0;
    for (int a = 0; a < m->probe_n[0]; a++) {
        size_t i = m->probe_i[0][a];
        mean += (m->x[i][1] - m->x0[i][1]) / m->probe_n[0];
        mean_x += (m->x[i][0] - m->x0[i][0]) / m->probe_n[0];
    }
    CHECK_NEAR(tip, mean, 1e-15);
    CHECK(m->probe_n[2] == m->probe_n[0] && fabs(mean_x) > 1e-9);
    CHECK_NEAR(solid_mps_probe(m, 2), mean_x, 1e-12 * fabs(mean_x));
    solid_mps_destroy(&m);
}

static void bodies_test(void)
{
    struct solid_scene one, two;
    block_scene(&one, 10, 6, 0.01, 1e8, 0.3, 0.9);
    one.bodies[0].v[0] = 1.0;
    two = one;
    two.nbodies = 2;
    two.bodies[1] = two.bodies[0];
    snprintf(two.bodies[1].name, sizeof two.bodies[1].name, "stiff");
    two.bodies[1].y0 = 0.1; /* above the first, not touching */
    two.bodies[1].y1 = 0.16;
    two.bodies[1].E = 4e8;  /* stiffer: the step is its */
    two.bodies[1].rho = 2000.0;
    two.bodies[1].v[0] = -2.0;
    struct solid_mps *a = make_model(&one), *b = make_model(&two);
    CHECK(b->n == 2 * a->n);
    double dt = solid_mps_stable_dt(b);
    CHECK(dt < solid_mps_stable_dt(a));
    CHECK_NEAR(dt / solid_mps_stable_dt(a), sqrt(2.0 / 4.0), 1e-12); /* c ~ sqrt(E/rho) */
    /* a small initial strain so that there are forces */
    for (size_t i = 0; i < a->n; i++) {
        a->x[i][0] += 1e-3 * a->x0[i][1];
        b->x[i][0] += 1e-3 * b->x0[i][1];
    }
    struct mps_err err = {0};
    for (int k = 0; k < 500; k++) {
        CHECK(solid_mps_advance(a, dt, &err) == MPS_OK);
        CHECK(solid_mps_advance(b, dt, &err) == MPS_OK);
    }
    int same = 1;
    for (size_t i = 0; i < a->n; i++)
        same &= a->x[i][0] == b->x[i][0] && a->x[i][1] == b->x[i][1] &&
                a->theta[i] == b->theta[i];
    CHECK(same);
    int bonds_cross = 0;
    for (size_t i = 0; i < b->n; i++)
        for (size_t e = b->bstart[i]; e < b->bstart[i + 1]; e++)
            bonds_cross += b->body[b->bj[e]] != b->body[i];
    CHECK(bonds_cross == 0);
    solid_mps_destroy(&a);
    solid_mps_destroy(&b);
}

static void loads_test(void)
{
    struct solid_scene sc;
    block_scene(&sc, 10, 6, 0.01, 1e8, 0.3, 0.9);
    struct solid_mps *m = make_model(&sc);
    const struct solid_model_ops *ops = solid_model_find("mps");
    CHECK(ops == &solid_mps_ops);
    CHECK(solid_model_find("nosuch") == NULL);
    struct solid_iface f;
    struct mps_err err = {0};
    CHECK(uniform_surface_loads(ops, m, 0.0, 2.0, &f, &err) == MPS_OK); /* N per metre depth */
    CHECK(f.n == 2 * 10 + 2 * 6 - 4);
    struct solid_mps_diag d0, d1;
    solid_mps_diag(m, &d0);
    double dt = ops->stable_dt(m);
    for (int k = 0; k < 100; k++)
        CHECK(ops->advance(m, dt, &err) == MPS_OK);
    solid_mps_diag(m, &d1);
    CHECK_NEAR(d1.momentum[1] - d0.momentum[1], 2.0 * f.n * 100 * dt, 1e-12);
    CHECK_NEAR(d1.momentum[0] - d0.momentum[0], 0.0, 1e-12);
    int bad_id = 100000;
    double bad_force[1][MPS_DIM] = {{0.0, 2.0}}, bad_pres[1] = {0.0};
    struct solid_loads bad = {1, &bad_id, bad_pres, (const double(*)[MPS_DIM])bad_force};
    CHECK(ops->set_loads(m, &bad, &err) == MPS_EINPUT);
    printf("loads: %s\n", err.msg);
    solid_mps_destroy(&m);

    /* interface with depth: 12 x 10 block, rings 1 and 2 within 2 dp */
    block_scene(&sc, 12, 10, 0.01, 1e8, 0.3, 0.9);
    m = make_model(&sc);
    CHECK(ops->interface(m, 0.02, &f, &err) == MPS_OK);
    size_t nsurf = 0;
    for (size_t k = 0; k < f.n; k++)
        nsurf += f.surface[k];
    printf("interface: %zu particles, %zu on the surface\n", f.n, nsurf);
    CHECK(nsurf == 40);
    CHECK(f.n == 40 + 32 + 24);
    m->x[f.id[0]][0] += 0.5; /* positions are copied at each call */
    CHECK(ops->interface(m, 0.02, &f, &err) == MPS_OK);
    CHECK_NEAR(f.x[0][0], m->x[f.id[0]][0], 0.0);
    solid_mps_destroy(&m);
}

static void threads_test(void)
{
    struct solid_scene sc;
    block_scene(&sc, 90, 60, 0.01, 1e8, 0.3, 0.9); /* above the threading threshold */
    struct solid_mps *s[2];
    for (int t = 0; t < 2; t++) {
        s[t] = make_model(&sc);
        for (size_t i = 0; i < s[t]->n; i++)
            s[t]->x[i][0] += 1e-3 * s[t]->x0[i][1] * s[t]->x0[i][1];
        omp_set_num_threads(t + 1);
        struct mps_err err = {0};
        for (int k = 0; k < 50; k++)
            CHECK(solid_mps_advance(s[t], solid_mps_stable_dt(s[t]), &err) == MPS_OK);
    }
    CHECK(memcmp(s[0]->x, s[1]->x, s[0]->n * sizeof *s[0]->x) == 0);
    CHECK(memcmp(s[0]->theta, s[1]->theta, s[0]->n * sizeof *s[0]->theta) == 0);
    solid_mps_destroy(&s[0]);
    solid_mps_destroy(&s[1]);
}

int main(void)
{
    clamp_probe_test(5);
    clamp_probe_test(4);
    bodies_test();
    loads_test();
    threads_test();
    return test_summary("test_solid_model");
}
