/* The registry of solid models compiled in (the "none"-style choice of the
 * house style: a scene picks one by name, --model or solid.model). */
#include "solid_model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mps_timer.h"
#include "solid_mps.h"
#include "solid_refine.h"
#include "solid_tlsph.h"

static const struct solid_model_ops *const models[] = {&solid_mps_ops, &solid_tlsph_ops, NULL};

const struct solid_model_ops *solid_model_find(const char *name)
{
    for (int k = 0; name && models[k]; k++)
        if (strcmp(models[k]->name, name) == 0)
            return models[k];
    return NULL;
}

const char *solid_model_names(void)
{
    static char names[256];
    if (!names[0])
        for (int k = 0; models[k]; k++)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? ", " : "",
                     models[k]->name);
    return names;
}

enum mps_status solid_model_snapshot(const struct solid_model_ops *ops, void *model,
                                     struct mps_h5_series *h5, double t, long step,
                                     double *seconds, struct mps_err *err)
{
    double w0 = mps_wall_seconds();
    const double(*x)[MPS_DIM] = NULL;
    struct mps_field f[MPS_PARTICLES_MAX_FIELDS];
    int nf = 0;
    size_t n = ops->snapshot(model, &x, f, MPS_PARTICLES_MAX_FIELDS, &nf);
    enum mps_status st = mps_h5_write(h5, t, step, n, x, f, nf, err);
    *seconds += mps_wall_seconds() - w0;
    return st;
}

enum mps_status solid_model_open(const struct solid_model_ops **ops, void **self,
                                 const struct mps_case *c, struct mps_err *err)
{
    enum mps_status st = (*ops)->create(self, c, err);
    if (st == MPS_OK && mps_case_int(c, "solid.refine") > 1)
        st = solid_refine_wrap(ops, self, c, err);
    return st;
}

enum mps_status solid_model_check_step(const struct solid_model_ops *ops, const void *self,
                                       const struct mps_case *c, struct mps_err *err)
{
    /* An absurd material (rho = 1e-300 kg/m^3 underflows the rotation's
     * inertia to a zero step; E = 1e300 Pa asks 1e149 steps) is refused here,
     * where the case is still at hand: before, the standalone loop's step
     * count overflowed and the run "finished" at once with exit 0, and a
     * coupled one failed as a protocol error on READY's dt = 0. */
    const double dt = ops->stable_dt(self), end = mps_case_double(c, "end_time");
    if (dt > 0.0 && end / dt <= SOLID_MAX_STEPS)
        return MPS_OK;
    /* named at the stiffest body for its mass, whose wave sets the step */
    int worst = 0;
    double most = -1.0;
    for (int b = 0; b < mps_case_count(c, "solid.bodies"); b++) {
        double ratio = mps_case_double(c, "solid.bodies.%d.E", b) /
                       mps_case_double(c, "solid.bodies.%d.rho", b);
        if (!(ratio <= most)) {
            most = ratio;
            worst = b;
        }
    }
    char key[48];
    snprintf(key, sizeof key, "solid.bodies.%d.E", worst);
    return mps_case_fail(c, err, key,
                         "with rho = %g kg/m^3 and dp = %g m the solid's stable step is %.3g s, "
                         "%.3g steps to end_time = %g s (more than %.0e): check the body's E "
                         "and rho",
                         mps_case_double(c, "solid.bodies.%d.rho", worst),
                         mps_case_double(c, "dp"), dt, dt > 0.0 ? ceil(end / dt) : INFINITY, end,
                         SOLID_MAX_STEPS);
}
