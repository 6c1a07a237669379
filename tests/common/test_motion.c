/* The tank frame's motion (common/mps_motion.c): Eq. 55's two periods, the
 * sinusoid's derivatives, the table's spline fit, every term of the frame's
 * body acceleration against a particle flying freely in the lab, the resolved
 * case's absolute table path, and the input errors. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../test_util.h"
#include "mps_case.h"
#include "mps_motion.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const struct mps_key_spec *const tables[] = {mps_case_common_keys, mps_motion_keys};
static const char *const ignore[] = {"fluid.", "solid.", NULL};

static char dir[64];

static const char *write_file(const char *name, const char *text)
{
    static char path[8][256];
    static int k = 0;
    char *p = path[k++ % 8];
    snprintf(p, sizeof path[0], "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    if (!f) {
        perror(p);
        exit(1);
    }
    fputs(text, f);
    fclose(f);
    return p;
}

/* Loads text as a case and reads its motion; returns the status, *m set on
 * success (the caller destroys it). */
static enum mps_status read_motion(const char *text, struct mps_motion **m, struct mps_err *err)
{
    struct mps_case *c = NULL;
    *m = NULL;
    enum mps_status st =
        mps_case_load(&c, write_file("case.yml", text), NULL, 0, tables, 2, ignore, err);
    if (!st)
        st = mps_motion_read(m, c, err);
    mps_case_destroy(&c);
    return st;
}

static void expect_error(const char *text, const char *frag1, const char *frag2)
{
    struct mps_motion *m = NULL;
    struct mps_err err = {0};
    enum mps_status st = read_motion(text, &m, &err);
    CHECK(st != MPS_OK && m == NULL);
    int ok = strstr(err.msg, frag1) && (!frag2 || strstr(err.msg, frag2));
    CHECK(ok);
    if (!ok)
        fprintf(stderr, "  message was: %s\n", err.msg);
    mps_motion_destroy(&m);
}

static void test_eq55(void)
{
    /* the paper's 1.646 s and 1.211 s (L = 0.609 m, H_L = 57.4 / 114.8 mm);
     * Eq. 55 gives 1.6466 and 1.2115: the paper truncates */
    CHECK_NEAR(mps_motion_eq55(0.609, 0.0574, 9.81), 1.646, 0.001);
    CHECK_NEAR(mps_motion_eq55(0.609, 0.1148, 9.81), 1.211, 0.001);
    /* deep water: T -> sqrt(2 pi L / (pi g)) ... = 2 pi / sqrt(pi g / L) */
    CHECK_NEAR(mps_motion_eq55(1.0, 100.0, 9.81), 2.0 * PI / sqrt(PI * 9.81), 1e-12);

    /* period: eq55 reads the fluid section (here as an ignored prefix, as the
     * solid sees it) */
    struct mps_motion *m;
    struct mps_err err = {0};
    const char *yml = "dp: 0.001\nend_time: 1\n"
                      "motion: {kind: sinusoid, amplitude: 4, period: eq55, pivot: {x: 0.3045, y: 0}}\n"
                      "fluid:\n  tank: {width: 0.609, height: 0.3445}\n"
                      "  blocks:\n    - {x0: 0, y0: 0, x1: 0.304, y1: 0.1148}\n"
                      "    - {x0: 0.308, y0: 0, x1: 0.609, y1: 0.1148}\n";
    CHECK(read_motion(yml, &m, &err) == MPS_OK);
    if (m) {
        CHECK(m->kind == MPS_MOTION_SINUSOID && m->period_eq55);
        CHECK_NEAR(m->period, mps_motion_eq55(0.609, 0.1148, 9.81), 1e-15);
        CHECK_NEAR(m->amplitude, 4.0 * DEG, 1e-15);
    }
    mps_motion_destroy(&m);
}

/* Central differences of theta and omega against the frame's omega and
 * omega_dot. */
static void check_derivatives(const struct mps_motion *m, double t0, double t1, double tol_w,
                              double tol_wd)
{
    const double h = 1e-5;
    double ew = 0.0, ewd = 0.0;
    for (double t = t0; t <= t1; t += 0.0137) {
        struct mps_motion_frame a = mps_motion_at(m, t - h), b = mps_motion_at(m, t + h),
                                f = mps_motion_at(m, t);
        ew = fmax(ew, fabs((b.theta - a.theta) / (2 * h) - f.omega));
        ewd = fmax(ewd, fabs((b.omega - a.omega) / (2 * h) - f.omega_dot));
    }
    CHECK(ew <= tol_w);
    CHECK(ewd <= tol_wd);
    if (ew > tol_w || ewd > tol_wd)
        fprintf(stderr, "  derivative errors %g rad/s, %g rad/s^2\n", ew, ewd);
}

static void test_sinusoid(void)
{
    struct mps_motion *m;
    struct mps_err err = {0};
    CHECK(read_motion("dp: 0.01\nend_time: 1\nmotion: {kind: sinusoid, amplitude: 4, period: 1.2, "
                      "pivot: {x: 0.3, y: 0}}\n",
                      &m, &err) == MPS_OK);
    if (!m)
        return;
    CHECK(!m->period_eq55 && m->period == 1.2);
    struct mps_motion_frame f = mps_motion_at(m, 0.3); /* a quarter period */
    CHECK_NEAR(f.theta, 4.0 * DEG, 1e-15);
    CHECK_NEAR(f.omega, 0.0, 1e-15);
    CHECK_NEAR(f.omega_dot, -4.0 * DEG * pow(2 * PI / 1.2, 2), 1e-13);
    /* gravity in the tank's axes: right end up (theta > 0), the water goes -x */
    CHECK_NEAR(f.g[0], -9.81 * sin(4.0 * DEG), 1e-14);
    CHECK_NEAR(f.g[1], -9.81 * cos(4.0 * DEG), 1e-14);
    check_derivatives(m, 0.0, 3.0, 1e-8, 1e-7);
    mps_motion_destroy(&m);
}

/* A table sampled from a smooth roll every 10 ms (the experiment's spacing),
 * with a 0.005 deg alternating error (the measured table's scatter): the
 * spline with knots every 0.05 s follows the roll to 0.01 deg and its
 * derivatives to the differences the scatter allows. */
static void test_table(void)
{
    char buf[65536];
    size_t len = (size_t)snprintf(buf, sizeof buf,
                                  "# a comment line\ntime_s,roll_deg\n");
    const double T = 1.2, A = 4.0;
    for (int k = 1; k <= 500; k++) {
        double t = 0.01 * k, ramp = 1.0 - exp(-t / 0.3);
        double y = A * ramp * sin(2 * PI * t / T) + (k % 2 ? 0.005 : -0.005);
        len += (size_t)snprintf(buf + len, sizeof buf - len, "%.6f, %.6f\n", t, y);
    }
    write_file("roll.csv", buf);
    struct mps_motion *m;
    struct mps_err err = {0};
    CHECK(read_motion("dp: 0.01\nend_time: 4.9\nmotion: {kind: table, pivot: {x: 0, y: 0},\n"
                      "  table: {file: roll.csv, scale: -1}}\n",
                      &m, &err) == MPS_OK);
    if (!m) {
        fprintf(stderr, "  %s\n", err.msg);
        return;
    }
    CHECK(m->table_rows == 500 && m->t_end == 5.0 && m->nspan == 100);
    double eth = 0.0, ew = 0.0, ewd = 0.0, wdmax = 0.0;
    for (double t = 0.5; t <= 4.9; t += 0.001) {
        double w = 2 * PI / T, tau = 0.3, r = 1.0 - exp(-t / tau), rp = exp(-t / tau) / tau,
               rpp = -exp(-t / tau) / (tau * tau);
        double th = -A * DEG * r * sin(w * t); /* scale -1 */
        double om = -A * DEG * (rp * sin(w * t) + r * w * cos(w * t));
        double al = -A * DEG * (rpp * sin(w * t) + 2 * rp * w * cos(w * t) - r * w * w * sin(w * t));
        struct mps_motion_frame f = mps_motion_at(m, t);
        eth = fmax(eth, fabs(f.theta - th));
        ew = fmax(ew, fabs(f.omega - om));
        ewd = fmax(ewd, fabs(f.omega_dot - al));
        wdmax = fmax(wdmax, fabs(al));
    }
    /* 0.01 deg; omega within 1% of its amplitude (0.36 rad/s); omega_dot
     * within 10% of its amplitude (1.9 rad/s^2): interpolating the rows
     * instead makes omega_dot swing by about 0.01 deg / (0.01 s)^2 = 2 rad/s^2 */
    CHECK(eth <= 0.01 * DEG);
    CHECK(ew <= 0.01 * 0.36);
    CHECK(ewd <= 0.1 * wdmax);
    if (eth > 0.01 * DEG || ew > 0.0036 || ewd > 0.1 * wdmax)
        fprintf(stderr, "  table fit errors %g deg, %g rad/s, %g rad/s^2 (amplitude %g)\n",
                eth / DEG, ew, ewd, wdmax);
    CHECK(m->table_rms / DEG < 0.01);
    check_derivatives(m, 0.02, 4.98, 1e-7, 1e-5);
    mps_motion_destroy(&m);
}

/* A particle flying freely in the lab (gravity only) seen from the rolling
 * tank: its tank-frame acceleration (second differences of its tank-frame
 * path) must be the frame's body acceleration at its tank-frame x and v. This
 * checks rotated gravity, Euler, centrifugal and Coriolis terms and their
 * signs at once. */
static void test_free_particle(void)
{
    struct mps_motion *m;
    struct mps_err err = {0};
    CHECK(read_motion("dp: 0.01\nend_time: 1\ngravity: {x: 0.3, y: -9.81}\n"
                      "motion: {kind: sinusoid, amplitude: 20, period: 0.7, "
                      "pivot: {x: 0.25, y: -0.1}}\n",
                      &m, &err) == MPS_OK);
    if (!m)
        return;
    const double X0[2] = {0.4, 0.3}, V0[2] = {-0.7, 1.1}, P[2] = {0.25, -0.1}, h = 1e-4;
    double emax = 0.0, amax = 0.0;
    for (double t = 0.05; t < 1.0; t += 0.0731) {
        double x[3][2];
        for (int s = 0; s < 3; s++) {
            double ts = t + (s - 1) * h;
            double X[2] = {X0[0] + V0[0] * ts + 0.5 * 0.3 * ts * ts,
                           X0[1] + V0[1] * ts - 0.5 * 9.81 * ts * ts};
            double th = mps_motion_at(m, ts).theta, c = cos(th), sn = sin(th);
            double r[2] = {X[0] - P[0], X[1] - P[1]};
            /* tank frame: x = P + R(-theta) (X - P) */
            x[s][0] = P[0] + c * r[0] + sn * r[1];
            x[s][1] = P[1] - sn * r[0] + c * r[1];
        }
        double v[2], a[2], want[2];
        for (int d = 0; d < 2; d++) {
            v[d] = (x[2][d] - x[0][d]) / (2 * h);
            a[d] = (x[2][d] - 2 * x[1][d] + x[0][d]) / (h * h);
        }
        struct mps_motion_frame f = mps_motion_at(m, t);
        mps_motion_accel(&f, x[1], v, want);
        for (int d = 0; d < 2; d++) {
            emax = fmax(emax, fabs(a[d] - want[d]));
            amax = fmax(amax, fabs(want[d]));
        }
    }
    /* second differences at h = 1e-4 s: round-off about 1e-16 / 1e-8 */
    CHECK(emax < 1e-5 * amax);
    if (emax >= 1e-5 * amax)
        fprintf(stderr, "  free particle: tank-frame acceleration off by %g m/s^2 (of %g)\n",
                emax, amax);

    /* kind none: the lab's gravity, nothing else */
    struct mps_motion *n;
    CHECK(read_motion("dp: 0.01\nend_time: 1\n", &n, &err) == MPS_OK);
    if (n) {
        CHECK(!mps_motion_moving(n));
        struct mps_motion_frame f = mps_motion_at(n, 0.3);
        double x[2] = {1, 2}, v[2] = {3, 4}, acc[2];
        mps_motion_accel(&f, x, v, acc);
        CHECK(acc[0] == 0.0 && acc[1] == -9.81);
    }
    mps_motion_destroy(&n);
    mps_motion_destroy(&m);
}

static void test_constant_and_path(void)
{
    struct mps_motion *m;
    struct mps_err err = {0};
    CHECK(read_motion("dp: 0.01\nend_time: 1\nmotion: {kind: constant, angle: -30, "
                      "pivot: {x: 0, y: 0}}\n",
                      &m, &err) == MPS_OK);
    if (m) {
        struct mps_motion_frame f = mps_motion_at(m, 7.0);
        CHECK(f.omega == 0.0 && f.omega_dot == 0.0);
        CHECK_NEAR(f.g[0], 9.81 * 0.5, 1e-14); /* right end down: the water goes +x */
    }
    mps_motion_destroy(&m);

    /* the table's path is relative to the case; the resolved YAML (read by
     * the solvers from the coupler's OUT) holds it absolute */
    struct mps_case *c = NULL;
    const char *path = write_file("case.yml", "dp: 0.01\nend_time: 1\nmotion: {kind: table, "
                                              "pivot: {x: 0, y: 0}, table: {file: roll.csv}}\n");
    CHECK(mps_case_load(&c, path, NULL, 0, tables, 2, ignore, &err) == MPS_OK);
    char *y = c ? mps_case_resolved_yaml(c) : NULL;
    char want[300];
    snprintf(want, sizeof want, "file: %s/roll.csv", dir);
    CHECK(y && strstr(y, want));
    if (y && !strstr(y, want))
        fprintf(stderr, "  resolved YAML lacks '%s':\n%s\n", want, y);
    free(y);
    mps_case_destroy(&c);
}

static void test_errors(void)
{
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: sinusoid, amplitude: 4, period: 1}\n",
                 "motion.kind = sinusoid", "needs motion.pivot");
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: sinusoid, pivot: {x: 0, y: 0}}\n",
                 "motion.kind = sinusoid", "needs motion.period");
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: sinusoid, period: -1, pivot: {x: 0, y: 0}}\n",
                 "motion.period = -1", "time > 0");
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: sinusoid, period: eq55, pivot: {x: 0, y: 0}}\n",
                 "eq55 needs fluid.tank.width", NULL);
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: table, pivot: {x: 0, y: 0}}\n",
                 "needs motion.table.file", NULL);
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: no_such.csv}}\n",
                 "motion.table.file", "cannot open");
    write_file("bad.csv", "t,deg\n0.1, 1\n0.2, 2\n0.3 x\n0.4, 4\n");
    expect_error("dp: 0.01\nend_time: 0.3\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: bad.csv}}\n",
                 "bad.csv:4:", "two numbers");
    write_file("back.csv", "0.1, 1\n0.2, 2\n0.15, 3\n0.4, 4\n");
    expect_error("dp: 0.01\nend_time: 0.3\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: back.csv}}\n",
                 "back.csv:3:", "increasing");
    /* roll.csv (test_table) ends at 5 s */
    expect_error("dp: 0.01\nend_time: 10\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: roll.csv}}\n",
                 "ends at t = 5 s, before end_time = 10 s", NULL);
    /* rows only in [0, 0.19] and [1, 1.19]: the knots between have none */
    char gap[2048];
    size_t gl = 0;
    for (int k = 0; k < 40; k++)
        gl += (size_t)snprintf(gap + gl, sizeof gap - gl, "%g, %g\n", (k < 20 ? 0.0 : 1.0) +
                               0.01 * (k % 20), (double)(k / 20));
    write_file("gap.csv", gap);
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: gap.csv}}\n",
                 "too few rows between", "knot_spacing");
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: gap.csv, knot_spacing: 0.001}}\n",
                 "knot spans over 1.19 s for 40 rows", NULL);
    expect_error("dp: 0.01\nend_time: 1\nmotion: {kind: table, pivot: {x: 0, y: 0}, "
                 "table: {file: /dev/null}}\n",
                 "/dev/null: not a regular file", NULL);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/test_motion_XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_eq55();
    test_sinusoid();
    test_table();
    test_free_particle();
    test_constant_and_path();
    test_errors();
    const char *files[] = {"case.yml", "roll.csv", "bad.csv", "back.csv", "gap.csv"};
    for (int k = 0; k < 5; k++) {
        char p[300];
        snprintf(p, sizeof p, "%s/%s", dir, files[k]);
        unlink(p);
    }
    rmdir(dir);
    return test_summary("test_motion");
}
