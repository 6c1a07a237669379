#include "solid_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_budget.h"
#include "mps_kernel.h"
#include "solid_loadprobe.h"

#define ANY (MPS_KEY_NO_LO | MPS_KEY_NO_HI)
#define POS (MPS_KEY_LO_OPEN | MPS_KEY_NO_HI)

/* Courant default 0.9: C = 1 is at or below the linear stability limit of
 * bodies 3 or more particles thick, a strip 2 particles thick goes unstable
 * at 0.96 (solid_mps.h, test_solid_stability). */
const struct mps_key_spec solid_case_keys[] = {
    {"solid.model", MPS_KEY_ENUM, "mps", 0, 0, 0, "mps|tlsph", "", "solid model"},
    {"solid.tlsph.alpha", MPS_KEY_DOUBLE, "1", 0, 0, MPS_KEY_NO_HI, NULL, "",
     "TLSPH artificial viscosity coefficient (solid_tlsph.h)"},
    {"solid.tlsph.hourglass", MPS_KEY_DOUBLE, "0.05", 0, 0, MPS_KEY_NO_HI, NULL, "",
     "TLSPH hourglass stiffness, fraction of E (solid_tlsph.h)"},
    {"solid.tlsph.correction", MPS_KEY_ENUM, "linear", 0, 0, 0, "linear|quadratic", "",
     "TLSPH kernel gradient correction: exact for linear or quadratic fields"},
    {"solid.mps.damping", MPS_KEY_DOUBLE, "0", 0, 0.5, 0, NULL, "",
     "MPS solid: damping ratio of the spin (highest) frequency, Kelvin-Voigt on the bonds; "
     "0 = the paper (solid_mps.h)"},
    {"solid.refine", MPS_KEY_INT, "1", 1, 8, 0, NULL, "",
     "solid particles per dp along each axis: the solid runs on a lattice this much finer than "
     "the fluid and meets it on the dp lattice (solid_refine.h); 1 = the paper"},
    {"solid.courant", MPS_KEY_DOUBLE, "0.9", 0, 1, MPS_KEY_LO_OPEN, NULL, "",
     "fraction of the stable explicit step, in (0, 1]"},
    {"solid.plane", MPS_KEY_ENUM, "strain", 0, 0, 0, "strain|stress", "",
     "2D Lame constants: plane strain (Eq. 4 as printed) or plane stress"},
    {"solid.plane_factor", MPS_KEY_DOUBLE, "1", 0, 2, MPS_KEY_LO_OPEN, NULL, "",
     "factor on E in 2D: the bending stiffness of the 3D body over that of the plane chosen, "
     "for a strip whose breadth and clamp put it between the planes "
     "(bench/plate_3d_stiffness.py); 1 = the plane as it is"},
    /* at least half a spacing: any depth under one sends the surface layer
     * alone, and 1e-300 dp made a grid of 1e300 cells */
    {"solid.interface_depth", MPS_KEY_DOUBLE, "2.1", 0.5, 0, MPS_KEY_NO_HI, NULL,
     "dp", "inner particles within this depth of the surface are sent to a coupled fluid (its "
     "number-density radius)"},
    /* No defaults: a scene that sets neither has no fracture and no contact,
     * and pays nothing for them (solid_mps_fracture.h, docs/fracture.md). */
    {"solid.eps_max", MPS_KEY_DOUBLE, NULL, 0, 0, POS, NULL, "",
     "brittle fracture (Eq. 47): a bond breaks for good when its normal strain exceeds this; "
     "absent: no fracture"},
    {"solid.contact", MPS_KEY_ENUM, NULL, 0, 0, 0, "all|bodies|none", "",
     "contact between unbonded surface particles: all (default with eps_max), bodies (only "
     "between different bodies), none (default without eps_max)"},
    {"solid.bodies.*.name", MPS_KEY_STRING, NULL, 0, 0, MPS_KEY_REQUIRED, NULL, "",
     "body name, used by clamps"},
    {"solid.bodies.*.x0", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "left edge of the body"},
    {"solid.bodies.*.y0", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "bottom edge of the body"},
    {"solid.bodies.*.x1", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "right edge of the body"},
    {"solid.bodies.*.y1", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "top edge of the body"},
    {"solid.bodies.*.rho", MPS_KEY_DOUBLE, NULL, 0, 0, POS | MPS_KEY_REQUIRED, NULL, "kg/m^3",
     "density"},
    {"solid.bodies.*.E", MPS_KEY_DOUBLE, NULL, 0, 0, POS | MPS_KEY_REQUIRED, NULL, "Pa",
     "Young's modulus"},
    {"solid.bodies.*.nu", MPS_KEY_DOUBLE, NULL, -1, 0.5,
     MPS_KEY_LO_OPEN | MPS_KEY_HI_OPEN | MPS_KEY_REQUIRED, NULL, "", "Poisson's ratio"},
    {"solid.bodies.*.vx", MPS_KEY_DOUBLE, "0", 0, 0, ANY, NULL, "m/s", "initial velocity, x"},
    {"solid.bodies.*.vy", MPS_KEY_DOUBLE, "0", 0, 0, ANY, NULL, "m/s", "initial velocity, y"},
    {"solid.clamps.*.body", MPS_KEY_STRING, NULL, 0, 0, MPS_KEY_REQUIRED, NULL, "",
     "name of the clamped body"},
    {"solid.clamps.*.x0", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "clamp region, left"},
    {"solid.clamps.*.y0", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "clamp region, bottom"},
    {"solid.clamps.*.x1", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "clamp region, right"},
    {"solid.clamps.*.y1", MPS_KEY_DOUBLE, NULL, 0, 0, ANY | MPS_KEY_REQUIRED, NULL, "m",
     "clamp region, top"},
    {"solid.probes.*.name", MPS_KEY_STRING, NULL, 0, 0, MPS_KEY_REQUIRED, NULL, "",
     "column name in probes.csv"},
    {"solid.probes.*.kind", MPS_KEY_ENUM, NULL, 0, 0, MPS_KEY_REQUIRED,
     "dx|dy|x|y|tank_angle|energy|force_x|force_y|moment", "",
     "displacement or position component of a particle; the tank's roll angle; the solid's "
     "energy; or the fluid's force on a body, or its moment about (x, y), the mean over the "
     "time since the previous probe row (docs/sensors.md)"},
    {"solid.probes.*.x", MPS_KEY_DOUBLE, NULL, 0, 0, ANY, NULL, "m",
     "probe point: the nearest particle(s) at start (dx, dy, x, y); the point the moment is "
     "taken about (moment)"},
    {"solid.probes.*.y", MPS_KEY_DOUBLE, NULL, 0, 0, ANY, NULL, "m",
     "probe point: the nearest particle(s) at start (dx, dy, x, y); the point the moment is "
     "taken about (moment)"},
    {"solid.probes.*.body", MPS_KEY_STRING, NULL, 0, 0, 0, NULL, "",
     "force_x, force_y, moment: the body's name (absent: all bodies together)"},
    {.name = NULL},
};

const struct mps_key_spec *const solid_case_tables[SOLID_NTABLES] = {
    mps_case_common_keys, solid_case_keys, mps_motion_keys};

void solid_scene_lattice(const struct solid_scene *s, int b, long *nx, long *ny)
{
    const struct solid_body_def *d = &s->bodies[b];
    /* a scene built by hand (tests) may leave refine 0: unrefined */
    const long k = s->refine > 1 ? s->refine : 1;
    const double dpc = k > 1 ? s->dp_coupling : s->dp;
    *nx = mps_lattice_count(d->x0, d->x1, dpc) * k;
    *ny = mps_lattice_count(d->y0, d->y1, dpc) * k;
    if (*nx == 0 || *ny == 0)
        *nx = *ny = 0;
}

double solid_scene_modulus(const struct solid_scene *s, int b)
{
    /* a scene built by hand (tests) may leave the factor 0: none */
    return s->bodies[b].E * (s->plane_factor > 0.0 ? s->plane_factor : 1.0);
}

void solid_scene_lame(const struct solid_scene *s, int b, double *lambda, double *mu)
{
    double E = solid_scene_modulus(s, b), nu = s->bodies[b].nu;
    *mu = E / (2.0 * (1.0 + nu)); /* Eq. 4 */
    if (s->plane == SOLID_PLANE_STRAIN)
        *lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)); /* Eq. 4 */
    else
        *lambda = E * nu / (1.0 - nu * nu);
}

/* Lattice points of body b inside [x0, x1] x [y0, y1]. */
static long count_inside(const struct solid_scene *s, int b, double x0, double y0, double x1,
                         double y1)
{
    long nx, ny, k = 0;
    solid_scene_lattice(s, b, &nx, &ny);
    const struct solid_body_def *d = &s->bodies[b];
    for (long i = 0; i < nx; i++) {
        double x = d->x0 + s->dp * (0.5 + (double)i);
        if (x < x0 || x > x1)
            continue;
        for (long j = 0; j < ny; j++) {
            double y = d->y0 + s->dp * (0.5 + (double)j);
            k += (y >= y0 && y <= y1);
        }
    }
    return k;
}

/* "plate, post": the bodies' names, for messages. */
static const char *body_names(const struct solid_scene *s, char *buf, size_t len)
{
    buf[0] = '\0';
    for (int b = 0; b < s->nbodies; b++)
        snprintf(buf + strlen(buf), len - strlen(buf), "%s%s", b ? ", " : "", s->bodies[b].name);
    return buf;
}

static void copy_name(char *dst, const char *src)
{
    snprintf(dst, SOLID_NAME_MAX, "%s", src);
}

enum mps_status solid_scene_read(struct solid_scene *s, const struct mps_case *c,
                                 struct mps_err *err)
{
    memset(s, 0, sizeof *s);
    char key[128];
    s->dp_coupling = mps_case_double(c, "dp");
    s->refine = (int)mps_case_int(c, "solid.refine");
    s->dp = s->dp_coupling / s->refine;
    s->g[0] = mps_case_double(c, "gravity.x");
    s->g[1] = mps_case_double(c, "gravity.y");
    s->courant = mps_case_double(c, "solid.courant");
    s->mps_damping = mps_case_double(c, "solid.mps.damping");
    s->plane = strcmp(mps_case_string(c, "solid.plane"), "strain") == 0 ? SOLID_PLANE_STRAIN
                                                                          : SOLID_PLANE_STRESS;
    s->plane_factor = mps_case_double(c, "solid.plane_factor");
    s->eps_max = mps_case_has(c, "solid.eps_max") ? mps_case_double(c, "solid.eps_max") : 0.0;
    s->contact = s->eps_max > 0.0 ? SOLID_CONTACT_ALL : SOLID_CONTACT_NONE;
    if (mps_case_has(c, "solid.contact")) {
        const char *v = mps_case_string(c, "solid.contact");
        s->contact = strcmp(v, "all") == 0      ? SOLID_CONTACT_ALL
                     : strcmp(v, "bodies") == 0 ? SOLID_CONTACT_BODIES
                                                : SOLID_CONTACT_NONE;
    }
    /* the refinement maps each coupling particle onto a fixed block of solid
     * particles; fracture makes new surface inside a block (solid_refine.h) */
    if (s->refine > 1 && (s->eps_max > 0.0 || s->contact != SOLID_CONTACT_NONE))
        return mps_case_fail(c, err, "solid.refine", "%d with %s: fracture and contact run "
                             "at the coupling's dp only (set solid.refine to 1)", s->refine,
                             s->eps_max > 0.0 ? "solid.eps_max" : "solid.contact");

    s->nbodies = mps_case_count(c, "solid.bodies");
    if (s->nbodies == 0)
        return mps_err_set(err, MPS_EINPUT, "%s: solid.bodies: no solid body given",
                           mps_case_origin(c));
    if (s->nbodies > SOLID_MAX_BODIES)
        return mps_case_fail(c, err, "solid.bodies", "%d bodies: at most %d", s->nbodies,
                             SOLID_MAX_BODIES);
    for (int b = 0; b < s->nbodies; b++) {
        struct solid_body_def *d = &s->bodies[b];
        snprintf(key, sizeof key, "solid.bodies.%d.name", b);
        if (!mps_case_has(c, "%s", key))
            return mps_err_set(err, MPS_EINPUT, "%s: solid.bodies.%d: missing (a gap in the "
                               "list of bodies)", mps_case_origin(c), b);
        copy_name(d->name, mps_case_string(c, "%s", key));
        d->x0 = mps_case_double(c, "solid.bodies.%d.x0", b);
        d->y0 = mps_case_double(c, "solid.bodies.%d.y0", b);
        d->x1 = mps_case_double(c, "solid.bodies.%d.x1", b);
        d->y1 = mps_case_double(c, "solid.bodies.%d.y1", b);
        d->rho = mps_case_double(c, "solid.bodies.%d.rho", b);
        d->E = mps_case_double(c, "solid.bodies.%d.E", b);
        d->nu = mps_case_double(c, "solid.bodies.%d.nu", b);
        d->v[0] = mps_case_double(c, "solid.bodies.%d.vx", b);
        d->v[1] = mps_case_double(c, "solid.bodies.%d.vy", b);
        for (int a = 0; a < b; a++)
            if (strcmp(s->bodies[a].name, d->name) == 0)
                return mps_case_fail(c, err, key, "body name already used by "
                                     "solid.bodies.%d", a);
        /* two bodies in one place would put particles on top of each other */
        for (int a = 0; a < b; a++) {
            const struct solid_body_def *o = &s->bodies[a];
            double tol = 1e-3 * s->dp;
            if (fmin(d->x1, o->x1) - fmax(d->x0, o->x0) > tol &&
                fmin(d->y1, o->y1) - fmax(d->y0, o->y0) > tol) {
                snprintf(key, sizeof key, "solid.bodies.%d.x0", b);
                return mps_case_fail(c, err, key, "body '%s' overlaps body '%s' ([%g, %g] x "
                                     "[%g, %g])", d->name, o->name, o->x0, o->x1, o->y0, o->y1);
            }
        }
        long nx, ny;
        solid_scene_lattice(s, b, &nx, &ny);
        if (nx == 0) {
            int wide = d->x1 - d->x0 >= s->dp_coupling;
            snprintf(key, sizeof key, "solid.bodies.%d.%s", b, wide ? "y1" : "x1");
            return mps_case_fail(c, err, key, "body '%s' holds no particle: it must reach at "
                                 "least dp = %g beyond %s", d->name, s->dp_coupling,
                                 wide ? "y0" : "x0");
        }
    }

    double nparticles = 0.0;
    for (int b = 0; b < s->nbodies; b++) {
        long nx, ny;
        solid_scene_lattice(s, b, &nx, &ny);
        nparticles += (double)nx * (double)ny;
    }
    enum mps_status st = mps_budget_check(c, "dp", "solid", nparticles, MPS_BUDGET_SOLID_BYTES,
                                          err);
    if (st)
        return st;

    s->nclamps = mps_case_count(c, "solid.clamps");
    if (s->nclamps > SOLID_MAX_CLAMPS)
        return mps_case_fail(c, err, "solid.clamps", "%d clamps: at most %d", s->nclamps,
                             SOLID_MAX_CLAMPS);
    for (int k = 0; k < s->nclamps; k++) {
        struct solid_clamp_def *d = &s->clamps[k];
        snprintf(key, sizeof key, "solid.clamps.%d.body", k);
        if (!mps_case_has(c, "%s", key))
            return mps_err_set(err, MPS_EINPUT, "%s: solid.clamps.%d: missing (a gap in the "
                               "list of clamps)", mps_case_origin(c), k);
        const char *name = mps_case_string(c, "%s", key);
        d->body = -1;
        for (int b = 0; b < s->nbodies; b++)
            if (strcmp(s->bodies[b].name, name) == 0)
                d->body = b;
        if (d->body < 0) {
            char names[512];
            return mps_case_fail(c, err, key, "no body of that name (bodies: %s)",
                                 body_names(s, names, sizeof names));
        }
        d->x0 = mps_case_double(c, "solid.clamps.%d.x0", k);
        d->y0 = mps_case_double(c, "solid.clamps.%d.y0", k);
        d->x1 = mps_case_double(c, "solid.clamps.%d.x1", k);
        d->y1 = mps_case_double(c, "solid.clamps.%d.y1", k);
        if (count_inside(s, d->body, d->x0, d->y0, d->x1, d->y1) == 0) {
            snprintf(key, sizeof key, "solid.clamps.%d.x0", k);
            return mps_case_fail(c, err, key, "empty clamp: region [%g, %g] x [%g, %g] "
                                 "holds no particle centre of body '%s'", d->x0, d->x1, d->y0,
                                 d->y1, name);
        }
    }

    s->nprobes = mps_case_count(c, "solid.probes");
    if (s->nprobes > SOLID_MAX_PROBES)
        return mps_case_fail(c, err, "solid.probes", "%d probes: at most %d", s->nprobes,
                             SOLID_MAX_PROBES);
    for (int k = 0; k < s->nprobes; k++) {
        struct solid_probe_def *d = &s->probes[k];
        snprintf(key, sizeof key, "solid.probes.%d.name", k);
        if (!mps_case_has(c, "%s", key))
            return mps_err_set(err, MPS_EINPUT, "%s: solid.probes.%d: missing (a gap in the "
                               "list of probes)", mps_case_origin(c), k);
        copy_name(d->name, mps_case_string(c, "%s", key));
        static const char *const kinds[] = {"dx",     "dy",      "x",       "y",     "tank_angle",
                                            "energy", "force_x", "force_y", "moment"};
        const char *kind = mps_case_string(c, "solid.probes.%d.kind", k);
        d->kind = SOLID_PROBE_DX;
        for (int a = 0; a < (int)(sizeof kinds / sizeof *kinds); a++)
            if (strcmp(kind, kinds[a]) == 0)
                d->kind = (enum solid_probe_kind)a;
        const int load = d->kind >= SOLID_PROBE_FORCE_X;
        /* a point for the particle kinds and the moment; a force, the tank's
         * angle and the energy have none */
        const int nopoint = d->kind == SOLID_PROBE_FORCE_X || d->kind == SOLID_PROBE_FORCE_Y ||
                            d->kind == SOLID_PROBE_TANK_ANGLE || d->kind == SOLID_PROBE_ENERGY;
        for (int a = 0; a < 2; a++) {
            const char *xy = a ? "y" : "x";
            int has = mps_case_has(c, "solid.probes.%d.%s", k, xy);
            snprintf(key, sizeof key, "solid.probes.%d.%s", k, has ? xy : "kind");
            if (!has && !nopoint)
                return mps_case_fail(c, err, key, "a %s probe needs solid.probes.%d.%s", kind, k,
                                     xy);
            if (has && nopoint)
                return mps_case_fail(c, err, key, "a %s probe has no point (x and y are for "
                                     "dx, dy, x, y and moment)", kind);
            double v = has ? mps_case_double(c, "%s", key) : 0.0;
            if (a)
                d->y = v;
            else
                d->x = v;
        }
        d->body = -1;
        snprintf(key, sizeof key, "solid.probes.%d.body", k);
        if (mps_case_has(c, "%s", key)) {
            if (!load)
                return mps_case_fail(c, err, key, "body is for force_x, force_y and moment");
            const char *name = mps_case_string(c, "%s", key);
            for (int b = 0; b < s->nbodies; b++)
                if (strcmp(s->bodies[b].name, name) == 0)
                    d->body = b;
            char names[512];
            if (d->body < 0)
                return mps_case_fail(c, err, key, "no body of that name (bodies: %s)",
                                     body_names(s, names, sizeof names));
        }
        snprintf(key, sizeof key, "solid.probes.%d.name", k);
        for (int a = 0; a < k; a++)
            if (strcmp(s->probes[a].name, d->name) == 0)
                return mps_case_fail(c, err, key, "probe name already used by "
                                     "solid.probes.%d", a);
    }
    return MPS_OK;
}

void solid_probes_locate(const struct solid_scene *s, size_t n, const double (*x0)[MPS_DIM],
                         int *probe_n, size_t (*probe_i)[SOLID_PROBE_TIES])
{
    for (int k = 0; k < s->nprobes; k++) {
        const struct solid_probe_def *p = &s->probes[k];
        probe_n[k] = 0;
        if (p->kind > SOLID_PROBE_Y)
            continue; /* not a point probe */
        double best = INFINITY;
        for (size_t i = 0; i < n; i++)
            best = fmin(best, hypot(x0[i][0] - p->x, x0[i][1] - p->y));
        probe_n[k] = 0;
        for (size_t i = 0; i < n && probe_n[k] < SOLID_PROBE_TIES; i++)
            if (hypot(x0[i][0] - p->x, x0[i][1] - p->y) <= best + 1e-6 * s->dp)
                probe_i[k][probe_n[k]++] = i;
    }
}

double solid_probe_value(const struct solid_scene *s, int k, const int *probe_n,
                         const size_t (*probe_i)[SOLID_PROBE_TIES], const double (*x)[MPS_DIM],
                         const double (*x0)[MPS_DIM], const struct solid_load_probes *lp,
                         const int *body)
{
    if (solid_probe_is_load(s->probes[k].kind))
        return solid_load_probes_value(lp, s, k, body, x);
    double sum = 0.0;
    for (int a = 0; a < probe_n[k]; a++) {
        size_t i = probe_i[k][a];
        switch (s->probes[k].kind) {
        case SOLID_PROBE_DX: sum += x[i][0] - x0[i][0]; break;
        case SOLID_PROBE_DY: sum += x[i][1] - x0[i][1]; break;
        case SOLID_PROBE_X: sum += x[i][0]; break;
        case SOLID_PROBE_Y: sum += x[i][1]; break;
        case SOLID_PROBE_TANK_ANGLE:
        case SOLID_PROBE_ENERGY: return NAN; /* the model's own (solid_mps.c, solid_tlsph.c) */
        default: break;                      /* the load kinds, above */
        }
    }
    return probe_n[k] ? sum / probe_n[k] : NAN;
}


enum mps_status solid_loads_accel(const struct solid_scene *s, const int *body, size_t n,
                                  const struct solid_loads *f, double (*aload)[MPS_DIM],
                                  struct mps_err *err)
{
    memset(aload, 0, n * sizeof *aload);
    if (!f || f->n == 0)
        return MPS_OK;
    /* PROTOCOL.md 5: ids are unique within a message; a receiver rejects a
     * duplicate rather than keep one of the two loads */
    unsigned char *seen = calloc(n ? n : 1, 1);
    if (!seen)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory (%zu load marks)", n);
    enum mps_status st = MPS_OK;
    for (size_t k = 0; k < f->n; k++) {
        int i = f->id[k];
        if (i < 0 || (size_t)i >= n) {
            st = mps_err_set(err, MPS_EINPUT, "solid: load on unknown particle id %d "
                             "(ids are 0..%zu)", i, n - 1);
            break;
        }
        if (seen[i]++) {
            st = mps_err_set(err, MPS_EINPUT, "solid: two loads on particle id %d", i);
            break;
        }
        double m = s->bodies[body[i]].rho * s->dp * s->dp; /* V = dp^2 per metre depth */
        for (int a = 0; a < MPS_DIM; a++)
            aload[i][a] = f->force[k][a] / m;
    }
    free(seen);
    return st;
}
