/* solid_static_load: the static deflection of one body of a case under a
 * hydrostatic load on its upstream (left) face, through the solid model
 * interface only (solid_model.h), for any model: docs/hard_cases.md, the
 * elastic gate against Timoshenko beam theory.
 *
 *   solid_static_load CASE.yml --body NAME --water-level H [--water-right H2]
 *       [--model mps|tlsph] [--load-scale S] [--damping C] [--max-time T]
 *       [--set key=value]...
 *
 * Every particle of the body's leftmost column below H gets the force
 * S rho_w g (H - y) dp (N/m, +x; rho_w = 1000, g = 9.81, y its initial
 * height), the pressure of still water of level H times the face it stands
 * for; with --water-right, the rightmost column below H2 gets
 * -S rho_w g (H2 - y) dp (water on both sides). Gravity on the solid is switched off (beam theory leaves out the
 * body's weight) unless --gravity keeps the case's: a soft upright plate's own
 * weight bends it further (beam-column, docs/hard_cases.md, the plate at rest). The body is brought to rest by a damping force -C m v on
 * every particle (C in 1/s; near twice the first bending frequency settles it
 * fastest), added to the loads each step, and stepped at the model's stable
 * step until the first probe moves less than 1e-7 of its value over 0.01 s
 * (or --max-time). Prints one JSON line: model, dp, particles, the probes at
 * rest, steps, simulated time, wall seconds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_case.h"
#include "mps_motion.h"
#include "mps_timer.h"
#include "solid_model.h"
#include "solid_scene.h"

#define RHO_W 1000.0
#define G 9.81
#define MAX_SETS 32

static int fail(const char *msg)
{
    fprintf(stderr, "solid_static_load: %s\n", msg);
    return 2;
}

int main(int argc, char **argv)
{
    const char *case_path = NULL, *body_name = NULL, *model = NULL;
    double level = NAN, right = -INFINITY, scale = 1.0, damping = 150.0, tmax = 2.0;
    const char *sets[MAX_SETS + 1];
    int nsets = 0, keep_gravity = 0;
    sets[nsets++] = "gravity.y=0";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--body") && v)
            body_name = argv[++i];
        else if (!strcmp(a, "--water-level") && v)
            level = atof(argv[++i]);
        else if (!strcmp(a, "--water-right") && v)
            right = atof(argv[++i]);
        else if (!strcmp(a, "--model") && v)
            model = argv[++i];
        else if (!strcmp(a, "--load-scale") && v)
            scale = atof(argv[++i]);
        else if (!strcmp(a, "--damping") && v)
            damping = atof(argv[++i]);
        else if (!strcmp(a, "--max-time") && v)
            tmax = atof(argv[++i]);
        else if (!strcmp(a, "--gravity"))
            keep_gravity = 1;
        else if (!strcmp(a, "--set") && v && nsets < MAX_SETS)
            sets[nsets++] = argv[++i];
        else if (a[0] != '-' && !case_path)
            case_path = a;
        else
            return fail("usage: solid_static_load CASE.yml --body NAME --water-level H "
                        "[--water-right H2] [--model mps|tlsph] [--load-scale S] [--damping C] "
                        "[--max-time T] [--gravity] [--set key=value]...");
    }
    if (!case_path || !body_name || !isfinite(level) || !(damping >= 0.0) || !(tmax > 0.0))
        return fail("needs CASE.yml, --body NAME and --water-level H (m); --damping >= 0, "
                    "--max-time > 0");

    struct mps_err err = {0};
    struct mps_case *cs = NULL;
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, solid_case_keys,
                                                 mps_motion_keys};
    const char *const ignore[] = {"fluid.", "coupling.", NULL};
    /* sets[0] is the switch-off of gravity */
    if (mps_case_load(&cs, case_path, sets + keep_gravity, nsets - keep_gravity, tables, 3, ignore,
                      &err))
        return fprintf(stderr, "solid_static_load: %s\n", err.msg), 2;
    struct solid_scene *sc = malloc(sizeof *sc);
    const struct solid_model_ops *ops =
        solid_model_find(model ? model : mps_case_string(cs, "solid.model"));
    void *m = NULL;
    int rc = 1;
    if (!sc || !ops || solid_scene_read(sc, cs, &err) || solid_model_open(&ops, &m, cs, &err)) {
        fprintf(stderr, "solid_static_load: %s\n", !sc ? "out of memory" : !ops ? "unknown model"
                                                                                : err.msg);
        goto done;
    }
    int b = -1;
    for (int k = 0; k < sc->nbodies; k++)
        if (!strcmp(sc->bodies[k].name, body_name))
            b = k;
    if (b < 0) {
        fprintf(stderr, "solid_static_load: no body '%s'\n", body_name);
        rc = 2;
        goto done;
    }
    /* every particle: the interface with a depth beyond the scene, in the
     * model's creation order (ids 0..n-1) */
    struct solid_iface all;
    if (ops->interface(m, 1e30, &all, &err))
        goto done;
    const size_t n = all.n;
    /* the interface is on the coupling lattice (solid.refine: solid_refine.h) */
    const double dp = sc->dp_coupling, x_face = sc->bodies[b].x0 + dp,
                 x_back = sc->bodies[b].x1 - dp;
    double *hydro = calloc(n, sizeof *hydro), *mass = calloc(n, sizeof *mass);
    double (*force)[MPS_DIM] = calloc(n, sizeof *force);
    int *id = malloc(n * sizeof *id);
    double *press = calloc(n, sizeof *press);
    if (!hydro || !mass || !force || !id || !press) {
        fprintf(stderr, "solid_static_load: out of memory\n");
        free(hydro), free(mass), free(force), free(id), free(press);
        goto done;
    }
    /* the body a particle belongs to, from where it started */
    for (size_t k = 0; k < n; k++) {
        const double *x = all.x[k];
        int body = -1;
        for (int q = 0; q < sc->nbodies && body < 0; q++)
            if (x[0] > sc->bodies[q].x0 && x[0] < sc->bodies[q].x1 && x[1] > sc->bodies[q].y0 &&
                x[1] < sc->bodies[q].y1)
                body = q;
        id[k] = all.id[k];
        mass[k] = (body >= 0 ? sc->bodies[body].rho : 0.0) * dp * dp;
        if (body == b && x[0] < x_face && x[1] < level)
            hydro[k] += scale * RHO_W * G * (level - x[1]) * dp;
        if (body == b && x[0] > x_back && x[1] < right)
            hydro[k] -= scale * RHO_W * G * (right - x[1]) * dp;
    }
    double t = 0.0, wall0 = mps_wall_seconds(), last = NAN, t_check = 0.01;
    long steps = 0;
    int settled = 0;
    while (t < tmax && !settled) {
        if (ops->interface(m, 1e30, &all, &err))
            break;
        for (size_t k = 0; k < n; k++) {
            force[k][0] = hydro[k] - damping * mass[k] * all.v[k][0];
            force[k][1] = -damping * mass[k] * all.v[k][1];
        }
        struct solid_loads loads = {n, id, press, (const double(*)[MPS_DIM])force};
        double h = ops->stable_dt(m);
        if (ops->set_loads(m, &loads, &err) || ops->advance(m, h, &err))
            break;
        t += h;
        steps++;
        if (t >= t_check) {
            double tip = ops->probe_value(m, 0);
            settled = fabs(tip - last) <= 1e-7 * fabs(tip);
            last = tip;
            t_check += 0.01;
        }
    }
    if (err.msg[0]) {
        fprintf(stderr, "solid_static_load: %s\n", err.msg);
    } else {
        printf("{\"model\": \"%s\", \"dp\": %g, \"particles\": %zu, \"load_scale\": %g, "
               "\"settled\": %s, \"steps\": %ld, \"time\": %g, \"wall_seconds\": %.3f, "
               "\"probes\": {",
               ops->name, dp, n, scale, settled ? "true" : "false", steps, t,
               mps_wall_seconds() - wall0);
        for (int k = 0; k < ops->probe_count(m); k++)
            printf("%s\"%s\": %.10g", k ? ", " : "", ops->probe_name(m, k),
                   ops->probe_value(m, k));
        printf("}}\n");
        rc = settled ? 0 : 1;
    }
    free(hydro), free(mass), free(force), free(id), free(press);
done:
    if (m)
        ops->destroy(&m);
    free(sc);
    mps_case_destroy(&cs);
    return rc;
}
