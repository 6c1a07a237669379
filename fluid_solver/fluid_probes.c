/* Probes, snapshot fields and the run summary of the fluid. */
#include <math.h>
#include <string.h>

#include "fluid.h"

static double probe_front(const struct fluid *f)
{
    /* leading edge of the water on the floor: the particles of the two
     * lowest layers, plus half a spacing (a particle stands for a cell) */
    double xmax = -INFINITY;
    for (size_t i = 0; i < f->nfluid; i++)
        if (f->x[i][1] < 2.0 * f->prm.dp && f->x[i][0] > xmax)
            xmax = f->x[i][0];
    return isfinite(xmax) ? xmax + 0.5 * f->prm.dp : 0.0;
}

static double probe_height(const struct fluid *f, double x0)
{
    /* the highest particle of the column [x0, x0 + dp), plus half a spacing */
    double ymax = -INFINITY;
    for (size_t i = 0; i < f->nfluid; i++)
        if (f->x[i][0] >= x0 && f->x[i][0] < x0 + f->prm.dp && f->x[i][1] > ymax)
            ymax = f->x[i][1];
    return isfinite(ymax) ? ymax + 0.5 * f->prm.dp : 0.0;
}

static double probe_bottom(const struct fluid *f)
{
    /* mean over floor wall particles that have water above them (not free
     * surface) of their pressure carried hydrostatically from the particle
     * centre (dp/2 below the floor) up to the floor, y = 0: the pressure on
     * the bottom of the tank (acc: the body force of the last step) */
    double s = 0.0;
    int m = 0;
    for (size_t i = f->nfluid; i < f->nfixed_end; i++)
        if (f->type[i] == WALL_P && f->x[i][1] < 0.0 && f->x[i][0] > 0.0 &&
            f->x[i][0] < f->prm.tank_w && !f->surface[i]) {
            s += f->p[i] + f->prm.rho * f->acc[i][1] * (0.0 - f->x[i][1]);
            m++;
        }
    return m ? s / m : 0.0;
}

static double probe_tank_angle(const struct fluid *f)
{
    const double deg = 180.0 / 3.14159265358979323846;
    return mps_motion_moving(f->prm.motion) ? mps_motion_at(f->prm.motion, f->time).theta * deg
                                            : 0.0;
}

static double probe_max_speed(const struct fluid *f)
{
    double v2 = 0.0;
    for (size_t i = 0; i < f->nfluid; i++) {
        double s = f->v[i][0] * f->v[i][0] + f->v[i][1] * f->v[i][1];
        if (s > v2)
            v2 = s;
    }
    return sqrt(v2);
}

static double probe_escaped(const struct fluid *f)
{
    int m = 0;
    for (size_t i = 0; i < f->nfluid; i++)
        if (f->x[i][0] < 0.0 || f->x[i][0] > f->prm.tank_w || f->x[i][1] < 0.0 ||
            (f->prm.tank_lid && f->x[i][1] > f->prm.tank_h))
            m++;
    return m;
}

double fluid_probe(const struct fluid *f, int k)
{
    const struct fluid_probe_def *d = &f->prm.probes[k];
    switch (d->kind) {
    case FLUID_PROBE_FRONT: return probe_front(f);
    case FLUID_PROBE_HEIGHT: return probe_height(f, d->x);
    case FLUID_PROBE_PRESSURE:
    case FLUID_PROBE_WALL_FORCE:
    case FLUID_PROBE_WALL_MOMENT: return fluid_sensors_value(f, k);
    case FLUID_PROBE_BOTTOM: return probe_bottom(f);
    case FLUID_PROBE_MAX_SPEED: return probe_max_speed(f);
    case FLUID_PROBE_ESCAPED: return probe_escaped(f);
    case FLUID_PROBE_TANK_ANGLE: return probe_tank_angle(f);
    }
    return NAN;
}

void fluid_probes_restart(const struct fluid *f)
{
    fluid_sensors_restart(f);
}

int fluid_output_fields(const struct fluid *f, struct mps_field *out, int max)
{
    return mps_particles_output(&f->ps, out, max);
}

void fluid_summary(const struct fluid *f, struct mps_json *j)
{
    size_t nwall = 0, ndummy = 0;
    for (size_t i = f->nfluid; i < f->nfixed_end; i++)
        f->type[i] == WALL_P ? nwall++ : ndummy++;
    mps_json_object(j, "particles");
    mps_json_int(j, "fluid", (long long)f->nfluid);
    mps_json_int(j, "wall", (long long)nwall);
    mps_json_int(j, "dummy", (long long)ndummy);
    mps_json_int(j, "solid", (long long)(f->ps.n - f->nfixed_end));
    mps_json_int(j, "total", (long long)f->ps.n);
    mps_json_close(j);
    /* steps counts from the run's start; the counters and times, and so
     * the per-step figures, are this process's (a restart's: steps_run) */
    const long run = f->step - f->step_start;
    mps_json_int(j, "steps", f->step);
    mps_json_int(j, "steps_run", run);
    mps_json_num(j, "simulated_time", f->time);
    mps_json_int(j, "ppe_iterations", f->ppe_iterations);
    mps_json_num(j, "ppe_iterations_per_step", run > 0 ? (double)f->ppe_iterations / run : 0);
    mps_json_int(j, "neighbour_builds", f->nbr_rebuilds);
    mps_json_int(j, "lost_particles", f->lost);
    mps_json_int(j, "wall_guard_uses", f->wall_guard);
    /* where the guard was used, and its first use: a leak shows where it is */
    static const char *const face[4] = {"floor", "left", "right", "lid"};
    mps_json_object(j, "wall_guard_faces");
    for (int k = 0; k < 4; k++)
        mps_json_int(j, face[k], f->wall_guard_face[k]);
    mps_json_close(j);
    if (f->wall_guard > 0) {
        mps_json_object(j, "wall_guard_first");
        mps_json_num(j, "time", f->wall_guard_first[0]);
        mps_json_str(j, "face", face[f->wall_guard_first_face]);
        mps_json_num(j, "x", f->wall_guard_first[1]);
        mps_json_num(j, "y", f->wall_guard_first[2]);
        mps_json_close(j);
    }
    if (f->side_wall_rate > 0.0) {
        mps_json_num(j, "side_wall_rate", f->side_wall_rate);
        mps_json_num(j, "side_wall_inertia", f->side_wall_inertia);
    }
    mps_json_str(j, "ppe_solver", fluid_linsolve_method(f->ls));
    double total = mps_timer_total(&f->timer);
    mps_json_num(j, "step_seconds", total);
    mps_json_num(j, "ns_per_particle_step",
                 run > 0 ? 1e9 * total / ((double)run * (double)f->ps.n) : 0.0);
    fluid_sensors_summary(f, j);
    mps_json_object(j, "phase_seconds");
    for (int k = 0; k < f->timer.nphases; k++)
        mps_json_num(j, f->timer.names[k], f->timer.seconds[k]);
    mps_json_close(j);
}
