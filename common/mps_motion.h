/* The motion of the tank's frame, declared once in the case (the `motion:`
 * block) and evaluated here for every solver, so the fluid and the solid see
 * the same motion at their own (sub-)step times.
 *
 * Formulation (docs/sloshing.md): every solver works in the tank's frame, in
 * which the walls are fixed; the frame rolls by theta(t) (counterclockwise
 * positive, radians) about a pivot fixed in the lab. A particle at x with
 * velocity v (tank-frame coordinates) then feels, per unit mass,
 *   a = R(-theta) g - omega_dot z x r - omega z x (omega z x r) - 2 omega z x v,
 * r = x - pivot: the gravity of the lab seen from the tilted frame, and the
 * Euler, centrifugal and Coriolis terms. Kinds:
 *   none      the tank stands still: a = g (the solvers take their old path);
 *   constant  a fixed tilt theta = motion.angle;
 *   sinusoid  theta = amplitude sin(2 pi t / period), period a number or eq55
 *             (Eq. 55 from fluid.tank.width, the filling level and |g|);
 *   table     theta from a CSV of (time s, angle deg), fitted by a
 *             least-squares cubic B-spline (smooth enough for omega_dot).
 * Units SI, angles in radians except the case keys (degrees). */
#ifndef MPS_MOTION_H
#define MPS_MOTION_H

#include <stddef.h>

#include "mps_case.h"
#include "mps_dim.h"
#include "mps_err.h"
#include "mps_json.h"

enum mps_motion_kind {
    MPS_MOTION_NONE,
    MPS_MOTION_CONSTANT,
    MPS_MOTION_SINUSOID,
    MPS_MOTION_TABLE
};

struct mps_motion {
    enum mps_motion_kind kind;
    double g[MPS_DIM];        /* lab gravity (the case's gravity.x, .y), m/s^2 */
    double pivot[MPS_DIM];    /* the roll axis, tank frame, m */
    double angle;             /* constant: theta, rad */
    double amplitude, period; /* sinusoid: rad, s */
    int period_eq55;          /* the period came from Eq. 55 */
    /* table: theta(t) = sum_k coef[k] B((t - k0 h) / h) on [0, t_end], the
     * cubic B-splines on knots 0, h, 2h, ..., nspan h = t_end */
    double *coef;             /* nspan + 3 coefficients, rad */
    int nspan;
    double h, t_end;          /* knot spacing (s), end of the table (s) */
    size_t table_rows;
    double table_rms;         /* rms of fit minus table, rad */
    char table_file[1024];
};

/* The frame at one time: what the body force needs. */
struct mps_motion_frame {
    double t, theta, omega, omega_dot; /* s, rad, rad/s, rad/s^2 */
    double g[MPS_DIM];                 /* R(-theta) g: gravity in tank axes, m/s^2 */
    double pivot[MPS_DIM];
};

/* The motion.* keys (for mps_case_load, next to mps_case_common_keys). */
extern const struct mps_key_spec mps_motion_keys[];
#define MPS_MOTION_KEYS_TITLE "Every program: the tank's motion (`motion.*`)"

/* Reads and checks the motion block (a table file is read and fitted here).
 * *out is allocated for every kind, none included. Errors name the file, line
 * and key: a missing pivot or period, an unreadable or short table, a table
 * that ends before end_time, eq55 without a fluid tank. */
enum mps_status mps_motion_read(struct mps_motion **out, const struct mps_case *c,
                                struct mps_err *err);
void mps_motion_destroy(struct mps_motion **m);

/* 1 unless the kind is none (or m is NULL). */
int mps_motion_moving(const struct mps_motion *m);
const char *mps_motion_kind_name(enum mps_motion_kind k);

/* The frame at time t (s). */
struct mps_motion_frame mps_motion_at(const struct mps_motion *m, double t);

/* Eq. 55: the first sloshing mode's period of a tank of length L filled to
 * depth h under gravity g, s. */
double mps_motion_eq55(double L, double h, double g);

/* Kind, period, amplitude, pivot (and the table's fit) into an open JSON
 * object, so a run's summary says which motion it saw. */
void mps_motion_summary(const struct mps_motion *m, struct mps_json *j);

/* The body acceleration of a particle at x moving at v (tank frame), m/s^2. */
static inline void mps_motion_accel(const struct mps_motion_frame *f, const double x[MPS_DIM],
                                    const double v[MPS_DIM], double a[MPS_DIM])
{
    const double rx = x[0] - f->pivot[0], ry = x[1] - f->pivot[1];
    const double w = f->omega, wd = f->omega_dot, w2 = w * w;
    /* z x (p, q) = (-q, p): -wd z x r = (wd ry, -wd rx); the centrifugal
     * -w z x (w z x r) = w^2 r; Coriolis -2 w z x v = (2 w vy, -2 w vx) */
    a[0] = f->g[0] + wd * ry + w2 * rx + 2.0 * w * v[1];
    a[1] = f->g[1] - wd * rx + w2 * ry - 2.0 * w * v[0];
}

#endif
