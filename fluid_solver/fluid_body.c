/* The body force on the fluid's particles: gravity in a fixed tank, the
 * moving frame's (mps_motion.h: rotated gravity, Euler, centrifugal and
 * Coriolis terms) in a rolling one. One field, f->acc, read by the
 * prediction (Eq. 16-17), the Neumann walls' ghost kick and pressure
 * extrapolation (fluid_ppe.c) and the initial hydrostatic pressure. */
#include "fluid.h"

void fluid_body_accel(struct fluid *f, double t)
{
    const size_t n = f->ps.n;
    double(*acc)[MPS_DIM] = f->acc;
    const struct mps_motion *m = f->prm.motion;
    if (!mps_motion_moving(m)) {
        const double *g = f->prm.g;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++)
            for (int d = 0; d < MPS_DIM; d++)
                acc[i][d] = g[d];
        return;
    }
    /* Tank particles sit still in the frame (v = 0); fluid and solid
     * particles feel the Coriolis term of their velocity relative to it. */
    const struct mps_motion_frame fr = mps_motion_at(m, t);
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    const double(*v)[MPS_DIM] = (const double(*)[MPS_DIM])f->v;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        mps_motion_accel(&fr, x[i], v[i], acc[i]);
}
