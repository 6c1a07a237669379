/* Pressure sensors and tank-wall loads; see fluid_sensors.h and docs/sensors.md. */
#include "fluid_sensors.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"

/* A fluid particle next to a face: its position s along the face, its
 * weight for its distance from the face, its pressure carried to the face
 * point at s. */
struct face_pt {
    double s, wn, p;
};

/* The fluid particles next to one face, sorted by s. */
struct face_pts {
    struct face_pt *a;
    size_t n, cap;
};

/* A face: a point o on it, unit tangent t (s grows along it), normal n from
 * the water into the wall or body, and the stretch [lo, hi] of s that is
 * read. The tank's walls: their inner faces; a solid's: the straight line
 * through the face point of a surface particle (fluid_sensors_value). */
struct face_geom {
    double o[2], t[2], n[2], lo, hi;
};

struct fluid_sensors {
    double sum[FLUID_MAX_PROBES]; /* integral of each averaged probe over time */
    double time;                  /* time integrated since the last restart, s */
    enum fluid_sensor_on on[FLUID_MAX_PROBES]; /* pressure: resolved placement */
    int anchor[FLUID_MAX_PROBES]; /* on a solid: id of its surface particle, -1 not yet */
    double offset[FLUID_MAX_PROBES]; /* and the sensor's centre along the face from it, m */
    unsigned char wall_used[FLUID_NWALLS];
    struct face_pts wall[FLUID_NWALLS];
    struct face_pts body; /* scratch: the face of a sensor on a solid */
};

static struct face_geom face_of(const struct fluid_params *p, enum fluid_wall w)
{
    const double W = p->tank_w, H = p->tank_h;
    switch (w) {
    case FLUID_WALL_LEFT: return (struct face_geom){{0, 0}, {0, 1}, {-1, 0}, 0, H};
    case FLUID_WALL_RIGHT: return (struct face_geom){{W, 0}, {0, 1}, {1, 0}, 0, H};
    case FLUID_WALL_FLOOR: return (struct face_geom){{0, 0}, {1, 0}, {0, -1}, 0, W};
    default: return (struct face_geom){{0, H}, {1, 0}, {0, 1}, 0, W};
    }
}

int fluid_probe_averaged(enum fluid_probe_kind kind)
{
    return kind == FLUID_PROBE_PRESSURE || kind == FLUID_PROBE_WALL_FORCE ||
           kind == FLUID_PROBE_WALL_MOMENT;
}

enum mps_status fluid_sensors_create(struct fluid_sensors **out, const struct fluid_params *p,
                                     struct mps_err *err)
{
    *out = NULL;
    int any = 0;
    for (int k = 0; k < p->nprobes; k++)
        any |= fluid_probe_averaged(p->probes[k].kind);
    if (!any)
        return MPS_OK;
    struct fluid_sensors *s = calloc(1, sizeof *s);
    if (!s)
        return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory for the sensors");
    for (int k = 0; k < p->nprobes; k++) {
        const struct fluid_probe_def *d = &p->probes[k];
        s->on[k] = d->on;
        s->anchor[k] = -1;
        if (d->kind != FLUID_PROBE_PRESSURE || d->on == FLUID_ON_WALL)
            s->wall_used[d->wall] |= fluid_probe_averaged(d->kind);
    }
    *out = s;
    return MPS_OK;
}

void fluid_sensors_destroy(struct fluid_sensors **ps)
{
    struct fluid_sensors *s = ps ? *ps : NULL;
    if (!s)
        return;
    for (int w = 0; w < FLUID_NWALLS; w++)
        free(s->wall[w].a);
    free(s->body.a);
    free(s);
    *ps = NULL;
}

/* ---- the face pressure ---- */

static int cmp_face_pt(const void *a, const void *b)
{
    double sa = ((const struct face_pt *)a)->s, sb = ((const struct face_pt *)b)->s;
    return (sa > sb) - (sa < sb);
}

/* Adds fluid particle i to face q's points if it is next to the face: its
 * centre less than 1.5 dp in front of it (and less than dp behind: the
 * other side of a thin body is not this face's), within dp of the stretch
 * read. A failed allocation leaves the particle out (the reading is then
 * low, never a crash); the buffers only grow, so it can only happen in the
 * first steps. */
static void face_add(const struct fluid *f, const struct face_geom *q, size_t i,
                     struct face_pts *out)
{
    const struct fluid_params *p = &f->prm;
    const double dp = p->dp, band = 1.5 * dp;
    const double rx = f->x[i][0] - q->o[0], ry = f->x[i][1] - q->o[1];
    const double d = -(rx * q->n[0] + ry * q->n[1]); /* in front of the face */
    const double sx = rx * q->t[0] + ry * q->t[1];
    if (d >= band || d <= -dp || sx <= q->lo - dp || sx >= q->hi + dp)
        return;
    if (out->n == out->cap) {
        size_t cap = out->cap ? 2 * out->cap : 256;
        struct face_pt *a = realloc(out->a, cap * sizeof *a);
        if (!a)
            return;
        out->a = a;
        out->cap = cap;
    }
    /* full weight up to dp/2 from the face (the first row's place on the
     * lattice), none from 1.5 dp (the second row's) */
    double wn = fmin(1.0, (band - d) / dp);
    /* carried along the normal to the face point: P + rho g.n d */
    double pf = f->p[i] + p->rho * d * (p->g[0] * q->n[0] + p->g[1] * q->n[1]);
    out->a[out->n++] = (struct face_pt){sx, wn, pf};
}

static void face_sort(struct face_pts *fp)
{
    if (fp->n > 1)
        qsort(fp->a, fp->n, sizeof *fp->a, cmp_face_pt);
}

/* The fluid next to each wall face in use: one pass over the fluid with a
 * few comparisons per particle; what follows is only for those found. */
static void collect_walls(const struct fluid *f)
{
    struct fluid_sensors *s = f->sens;
    struct face_geom g[FLUID_NWALLS];
    int used = 0;
    for (int w = 0; w < FLUID_NWALLS; w++) {
        g[w] = face_of(&f->prm, (enum fluid_wall)w);
        s->wall[w].n = 0;
        used |= s->wall_used[w];
    }
    if (!used)
        return;
    for (size_t i = 0; i < f->nfluid; i++)
        for (int w = 0; w < FLUID_NWALLS; w++)
            if (s->wall_used[w])
                face_add(f, &g[w], i, &s->wall[w]);
    for (int w = 0; w < FLUID_NWALLS; w++)
        face_sort(&s->wall[w]);
}

/* Reads the face pressure at increasing s (a moving window of the sorted
 * points within dp). */
struct face_reader {
    const struct face_pt *pt;
    size_t n, lo;
    double dp, rho_gt; /* rho g.t: the hydrostatic carry along the face */
    int clamp;
};

static struct face_reader face_reader(const struct fluid *f, const struct face_geom *q,
                                      const struct face_pts *fp, double s_first)
{
    const struct fluid_params *p = &f->prm;
    struct face_reader r = {fp->a, fp->n, 0, p->dp,
                            p->rho * (p->g[0] * q->t[0] + p->g[1] * q->t[1]), p->clamp_negative};
    size_t a = 0, b = r.n; /* the first point with s > s_first - dp */
    while (a < b) {
        size_t m = a + (b - a) / 2;
        if (r.pt[m].s <= s_first - r.dp)
            a = m + 1;
        else
            b = m;
    }
    r.lo = a;
    return r;
}

static double face_pressure(struct face_reader *r, double s)
{
    while (r->lo < r->n && r->pt[r->lo].s <= s - r->dp)
        r->lo++;
    double sw = 0.0, swp = 0.0;
    for (size_t k = r->lo; k < r->n && r->pt[k].s < s + r->dp; k++) {
        const struct face_pt *q = &r->pt[k];
        double w = (1.0 - fabs(s - q->s) / r->dp) * q->wn;
        double pk = q->p + r->rho_gt * (s - q->s);
        if (r->clamp && pk < 0.0)
            pk = 0.0; /* carried above the water line: gauge 0 */
        sw += w;
        swp += w * pk;
    }
    /* less than half a row of particles touching the face: the rest is dry */
    return swp / fmax(sw, 0.5);
}

/* Integrals of the face pressure over a whole wall, midpoint rule at
 * spacing <= dp/4 over the stretch the particles touch: I0 = int P ds (N/m),
 * I1 = int P s ds. */
static void wall_integrals(const struct fluid *f, enum fluid_wall w, double *I0, double *I1)
{
    const struct face_pts *fp = &f->sens->wall[w];
    *I0 = *I1 = 0.0;
    if (fp->n == 0)
        return;
    const struct face_geom q = face_of(&f->prm, w);
    const double dp = f->prm.dp, len = q.hi;
    const long nq = (long)ceil(4.0 * len / dp);
    const double h = len / (double)nq;
    long k0 = (long)floor(fmax(0.0, fp->a[0].s - dp) / h);
    long k1 = (long)ceil(fmin(len, fp->a[fp->n - 1].s + dp) / h);
    if (k1 > nq)
        k1 = nq;
    struct face_reader r = face_reader(f, &q, fp, (k0 + 0.5) * h);
    for (long k = k0; k < k1; k++) {
        double sk = (k + 0.5) * h, pk = face_pressure(&r, sk);
        *I0 += h * pk;
        *I1 += h * pk * sk;
    }
}

/* A circular transducer of diameter D on a face, centred at s0: in a 2D flow
 * it averages P(s) with the chord 2 sqrt(R^2 - (s - s0)^2) of its disc as
 * weight. At least 16 points, and 8 per dp. */
static double face_sensor(const struct fluid *f, const struct face_geom *q,
                          const struct face_pts *fp, double s0, double D)
{
    const double R = 0.5 * D;
    int nq = (int)ceil(8.0 * D / f->prm.dp);
    if (nq < 16)
        nq = 16;
    if (nq > 4096)
        nq = 4096;
    const double h = 2.0 * R / nq;
    struct face_reader r = face_reader(f, q, fp, s0 - R + 0.5 * h);
    double sc = 0.0, scp = 0.0;
    for (int k = 0; k < nq; k++) {
        double u = -R + (k + 0.5) * h, c = sqrt(R * R - u * u);
        sc += c;
        scp += c * face_pressure(&r, s0 + u);
    }
    return sc > 0.0 ? scp / sc : 0.0;
}

static double wall_sensor(const struct fluid *f, const struct fluid_probe_def *d)
{
    const struct face_geom q = face_of(&f->prm, d->wall);
    const double s0 = q.t[1] != 0.0 ? d->y : d->x;
    return face_sensor(f, &q, &f->sens->wall[d->wall], s0, d->diameter);
}

static double wall_load(const struct fluid *f, const struct fluid_probe_def *d)
{
    double I0, I1;
    wall_integrals(f, d->wall, &I0, &I1);
    if (d->kind == FLUID_PROBE_WALL_FORCE)
        return I0; /* P pushes the wall outward, along n */
    /* M_z = int (r - x0) x (P n) ds with r = o + s t */
    struct face_geom q = face_of(&f->prm, d->wall);
    double arm0 = (q.o[0] - d->x) * q.n[1] - (q.o[1] - d->y) * q.n[0];
    double arm1 = q.t[0] * q.n[1] - q.t[1] * q.n[0];
    return arm0 * I0 + arm1 * I1;
}

/* ---- sensors in the water and on a solid ---- */

/* The fluid within max(D/2, dp) of the point, each pressure carried
 * hydrostatically to it, averaged (0: no water there). dp at least, so a
 * sensor smaller than a particle still finds the two or three around it. */
static double water_sensor(const struct fluid *f, const struct fluid_probe_def *d)
{
    const struct fluid_params *p = &f->prm;
    const double r = fmax(0.5 * d->diameter, p->dp), r2 = r * r;
    double sum = 0.0;
    long m = 0;
    for (size_t i = 0; i < f->nfluid; i++) {
        double dx = d->x - f->x[i][0], dy = d->y - f->x[i][1];
        if (dx * dx + dy * dy >= r2)
            continue;
        double pi = f->p[i] + p->rho * (p->g[0] * dx + p->g[1] * dy);
        sum += (p->clamp_negative && pi < 0.0) ? 0.0 : pi;
        m++;
    }
    return m ? sum / (double)m : 0.0;
}

/* Index of the solid surface particle nearest (x, y), or -1 (no solid). */
static long nearest_surface(const struct fluid *f, double x, double y, double *dist)
{
    long best = -1;
    double b2 = INFINITY;
    for (size_t i = f->nfixed_end; i < f->ps.n; i++) {
        if (f->type[i] != SOLID_SURF_P)
            continue;
        double dx = f->x[i][0] - x, dy = f->x[i][1] - y, r2 = dx * dx + dy * dy;
        if (r2 < b2) {
            b2 = r2;
            best = (long)i;
        }
    }
    *dist = sqrt(b2);
    return best;
}

/* A sensor on a solid's face. Its anchor, the solid surface particle
 * nearest the given point at the first reading, gives the face: the straight
 * line dp/2 out from the anchor's centre along the surface particles within
 * re_n of it (their principal axis; at a corner, or with fewer than three,
 * normal to the direction away from the solid particles around the anchor),
 * on the side away from the solid; the sensor keeps its place along
 * that line (offset from the anchor) and moves with the body. It reads the
 * fluid next to the face as on a tank wall, not the solid surface particles'
 * own pressures: the same reading on walls and bodies, and one that keeps
 * its diameter with fluid.wall_bc neumann, where those pressures are
 * averages over re_n + dp like the tank's wall particles'. (In still water
 * against the test plate, tests/coupler/plate_in_water.yml, both read
 * within 7 Pa of hydrostatic: docs/sensors.md.) */
static int solid_face(const struct fluid *f, int anchor, struct face_geom *q)
{
    const struct fluid_params *p = &f->prm;
    const double dp = p->dp;
    long a = -1;
    for (size_t i = f->nfixed_end; i < f->ps.n && a < 0; i++)
        if (f->id[i] == anchor)
            a = (long)i;
    if (a < 0)
        return -1; /* the anchor is gone (a solid re-sent without it) */
    const double *xa = f->x[a];
    /* m: from the solid around a towards a, out of the body; the surface
     * particles around a: their line (principal axis) is the face */
    double m[2] = {0.0, 0.0}, c[2] = {0.0, 0.0}, cxx = 0.0, cyy = 0.0, cxy = 0.0;
    int ns = 0;
    const double re2 = p->re_n * dp * p->re_n * dp;
    for (size_t i = f->nfixed_end; i < f->ps.n; i++) {
        double dx = f->x[i][0] - xa[0], dy = f->x[i][1] - xa[1];
        if (dx * dx + dy * dy >= re2)
            continue;
        m[0] -= dx;
        m[1] -= dy;
        if (f->type[i] == SOLID_SURF_P) {
            c[0] += dx;
            c[1] += dy;
            cxx += dx * dx;
            cyy += dy * dy;
            cxy += dx * dy;
            ns++;
        }
    }
    double mm = hypot(m[0], m[1]);
    if (mm <= 0.0)
        return -1;
    double n[2] = {m[0] / mm, m[1] / mm}; /* out of the body */
    if (ns >= 3) {
        cxx -= c[0] * c[0] / ns;
        cyy -= c[1] * c[1] / ns;
        cxy -= c[0] * c[1] / ns;
        double th = 0.5 * atan2(2.0 * cxy, cxx - cyy);
        double nl[2] = {-sin(th), cos(th)};
        double sgn = nl[0] * m[0] + nl[1] * m[1] >= 0.0 ? 1.0 : -1.0;
        n[0] = sgn * nl[0];
        n[1] = sgn * nl[1];
    }
    q->n[0] = -n[0]; /* into the body */
    q->n[1] = -n[1];
    q->t[0] = -q->n[1];
    q->t[1] = q->n[0];
    q->o[0] = xa[0] - 0.5 * dp * q->n[0];
    q->o[1] = xa[1] - 0.5 * dp * q->n[1];
    q->lo = q->hi = 0.0;
    return 0;
}

static double solid_sensor(const struct fluid *f, int k)
{
    struct fluid_sensors *s = f->sens;
    const double R = 0.5 * f->prm.probes[k].diameter, s0 = s->offset[k];
    struct face_geom q;
    if (solid_face(f, s->anchor[k], &q))
        return NAN;
    q.lo = s0 - R;
    q.hi = s0 + R;
    struct face_pts *fp = &s->body;
    fp->n = 0;
    for (size_t i = 0; i < f->nfluid; i++)
        face_add(f, &q, i, fp);
    face_sort(fp);
    return face_sensor(f, &q, fp, s0, 2.0 * R);
}

/* Resolves where a sensor sits the first time it can be (a coupled run has
 * its solid from the first step on; at t = 0 an auto sensor off the walls
 * reads the water and is decided again after the first step). */
static enum fluid_sensor_on resolve(const struct fluid *f, int k)
{
    struct fluid_sensors *s = f->sens;
    const struct fluid_probe_def *d = &f->prm.probes[k];
    const enum fluid_sensor_on on = s->on[k];
    if (on == FLUID_ON_WALL || on == FLUID_ON_WATER || s->anchor[k] >= 0)
        return on;
    double dist;
    long i = nearest_surface(f, d->x, d->y, &dist);
    if (on == FLUID_ON_AUTO && (i < 0 || dist > f->prm.dp)) {
        if (i >= 0 || f->step > 0)
            s->on[k] = FLUID_ON_WATER;
        return FLUID_ON_WATER;
    }
    if (i < 0)
        return FLUID_ON_SOLID; /* on: solid, no solid (yet): NaN */
    s->on[k] = FLUID_ON_SOLID;
    s->anchor[k] = f->id[i];
    /* the sensor stays where it was put along the face, not on the anchor */
    struct face_geom q;
    if (solid_face(f, s->anchor[k], &q) == 0)
        s->offset[k] = (d->x - q.o[0]) * q.t[0] + (d->y - q.o[1]) * q.t[1];
    return FLUID_ON_SOLID;
}

/* Probe k's value now (an averaged kind). Needs collect_walls() first. */
static double value_now(const struct fluid *f, int k)
{
    const struct fluid_probe_def *d = &f->prm.probes[k];
    if (d->kind != FLUID_PROBE_PRESSURE)
        return wall_load(f, d);
    switch (resolve(f, k)) {
    case FLUID_ON_WALL: return wall_sensor(f, d);
    case FLUID_ON_SOLID: return f->sens->anchor[k] >= 0 ? solid_sensor(f, k) : NAN;
    default: return water_sensor(f, d);
    }
}

void fluid_sensors_accumulate(const struct fluid *f, double dt)
{
    struct fluid_sensors *s = f->sens;
    if (!s)
        return;
    collect_walls(f);
    for (int k = 0; k < f->prm.nprobes; k++)
        if (fluid_probe_averaged(f->prm.probes[k].kind))
            s->sum[k] += dt * value_now(f, k);
    s->time += dt;
}

double fluid_sensors_value(const struct fluid *f, int k)
{
    struct fluid_sensors *s = f->sens;
    if (s->time > 0.0)
        return s->sum[k] / s->time;
    collect_walls(f);
    return value_now(f, k);
}

void fluid_sensors_restart(const struct fluid *f)
{
    struct fluid_sensors *s = f->sens;
    if (!s)
        return;
    memset(s->sum, 0, sizeof s->sum);
    s->time = 0.0;
}

void fluid_sensors_summary(const struct fluid *f, struct mps_json *j)
{
    const struct fluid_sensors *s = f->sens;
    if (!s)
        return;
    mps_json_object(j, "sensors");
    for (int k = 0; k < f->prm.nprobes; k++) {
        const struct fluid_probe_def *d = &f->prm.probes[k];
        char what[160];
        if (d->kind != FLUID_PROBE_PRESSURE)
            continue;
        switch (s->on[k]) {
        case FLUID_ON_WALL:
            snprintf(what, sizeof what, "%s wall, diameter %g m", fluid_wall_names[d->wall],
                     d->diameter);
            break;
        case FLUID_ON_SOLID:
            if (s->anchor[k] >= 0)
                snprintf(what, sizeof what, "on a solid: face of surface particle id %d, "
                         "%+.4g m along it, diameter %g m", s->anchor[k], s->offset[k],
                         d->diameter);
            else
                snprintf(what, sizeof what, "on a solid, but there was none");
            break;
        case FLUID_ON_WATER:
            snprintf(what, sizeof what, "in the water, radius %g m",
                     fmax(0.5 * d->diameter, f->prm.dp));
            break;
        default: snprintf(what, sizeof what, "never read"); break;
        }
        mps_json_str(j, d->name, what);
    }
    mps_json_close(j);
}
