/* Scenes and helpers for the TLSPH solid tests, built by hand (no case file). */
#ifndef TLSPH_TEST_UTIL_H
#define TLSPH_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "solid_tlsph.h"

/* One rectangle body, nx by ny particles of spacing dp from the origin, no
 * gravity, no clamp, plane stress, rho = 1000. */
static inline void tl_block_scene(struct solid_scene *s, int nx, int ny, double dp, double E,
                                  double nu, double courant)
{
    memset(s, 0, sizeof *s);
    s->dp = dp;
    s->courant = courant;
    s->plane = SOLID_PLANE_STRESS;
    s->nbodies = 1;
    struct solid_body_def *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "block");
    b->x1 = nx * dp;
    b->y1 = ny * dp;
    b->rho = 1000.0;
    b->E = E;
    b->nu = nu;
}

/* 1: tests run the second-order correction (solid.tlsph.correction) */
static int tl_quadratic = 0;

static inline struct solid_tlsph *tl_make(const struct solid_scene *sc, double alpha, double hg)
{
    struct solid_tlsph *m = NULL;
    struct mps_err err = {0};
    if (solid_tlsph_create(&m, sc, alpha, hg, tl_quadratic, &err) != MPS_OK) {
        fprintf(stderr, "solid_tlsph_create: %s\n", err.msg);
        exit(2);
    }
    return m;
}

/* A reproducible number in [-1, 1]. */
static inline double tl_rand(unsigned long *state)
{
    *state = *state * 6364136223846793005UL + 1442695040888963407UL;
    return (double)(*state >> 11) / (double)(1UL << 53) * 2.0 - 1.0;
}

static inline double tl_energy(const struct solid_tlsph *m)
{
    struct solid_tlsph_diag d;
    solid_tlsph_diag(m, &d);
    return d.kinetic + d.elastic + d.hourglass + d.gravity;
}

#endif
