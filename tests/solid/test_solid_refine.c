/* The refinement (solid.refine, solid_refine.h) on a cantilever plate 4
 * coupling particles thick (tests/solid/cases/refine_plate.yml):
 *  - the coupling lattice of a refined model is the unrefined model's: same
 *    ids, positions, surface and clamp flags, for both models;
 *  - a coupling particle's position and velocity are its block's means: the
 *    sums over all coupling particles, times the block size, are the sums
 *    over the model's particles, after the plate has moved;
 *  - the loads' total reaches the model whole (its force probes);
 *  - the point of it: the plate's static tip under a tip load approaches
 *    beam theory as the solid is refined while the coupling lattice stays. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mps_motion.h"
#include "solid_model.h"
#include "solid_scene.h"
#include "test_util.h"

#define CASE "tests/solid/cases/refine_plate.yml"
#define DP 0.01

static struct mps_case *load_case(const char *model, int refine)
{
    char s_model[64], s_refine[64];
    snprintf(s_model, sizeof s_model, "solid.model=%s", model);
    snprintf(s_refine, sizeof s_refine, "solid.refine=%d", refine);
    const char *sets[] = {s_model, s_refine};
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, solid_case_keys,
                                                 mps_motion_keys};
    struct mps_case *c = NULL;
    struct mps_err err = {0};
    if (mps_case_load(&c, CASE, sets, 2, tables, 3, NULL, &err) != MPS_OK) {
        fprintf(stderr, "%s\n", err.msg);
        exit(2);
    }
    return c;
}

struct opened {
    struct mps_case *c;
    const struct solid_model_ops *ops;
    void *m;
};

static struct opened open_model(const char *model, int refine)
{
    struct opened o = {load_case(model, refine), solid_model_find(model), NULL};
    struct mps_err err = {0};
    if (solid_model_open(&o.ops, &o.m, o.c, &err) != MPS_OK) {
        fprintf(stderr, "%s refine %d: %s\n", model, refine, err.msg);
        exit(2);
    }
    return o;
}

static void close_model(struct opened *o)
{
    o->ops->destroy(&o->m);
    mps_case_destroy(&o->c);
}

static int probe_index(const struct opened *o, const char *name)
{
    for (int k = 0; k < o->ops->probe_count(o->m); k++)
        if (strcmp(o->ops->probe_name(o->m, k), name) == 0)
            return k;
    fprintf(stderr, "no probe %s\n", name);
    exit(2);
}

/* The coupling lattice does not depend on the refinement. */
static void lattice_test(const char *model, int refine)
{
    struct opened a = open_model(model, 1), b = open_model(model, refine);
    struct solid_iface ia, ib;
    struct mps_err err = {0};
    CHECK(a.ops->interface(a.m, 2.1 * DP, &ia, &err) == MPS_OK);
    CHECK(b.ops->interface(b.m, 2.1 * DP, &ib, &err) == MPS_OK);
    CHECK(strcmp(a.ops->name, b.ops->name) == 0);
    CHECK(ia.n == ib.n);
    CHECK(ia.n == 33 * 4); /* 4 rows: all within 2.1 dp of a surface */
    double dx = 0.0;
    int same = 1;
    for (size_t k = 0; k < ia.n && k < ib.n; k++) {
        same &= ia.id[k] == ib.id[k] && ia.surface[k] == ib.surface[k] &&
                ia.fixed[k] == ib.fixed[k];
        for (int d = 0; d < MPS_DIM; d++)
            dx = fmax(dx, fabs(ia.x[k][d] - ib.x[k][d]));
    }
    struct solid_particles_view pv;
    b.ops->particles(b.m, &pv);
    printf("%s refine %d: %zu coupling particles over %zu, flags %s, largest position "
           "difference %.3g dp\n", model, refine, ib.n, pv.n, same ? "equal" : "DIFFER", dx / DP);
    CHECK(pv.n == ia.n * (size_t)(refine * refine));
    CHECK(same);
    CHECK(dx < 1e-12 * DP);
    close_model(&a);
    close_model(&b);
}

/* Means after motion, and the loads' total. */
static void means_and_loads_test(const char *model, int refine)
{
    struct opened o = open_model(model, refine);
    struct mps_err err = {0};
    struct solid_iface all;
    CHECK(o.ops->interface(o.m, 1.0, &all, &err) == MPS_OK); /* every coupling particle */
    const size_t n = all.n;
    int *id = malloc(n * sizeof *id);
    double *p = calloc(n, sizeof *p), (*f)[MPS_DIM] = calloc(n, sizeof *f);
    double total[MPS_DIM] = {0};
    for (size_t k = 0; k < n; k++) {
        id[k] = all.id[k];
        /* an uneven load, in both directions, on every particle */
        f[k][0] = 0.3 + 0.01 * (double)k;
        f[k][1] = -1.0 + 0.002 * (double)(k % 7);
        total[0] += f[k][0];
        total[1] += f[k][1];
    }
    struct solid_loads loads = {n, id, p, (const double(*)[MPS_DIM])f};
    CHECK(o.ops->set_loads(o.m, &loads, &err) == MPS_OK);
    double fx = o.ops->probe_value(o.m, probe_index(&o, "load_fx"));
    double fy = o.ops->probe_value(o.m, probe_index(&o, "load_fy"));
    CHECK_NEAR(fx, total[0], 1e-12 * fabs(total[0]));
    CHECK_NEAR(fy, total[1], 1e-12 * fabs(total[1]));
    double dt = o.ops->stable_dt(o.m);
    for (int s = 0; s < 200; s++)
        CHECK(o.ops->advance(o.m, dt, &err) == MPS_OK);
    CHECK(o.ops->interface(o.m, 1.0, &all, &err) == MPS_OK);
    struct solid_particles_view pv;
    o.ops->particles(o.m, &pv);
    double cx[MPS_DIM] = {0}, cv[MPS_DIM] = {0}, fx_[MPS_DIM] = {0}, fv[MPS_DIM] = {0};
    const double block = (double)(refine * refine);
    for (size_t k = 0; k < all.n; k++)
        for (int d = 0; d < MPS_DIM; d++) {
            cx[d] += block * all.x[k][d];
            cv[d] += block * all.v[k][d];
        }
    for (size_t i = 0; i < pv.n; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            fx_[d] += pv.x[i][d];
            fv[d] += pv.v[i][d];
        }
    double vmax = 0.0;
    for (size_t i = 0; i < pv.n; i++)
        vmax = fmax(vmax, hypot(pv.v[i][0], pv.v[i][1]));
    printf("%s refine %d: loads %.6g %.6g N/m reach the model as %.6g %.6g; after 200 steps "
           "sum x %.9g/%.9g, sum v %.6g/%.6g (coupling/model), largest speed %.3g m/s\n", model,
           refine, total[0], total[1], fx, fy, cx[1], fx_[1], cv[1], fv[1], vmax);
    CHECK(vmax > 1e-4); /* it moved */
    for (int d = 0; d < MPS_DIM; d++) {
        CHECK_NEAR(cx[d], fx_[d], 1e-12 * (double)pv.n);
        CHECK_NEAR(cv[d], fv[d], 1e-12 * (double)pv.n * vmax);
    }
    free(id);
    free(p);
    free(f);
    close_model(&o);
}

/* The static tip under a tip load P, brought to rest by a damping load
 * -C m v on the coupling particles (dynamic relaxation through the interface
 * only, as a fluid would load it). */
static double static_tip(const char *model, int refine, double P)
{
    struct opened o = open_model(model, refine);
    struct mps_err err = {0};
    struct solid_iface all;
    CHECK(o.ops->interface(o.m, 1.0, &all, &err) == MPS_OK);
    const size_t n = all.n;
    int *id = malloc(n * sizeof *id), ntip = 0;
    double *p = calloc(n, sizeof *p), (*f)[MPS_DIM] = calloc(n, sizeof *f);
    unsigned char *at_tip = calloc(n, 1); /* the free end's column */
    for (size_t k = 0; k < n; k++)
        ntip += at_tip[k] = all.x[k][0] > 0.3 - DP;
    const double m = 1000.0 * DP * DP, C = 60.0;
    const int tip = probe_index(&o, "tip_dy");
    double dt = o.ops->stable_dt(o.m), t = 0.0, last = 0.0, value = 0.0;
    for (int check = 0; check < 400; check++) {
        for (double t1 = t + 0.005; t < t1; t += dt) {
            CHECK(o.ops->interface(o.m, 1.0, &all, &err) == MPS_OK);
            for (size_t k = 0; k < n; k++) {
                id[k] = all.id[k];
                for (int d = 0; d < MPS_DIM; d++)
                    f[k][d] = -C * m * all.v[k][d];
                if (at_tip[k])
                    f[k][1] -= P / ntip;
            }
            struct solid_loads loads = {n, id, p, (const double(*)[MPS_DIM])f};
            CHECK(o.ops->set_loads(o.m, &loads, &err) == MPS_OK);
            CHECK(o.ops->advance(o.m, dt, &err) == MPS_OK);
        }
        value = o.ops->probe_value(o.m, tip);
        if (check > 20 && fabs(value - last) < 1e-6 * fabs(value))
            break;
        last = value;
    }
    free(id);
    free(p);
    free(f);
    free(at_tip);
    close_model(&o);
    return value;
}

/* Euler-Bernoulli + Timoshenko shear, plane stress, clamped at x = 0. */
static double beam_tip(double P)
{
    const double E = 1e7, nu = 0.3, h = 0.04, L = 0.3, I = h * h * h / 12.0;
    const double G = E / (2.0 * (1.0 + nu)), kappa = 5.0 / 6.0;
    return -(P * L * L * L / (3.0 * E * I) + P * L / (kappa * G * h));
}

static void convergence_test(void)
{
    const double P = 1.0, beam = beam_tip(P);
    double err[3];
    const int k[3] = {1, 2, 4};
    for (int a = 0; a < 3; a++) {
        double tip = static_tip("mps", k[a], P);
        err[a] = tip / beam - 1.0;
        printf("mps refine %d (%d particles thick): static tip %.5g m, beam theory %.5g m, "
               "%+.2f%%\n", k[a], 4 * k[a], tip, beam, 100.0 * err[a]);
    }
    /* Measured: +8.4% at 4 particles thick, -1.0% at 8, -2.2% at 16: the
     * solid converges (the steps shrink 7.6 times from 8 to 16) to about
     * 2.5% under beam theory, whose clamp at x = 0 is not quite the three
     * clamped columns'. Bands of +-1.5 points around those values (the
     * damping's stopping rule moves them by under 0.01 point): a load or a
     * block map off by 10% moves the tip by 10% and leaves them. */
    CHECK(err[0] > 0.069 && err[0] < 0.099);
    CHECK(err[1] > -0.025 && err[1] < 0.005);
    CHECK(err[2] > -0.037 && err[2] < -0.007);
    CHECK(fabs(err[2] - err[1]) < 0.25 * fabs(err[1] - err[0]));
}

/* Fracture cannot be refined: a case error naming the key. */
static void fracture_refused_test(void)
{
    const char *sets[] = {"solid.refine=2", "solid.eps_max=0.01"};
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, solid_case_keys,
                                                 mps_motion_keys};
    struct mps_case *c = NULL;
    struct mps_err err = {0};
    CHECK(mps_case_load(&c, CASE, sets, 2, tables, 3, NULL, &err) == MPS_OK);
    struct solid_scene *sc = malloc(sizeof *sc);
    CHECK(solid_scene_read(sc, c, &err) == MPS_EINPUT);
    printf("fracture refined: %s\n", err.msg);
    CHECK(strstr(err.msg, "solid.refine") && strstr(err.msg, "fracture"));
    free(sc);
    mps_case_destroy(&c);
}

int main(void)
{
    lattice_test("mps", 2);
    lattice_test("mps", 3);
    lattice_test("tlsph", 2);
    means_and_loads_test("mps", 2);
    means_and_loads_test("tlsph", 3);
    convergence_test();
    fracture_refused_test();
    return test_summary("test_solid_refine");
}
