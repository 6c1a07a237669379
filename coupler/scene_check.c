#include "scene_check.h"

#include <math.h>
#include <stdio.h>

enum mps_status scene_check_fsi(const struct fluid_params *fp, const struct solid_scene *sc,
                                const struct mps_case *c, struct mps_err *err)
{
    /* dp/1000 absorbs decimal round-off in the file, as for water blocks */
    const double tol = 1e-3 * fp->dp;
    char key[64];
    for (int b = 0; b < sc->nbodies; b++) {
        const struct solid_body_def *d = &sc->bodies[b];
        /* an open tank may hold a body that stands above its walls */
        const char *side = d->x0 < -tol                            ? "x0"
                           : d->y0 < -tol                          ? "y0"
                           : d->x1 > fp->tank_w + tol              ? "x1"
                           : fp->tank_lid && d->y1 > fp->tank_h + tol ? "y1"
                                                                      : NULL;
        if (side) {
            snprintf(key, sizeof key, "solid.bodies.%d.%s", b, side);
            return mps_case_fail(c, err, key, "body '%s' lies outside the tank [0, %g] x [0, %g]",
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
