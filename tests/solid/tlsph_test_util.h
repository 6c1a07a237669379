/* Scenes and helpers for the TLSPH solid tests, built by hand (no case file). */
#ifndef TLSPH_TEST_UTIL_H
#define TLSPH_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>

#include "solid_test_util.h" /* block_scene, test_rand */
#include "solid_tlsph.h"

/* block_scene: one rectangle body, nx by ny particles of spacing dp from the
 * origin, no gravity, no clamp, plane stress, rho = 1000. */
static inline void tl_block_scene(struct solid_scene *s, int nx, int ny, double dp, double E,
                                  double nu, double courant)
{
    block_scene(s, nx, ny, dp, E, nu, courant);
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
    return test_rand(state);
}

static inline double tl_energy(const struct solid_tlsph *m)
{
    struct solid_tlsph_diag d;
    solid_tlsph_diag(m, &d);
    return d.kinetic + d.elastic + d.hourglass + d.gravity;
}

#endif
