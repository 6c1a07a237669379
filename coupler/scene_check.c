#include "scene_check.h"

#include <math.h>
#include <stdio.h>

/* 1 if a clamp of body b covers the box [x0, x1] x [y0, y1] (within tol). */
static int clamped(const struct solid_scene *sc, int b, double x0, double y0, double x1,
                   double y1, double tol)
{
    for (int k = 0; k < sc->nclamps; k++) {
        const struct solid_clamp_def *q = &sc->clamps[k];
        if (q->body == b && q->x0 <= x0 + tol && q->y0 <= y0 + tol && q->x1 >= x1 - tol &&
            q->y1 >= y1 - tol)
            return 1;
    }
    return 0;
}

enum mps_status scene_check_fsi(const struct fluid_params *fp, const struct solid_scene *sc,
                                const struct mps_case *c, struct mps_err *err)
{
    /* dp/1000 absorbs decimal round-off in the file, as for water blocks */
    const double tol = 1e-3 * fp->dp;
    const double W = fp->tank_w, H = fp->tank_h;
    char key[64];
    for (int b = 0; b < sc->nbodies; b++) {
        const struct solid_body_def *d = &sc->bodies[b];
        /* Outside the tank only a clamped part: it takes the place of the
         * walls there (a plate clamped in the floor, fluid_coupling.c). An
         * open tank may hold a body that stands above its walls. */
        const char *side =
            d->x0 < -tol && !clamped(sc, b, d->x0, d->y0, 0.0, d->y1, tol)       ? "x0"
            : d->y0 < -tol && !clamped(sc, b, d->x0, d->y0, d->x1, 0.0, tol)     ? "y0"
            : d->x1 > W + tol && !clamped(sc, b, W, d->y0, d->x1, d->y1, tol)    ? "x1"
            : fp->tank_lid && d->y1 > H + tol && !clamped(sc, b, d->x0, H, d->x1, d->y1, tol)
                ? "y1"
                : NULL;
        if (side) {
            snprintf(key, sizeof key, "solid.bodies.%d.%s", b, side);
            return mps_case_fail(c, err, key, "body '%s' lies outside the tank [0, %g] x [0, %g] "
                                 "(only a clamped part may stand in the walls' place)",
                                 d->name, fp->tank_w, fp->tank_h);
        }
        for (int k = 0; k < fp->nblocks; k++) {
            const double *w = fp->block[k];
            if (fmin(d->x1, w[2]) - fmax(d->x0, w[0]) > tol &&
                fmin(d->y1, w[3]) - fmax(d->y0, w[1]) > tol) {
                snprintf(key, sizeof key, "solid.bodies.%d.x0", b);
                return mps_case_fail(c, err, key, "body '%s' overlaps the water block "
                                     "fluid.blocks.%d ([%g, %g] x [%g, %g])",
                                     d->name, k, w[0], w[2], w[1], w[3]);
            }
        }
    }
    return MPS_OK;
}
