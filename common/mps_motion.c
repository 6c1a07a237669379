/* The tank frame's motion (see mps_motion.h). */
#include "mps_motion.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI 3.14159265358979323846 /* M_PI is not POSIX */
#define DEG (PI / 180.0)
#define ANY (MPS_KEY_NO_LO | MPS_KEY_NO_HI)

const struct mps_key_spec mps_motion_keys[] = {
    {"motion.kind", MPS_KEY_ENUM, "none", 0, 0, 0, "none|constant|sinusoid|table", "",
     "motion of the tank: none, a constant tilt, theta = amplitude sin(2 pi t / period), or "
     "a table of angles (docs/sloshing.md)"},
    {"motion.angle", MPS_KEY_DOUBLE, "0", -90, 90, 0, NULL, "deg",
     "constant: the tank's tilt, counterclockwise"},
    {"motion.amplitude", MPS_KEY_DOUBLE, "0", -90, 90, 0, NULL, "deg",
     "sinusoid: amplitude of theta (counterclockwise positive)"},
    {"motion.period", MPS_KEY_STRING, NULL, 0, 0, 0, NULL, "s",
     "sinusoid: period in s, or eq55 for Eq. 55 with L = fluid.tank.width, H_L = the top "
     "of the highest fluid block and |gravity|"},
    {"motion.pivot.x", MPS_KEY_DOUBLE, NULL, 0, 0, ANY, NULL, "m",
     "roll axis, x in the tank frame (fixed in the lab)"},
    {"motion.pivot.y", MPS_KEY_DOUBLE, NULL, 0, 0, ANY, NULL, "m", "roll axis, y"},
    {"motion.table.file", MPS_KEY_STRING, NULL, 0, 0, MPS_KEY_PATH, NULL, "",
     "table: CSV of time (s), angle (deg) rows, '#' comments and one header line allowed; "
     "relative to the case file"},
    {"motion.table.scale", MPS_KEY_DOUBLE, "1", 0, 0, ANY, NULL, "",
     "table: factor on the angles (-1 for a table whose positive angle is clockwise)"},
    {"motion.table.knot_spacing", MPS_KEY_DOUBLE, "0.05", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI,
     NULL, "s",
     "table: knot spacing of the least-squares cubic spline through the angles (smoothing: "
     "omega_dot is the second derivative of measured data)"},
    {.name = NULL},
};

static const char *const kind_names[] = {"none", "constant", "sinusoid", "table"};

const char *mps_motion_kind_name(enum mps_motion_kind k)
{
    return k <= MPS_MOTION_TABLE ? kind_names[k] : "?";
}

int mps_motion_moving(const struct mps_motion *m)
{
    return m && m->kind != MPS_MOTION_NONE;
}

double mps_motion_eq55(double L, double h, double g)
{
    /* Eq. 55: T = 2 pi (pi g / L tanh(pi H_L / L))^(-1/2) */
    return 2.0 * PI / sqrt(PI * g / L * tanh(PI * h / L));
}

/* ---- cubic B-spline on uniform knots ---- */

/* The four basis functions that are nonzero on a span, at u in [0, 1), and
 * their first and second derivatives in u. */
static void bspline(double u, double b[4], double d1[4], double d2[4])
{
    const double v = 1.0 - u, u2 = u * u, u3 = u2 * u;
    b[0] = v * v * v / 6.0;
    b[1] = (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0;
    b[2] = (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0;
    b[3] = u3 / 6.0;
    d1[0] = -0.5 * v * v;
    d1[1] = 1.5 * u2 - 2.0 * u;
    d1[2] = -1.5 * u2 + u + 0.5;
    d1[3] = 0.5 * u2;
    d2[0] = v;
    d2[1] = 3.0 * u - 2.0;
    d2[2] = -3.0 * u + 1.0;
    d2[3] = u;
}

/* Span and local parameter of t; outside [0, t_end] the end spans' cubics
 * continue (the reader checks that end_time lies inside). */
static int span_of(const struct mps_motion *m, double t, double *u)
{
    double s = t / m->h;
    int k = (int)floor(s);
    if (k < 0)
        k = 0;
    if (k > m->nspan - 1)
        k = m->nspan - 1;
    *u = s - k;
    return k;
}

/* Least-squares fit of the coefficients to (t, y): the normal equations are
 * banded (a row touches four coefficients), solved by a banded Cholesky. */
static enum mps_status fit_table(struct mps_motion *m, const double *t, const double *y,
                                 size_t n, const char *where, struct mps_err *err)
{
    const int N = m->nspan + 3;
    double(*band)[4] = calloc((size_t)N, sizeof *band); /* band[i][j] = A(i, i + j) */
    double *rhs = calloc((size_t)N, sizeof *rhs);
    m->coef = calloc((size_t)N, sizeof *m->coef);
    if (!band || !rhs || !m->coef) {
        free(band);
        free(rhs);
        return mps_err_set(err, MPS_ENOMEM, "motion: out of memory fitting the table");
    }
    for (size_t r = 0; r < n; r++) {
        double u, b[4], d1[4], d2[4];
        int k = span_of(m, t[r], &u);
        bspline(u, b, d1, d2);
        for (int a = 0; a < 4; a++) {
            rhs[k + a] += b[a] * y[r];
            for (int c = a; c < 4; c++)
                band[k + a][c - a] += b[a] * b[c];
        }
    }
    double dmax = 0.0;
    for (int i = 0; i < N; i++)
        dmax = band[i][0] > dmax ? band[i][0] : dmax;
    /* banded Cholesky, L stored over the band: band[i][j] = L(i + j, i) */
    enum mps_status st = MPS_OK;
    for (int i = 0; i < N && !st; i++) {
        double d = band[i][0];
        for (int k = i - 3 > 0 ? i - 3 : 0; k < i; k++)
            d -= band[k][i - k] * band[k][i - k];
        if (!(d > 1e-12 * dmax)) {
            /* coefficient i shapes only the spans i-3 .. i */
            int s0 = i - 3 > 0 ? i - 3 : 0, s1 = i < m->nspan - 1 ? i : m->nspan - 1;
            st = mps_err_set(err, MPS_EINPUT,
                             "%s: too few rows between t = %g and %g s for the spline's knots "
                             "every %g s (raise motion.table.knot_spacing)",
                             where, s0 * m->h, (s1 + 1) * m->h, m->h);
            break;
        }
        band[i][0] = sqrt(d);
        for (int j = 1; j < 4 && i + j < N; j++) {
            double s = band[i][j];
            for (int k = i + j - 3 > 0 ? i + j - 3 : 0; k < i; k++)
                s -= band[k][i - k] * band[k][i + j - k];
            band[i][j] = s / band[i][0];
        }
    }
    if (!st) {
        for (int i = 0; i < N; i++) { /* L z = rhs */
            double s = rhs[i];
            for (int k = i - 3 > 0 ? i - 3 : 0; k < i; k++)
                s -= band[k][i - k] * m->coef[k];
            m->coef[i] = s / band[i][0];
        }
        for (int i = N - 1; i >= 0; i--) { /* L^T c = z */
            double s = m->coef[i];
            for (int j = 1; j < 4 && i + j < N; j++)
                s -= band[i][j] * m->coef[i + j];
            m->coef[i] = s / band[i][0];
        }
        double ss = 0.0;
        for (size_t r = 0; r < n; r++) {
            double e = mps_motion_at(m, t[r]).theta - y[r];
            ss += e * e;
        }
        m->table_rms = sqrt(ss / (double)n);
    }
    free(band);
    free(rhs);
    return st;
}

/* Reads "t, angle" rows (comma, space or tab separated; '#' comments and
 * blank lines skipped, one header line allowed before the first row). */
static enum mps_status read_table(struct mps_motion *m, const char *path, double scale,
                                  double **tp, double **yp, size_t *np, struct mps_err *err)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return mps_err_set(err, MPS_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(fp), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        fclose(fp); /* a device or a pipe could feed lines for ever */
        return mps_err_set(err, MPS_EINPUT, "%s: not a regular file", path);
    }
    size_t n = 0, cap = 0;
    double *t = NULL, *y = NULL;
    char line[1024];
    long ln = 0;
    int header_seen = 0;
    enum mps_status st = MPS_OK;
    while (!st && fgets(line, sizeof line, fp)) {
        ln++;
        char *s = line;
        while (*s == ' ' || *s == '\t')
            s++;
        if (*s == '#' || *s == '\n' || *s == '\r' || *s == '\0')
            continue;
        char *end;
        double a = strtod(s, &end), b;
        if (end == s) {
            if (n == 0 && !header_seen) { /* a header line */
                header_seen = 1;
                continue;
            }
            st = mps_err_set(err, MPS_EINPUT, "%s:%ld: expected 'time, angle', got '%.40s'",
                             path, ln, s);
            break;
        }
        s = end;
        while (*s == ' ' || *s == '\t' || *s == ',')
            s++;
        b = strtod(s, &end);
        while (end != s && (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n'))
            end++;
        if (end == s || (*end != '\0' && *end != '#')) {
            st = mps_err_set(err, MPS_EINPUT, "%s:%ld: expected 'time, angle' (two numbers)",
                             path, ln);
            break;
        }
        if (!isfinite(a) || !isfinite(b) || a < 0.0 || (n > 0 && a <= t[n - 1])) {
            st = mps_err_set(err, MPS_EINPUT,
                             "%s:%ld: time %g s: times must be finite, >= 0 and increasing",
                             path, ln, a);
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            double *t2 = realloc(t, cap * sizeof *t), *y2 = t2 ? realloc(y, cap * sizeof *y) : NULL;
            if (t2)
                t = t2;
            if (y2)
                y = y2;
            if (!t2 || !y2) {
                st = mps_err_set(err, MPS_ENOMEM, "motion: out of memory reading %s", path);
                break;
            }
        }
        t[n] = a;
        y[n] = scale * b * DEG;
        n++;
    }
    if (!st && ferror(fp))
        st = mps_err_set(err, MPS_EIO, "%s: read error", path);
    fclose(fp);
    if (!st && n < 4)
        st = mps_err_set(err, MPS_EINPUT, "%s: %zu rows: a table needs at least 4", path, n);
    if (st) {
        free(t);
        free(y);
        return st;
    }
    m->table_rows = n;
    *tp = t;
    *yp = y;
    *np = n;
    return MPS_OK;
}

static enum mps_status read_number(const struct mps_case *c, const char *key, double *out,
                                   struct mps_err *err)
{
    const char *s = mps_case_text(c, "%s", key);
    char *end;
    if (!s)
        return mps_case_fail(c, err, "motion.period", "eq55 needs %s", key);
    *out = strtod(s, &end);
    if (end == s || *end || !isfinite(*out))
        return mps_case_fail(c, err, key, "must be a number (motion.period = eq55 reads it)");
    return MPS_OK;
}

/* Eq. 55 from the fluid section: L = the tank's inner width, H_L = the top
 * of the highest block (the floor is at y = 0), g = |gravity|. */
static enum mps_status period_eq55(struct mps_motion *m, const struct mps_case *c,
                                   struct mps_err *err)
{
    double L = 0.0, top = 0.0;
    enum mps_status st = read_number(c, "fluid.tank.width", &L, err);
    int nb = mps_case_count(c, "fluid.blocks");
    if (!st && nb == 0)
        return mps_case_fail(c, err, "motion.period", "eq55 needs fluid.blocks (the filling)");
    for (int b = 0; b < nb && !st; b++) {
        char key[64];
        double y1 = 0.0;
        snprintf(key, sizeof key, "fluid.blocks.%d.y1", b);
        if (!(st = read_number(c, key, &y1, err)) && y1 > top)
            top = y1;
    }
    if (st)
        return st;
    double g = hypot(m->g[0], m->g[1]);
    if (!(L > 0.0 && top > 0.0 && g > 0.0))
        return mps_case_fail(c, err, "motion.period",
                             "eq55 needs a tank width, a filling and gravity > 0 (L = %g m, "
                             "H_L = %g m, g = %g m/s^2)",
                             L, top, g);
    m->period = mps_motion_eq55(L, top, g);
    m->period_eq55 = 1;
    return MPS_OK;
}

static enum mps_status read_sinusoid(struct mps_motion *m, const struct mps_case *c,
                                     struct mps_err *err)
{
    m->amplitude = mps_case_double(c, "motion.amplitude") * DEG;
    if (!mps_case_has(c, "motion.period"))
        return mps_case_fail(c, err, "motion.kind", "needs motion.period (s, or eq55)");
    const char *s = mps_case_string(c, "motion.period");
    if (strcmp(s, "eq55") == 0)
        return period_eq55(m, c, err);
    char *end;
    m->period = strtod(s, &end);
    if (end == s || *end || !isfinite(m->period) || !(m->period > 0.0))
        return mps_case_fail(c, err, "motion.period", "must be a time > 0 (s) or eq55");
    return MPS_OK;
}

static enum mps_status read_table_kind(struct mps_motion *m, const struct mps_case *c,
                                       struct mps_err *err)
{
    if (!mps_case_has(c, "motion.table.file"))
        return mps_case_fail(c, err, "motion.kind", "needs motion.table.file");
    const char *file = mps_case_string(c, "motion.table.file");
    if (file[0] == '/')
        snprintf(m->table_file, sizeof m->table_file, "%s", file);
    else
        snprintf(m->table_file, sizeof m->table_file, "%s/%s", mps_case_dir(c), file);
    double *t = NULL, *y = NULL;
    size_t n = 0;
    enum mps_status st = read_table(m, m->table_file, mps_case_double(c, "motion.table.scale"),
                                    &t, &y, &n, err);
    if (st)
        return mps_err_prefix(err, "%s: motion.table.file: ", mps_case_where(c, "motion.table.file"));
    const double end_time = mps_case_double(c, "end_time");
    m->t_end = t[n - 1];
    if (m->t_end < end_time * (1.0 - 1e-9)) {
        free(t);
        free(y);
        return mps_case_fail(c, err, "motion.table.file",
                             "the table ends at t = %g s, before end_time = %g s", m->t_end,
                             end_time);
    }
    /* whole spans from 0 to the last row: an end span with one or two rows
     * would leave its coefficients to the noise */
    const double want = mps_case_double(c, "motion.table.knot_spacing");
    const double spans = fmax(1.0, floor(m->t_end / want + 0.5));
    if (spans > (double)n) { /* more coefficients than rows: nothing to fit them to */
        free(t);
        free(y);
        return mps_case_fail(c, err, "motion.table.knot_spacing",
                             "%.0f knot spans over %g s for %zu rows: at most one span per row",
                             spans, m->t_end, n);
    }
    m->nspan = (int)spans;
    m->h = m->t_end / m->nspan;
    st = fit_table(m, t, y, n, m->table_file, err);
    free(t);
    free(y);
    return st ? mps_err_prefix(err, "%s: motion.table: ", mps_case_where(c, "motion.table.file"))
              : MPS_OK;
}

enum mps_status mps_motion_read(struct mps_motion **out, const struct mps_case *c,
                                struct mps_err *err)
{
    *out = NULL;
    struct mps_motion *m = calloc(1, sizeof *m);
    if (!m)
        return mps_err_set(err, MPS_ENOMEM, "motion: out of memory");
    const char *kind = mps_case_string(c, "motion.kind");
    for (int k = 0; k <= MPS_MOTION_TABLE; k++)
        if (strcmp(kind, kind_names[k]) == 0)
            m->kind = (enum mps_motion_kind)k;
    m->g[0] = mps_case_double(c, "gravity.x");
    m->g[1] = mps_case_double(c, "gravity.y");
    enum mps_status st = MPS_OK;
    if (m->kind != MPS_MOTION_NONE) {
        if (!mps_case_has(c, "motion.pivot.x") || !mps_case_has(c, "motion.pivot.y"))
            st = mps_case_fail(c, err, "motion.kind", "needs motion.pivot: {x, y} (the roll "
                                                      "axis in the tank frame, m)");
        else {
            m->pivot[0] = mps_case_double(c, "motion.pivot.x");
            m->pivot[1] = mps_case_double(c, "motion.pivot.y");
        }
    }
    if (!st) {
        switch (m->kind) {
        case MPS_MOTION_NONE: break;
        case MPS_MOTION_CONSTANT: m->angle = mps_case_double(c, "motion.angle") * DEG; break;
        case MPS_MOTION_SINUSOID: st = read_sinusoid(m, c, err); break;
        case MPS_MOTION_TABLE: st = read_table_kind(m, c, err); break;
        }
    }
    if (st) {
        mps_motion_destroy(&m);
        return st;
    }
    *out = m;
    return MPS_OK;
}

void mps_motion_destroy(struct mps_motion **pm)
{
    if (!pm || !*pm)
        return;
    free((*pm)->coef);
    free(*pm);
    *pm = NULL;
}

struct mps_motion_frame mps_motion_at(const struct mps_motion *m, double t)
{
    struct mps_motion_frame f = {.t = t};
    switch (m->kind) {
    case MPS_MOTION_NONE: break;
    case MPS_MOTION_CONSTANT: f.theta = m->angle; break;
    case MPS_MOTION_SINUSOID: {
        const double w = 2.0 * PI / m->period, s = sin(w * t), co = cos(w * t);
        f.theta = m->amplitude * s;
        f.omega = m->amplitude * w * co;
        f.omega_dot = -m->amplitude * w * w * s;
        break;
    }
    case MPS_MOTION_TABLE: {
        double u, b[4], d1[4], d2[4];
        int k = span_of(m, t, &u);
        bspline(u, b, d1, d2);
        for (int a = 0; a < 4; a++) {
            f.theta += m->coef[k + a] * b[a];
            f.omega += m->coef[k + a] * d1[a];
            f.omega_dot += m->coef[k + a] * d2[a];
        }
        f.omega /= m->h;
        f.omega_dot /= m->h * m->h;
        break;
    }
    }
    if (m->kind == MPS_MOTION_NONE) {
        f.g[0] = m->g[0];
        f.g[1] = m->g[1];
    } else {
        /* the lab's gravity in the tank's axes: R(-theta) g */
        const double c = cos(f.theta), s = sin(f.theta);
        f.g[0] = c * m->g[0] + s * m->g[1];
        f.g[1] = -s * m->g[0] + c * m->g[1];
    }
    f.pivot[0] = m->pivot[0];
    f.pivot[1] = m->pivot[1];
    return f;
}

void mps_motion_summary(const struct mps_motion *m, struct mps_json *j)
{
    mps_json_str(j, "kind", mps_motion_kind_name(m->kind));
    if (m->kind == MPS_MOTION_NONE)
        return;
    mps_json_num(j, "pivot_x", m->pivot[0]);
    mps_json_num(j, "pivot_y", m->pivot[1]);
    switch (m->kind) {
    case MPS_MOTION_CONSTANT: mps_json_num(j, "angle_deg", m->angle / DEG); break;
    case MPS_MOTION_SINUSOID:
        mps_json_num(j, "amplitude_deg", m->amplitude / DEG);
        mps_json_num(j, "period", m->period);
        mps_json_str(j, "period_from", m->period_eq55 ? "eq55" : "case");
        break;
    case MPS_MOTION_TABLE:
        mps_json_str(j, "table", m->table_file);
        mps_json_int(j, "table_rows", (long long)m->table_rows);
        mps_json_num(j, "table_end", m->t_end);
        mps_json_num(j, "knot_spacing", m->h);
        mps_json_num(j, "fit_rms_deg", m->table_rms / DEG);
        break;
    default: break;
    }
}
