/* Scenes for the solid tests, built by hand (no case file). */
#ifndef SOLID_TEST_UTIL_H
#define SOLID_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "solid_mps.h"

/* One rectangle body, nx by ny particles of spacing dp from the origin, no
 * gravity, no clamp. */
static inline void block_scene(struct solid_scene *s, int nx, int ny, double dp, double E,
                               double nu, double courant)
{
    memset(s, 0, sizeof *s);
    s->dp = dp;
    s->courant = courant;
    s->plane = SOLID_PLANE_STRESS;
    s->nbodies = 1;
    struct solid_body_def *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "block");
    b->x0 = 0.0;
    b->y0 = 0.0;
    b->x1 = nx * dp;
    b->y1 = ny * dp;
    b->rho = 1000.0;
    b->E = E;
    b->nu = nu;
}

static inline struct solid_mps *make_model(const struct solid_scene *sc)
{
    struct solid_mps *m = NULL;
    struct mps_err err = {0};
    if (solid_mps_create(&m, sc, &err) != MPS_OK) {
        fprintf(stderr, "solid_mps_create: %s\n", err.msg);
        exit(2);
    }
    return m;
}

/* A reproducible small random number in [-1, 1]. */
static inline double test_rand(unsigned long *state)
{
    *state = *state * 6364136223846793005UL + 1442695040888963407UL;
    return (double)(*state >> 11) / (double)(1UL << 53) * 2.0 - 1.0;
}

static inline double total_energy(const struct solid_mps *m)
{
    struct solid_mps_diag d;
    solid_mps_diag(m, &d);
    return d.kinetic + d.elastic + d.gravity;
}

/* The same load (fx, fy), N per metre of depth, on every particle of the
 * model's interface (the surface: depth 0), through its function table, as
 * the coupler sends the fluid's; f gets the interface. The model keeps a copy
 * of the loads. */
static inline enum mps_status uniform_surface_loads(const struct solid_model_ops *ops, void *m,
                                                    double fx, double fy, struct solid_iface *f,
                                                    struct mps_err *err)
{
    enum mps_status st = ops->interface(m, 0.0, f, err);
    if (st != MPS_OK)
        return st;
    double(*force)[MPS_DIM] = calloc(f->n ? f->n : 1, sizeof *force);
    double *pres = calloc(f->n ? f->n : 1, sizeof *pres);
    if (!force || !pres) {
        free(force);
        free(pres);
        return mps_err_set(err, MPS_ENOMEM, "test: out of memory for the loads");
    }
    for (size_t k = 0; k < f->n; k++) {
        force[k][0] = fx;
        force[k][1] = fy;
    }
    struct solid_loads ld = {f->n, f->id, pres, (const double(*)[MPS_DIM])force};
    st = ops->set_loads(m, &ld, err);
    free(force);
    free(pres);
    return st;
}

#endif
