/* A fake solid for coupling tests (no solid physics): the first body of the
 * case as a rigid lattice of particles moving on a prescribed path
 *   x(t) = x0 + A sin(2 pi f t),
 * that reports the total fluid force it receives as probes (plate_fx,
 * plate_fy: the force of the last step; plate_dx; tip_EI: the quasi-static
 * tip deflection those loads would give a cantilever clamped at the top of
 * the case's first clamp, times its E I (N m^2 per metre):
 * sum_k f_x,k a_k^2 (3 L - a_k) / 6, a_k the particle's height above the
 * clamp, L the free length (Euler-Bernoulli; docs/hard_cases.md, the stiff
 * plate against the rigid limit)), followed by the case's solid.probes
 * through the scene-level probe code every solid model uses (solid_scene.h,
 * solid_loadprobe.h: force_x, force_y, moment as means over each probe
 * interval). It speaks the protocol through proto_solver like the real
 * solids do.
 *   fake_solid [--amplitude A] [--frequency F] [--fail-at T] [--version V]
 *              --connect ENDPOINT
 * --fail-at T makes it crash (abort) at time T, for the coupler's failure
 * tests; --hang-at T makes it stop answering at time T, --hang-in hello
 * before it connects, --hang-in ready after CONFIG (before READY). With
 * --hang-mark FILE it writes the wall-clock second (CLOCK_REALTIME, as
 * Python's time.time()) at which it stops answering into FILE, so a test
 * measures the coupler's deadline from there. It can repeat a step (implicit
 * coupling: its state is a function of time, so there is nothing to keep);
 * --no-rollback makes it a solver that cannot (no caps=rollback in HELLO),
 * which the coupler must refuse when implicit coupling is asked. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mps_case.h"
#include "mps_cli.h"
#include "proto_solver.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include "solid_loadprobe.h"
#include "solid_scene.h"

#define FIXED_PROBES 4

struct fake {
    double amp, freq, fail_at, hang_at;
    const char *hang_in;   /* "hello", "ready" or NULL */
    const char *hang_mark; /* file for the time the hang began, or NULL */
    double dp;
    size_t n;
    int *id;
    double (*x0)[2], (*x)[2], (*v)[2];
    unsigned char *surface, *fixed;
    double force[2];
    double tip_ei;             /* see the header */
    double yc, len;            /* clamp top, free length (m) */
    double t;
    /* the case's probes */
    struct solid_scene scene;
    int *body;                      /* all 0: the fake is body 0 */
    int probe_n[SOLID_MAX_PROBES];
    size_t probe_i[SOLID_MAX_PROBES][SOLID_PROBE_TIES];
    struct solid_load_probes loadprobes;
    char names[4096];
    double probes[FIXED_PROBES + SOLID_MAX_PROBES];
};

static void place(struct fake *s, double t)
{
    double w = 2.0 * M_PI * s->freq;
    double dx = s->amp * sin(w * t), vx = s->amp * w * cos(w * t);
    for (size_t i = 0; i < s->n; i++) {
        s->x[i][0] = s->x0[i][0] + dx;
        s->x[i][1] = s->x0[i][1];
        s->v[i][0] = vx;
        s->v[i][1] = 0.0;
    }
}

/* Stops answering for good, after writing the time into s->hang_mark. */
static void hang(const struct fake *s)
{
    if (s->hang_mark) {
        struct timespec now;
        clock_gettime(CLOCK_REALTIME, &now);
        FILE *f = fopen(s->hang_mark, "w");
        if (f) {
            fprintf(f, "%.6f\n", (double)now.tv_sec + 1e-9 * (double)now.tv_nsec);
            fclose(f);
        }
    }
    for (;;)
        pause();
}

static enum mps_status configure(void *self, const char *case_path, const char *out,
                                 const char *prefix, struct mps_err *err)
{
    struct fake *s = self;
    if (s->hang_in && !strcmp(s->hang_in, "ready"))
        hang(s);
    struct mps_case *c = NULL;
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, solid_case_keys};
    /* motion: a moving case never reaches here (CONFIG motion is refused) */
    const char *const ignore[] = {"fluid.", "coupling.", "motion.", NULL};
    enum mps_status st = mps_case_load(&c, case_path, NULL, 0, tables, 2, ignore, err);
    if (!st)
        st = solid_scene_read(&s->scene, c, err);
    if (st) { /* a problem with its keys is a case error (PROTOCOL.md 4, 8) */
        mps_case_destroy(&c);
        return proto_solver_case_error(st, err);
    }
    s->dp = mps_case_double(c, "dp");
    double b[4] = {mps_case_double(c, "solid.bodies.0.x0"), mps_case_double(c, "solid.bodies.0.y0"),
                   mps_case_double(c, "solid.bodies.0.x1"), mps_case_double(c, "solid.bodies.0.y1")};
    /* the clamp's top: the top of the highest row whose centres it covers */
    double cy1 = mps_case_count(c, "solid.clamps") ? mps_case_double(c, "solid.clamps.0.y1") : b[1];
    mps_case_destroy(&c);
    s->yc = b[1];
    for (long j = 0; b[1] + (j + 0.5) * s->dp <= cy1; j++)
        s->yc = b[1] + (j + 1.0) * s->dp;
    s->len = b[3] - s->yc;
    long nx = (long)floor((b[2] - b[0]) / s->dp + 1e-6), ny = (long)floor((b[3] - b[1]) / s->dp + 1e-6);
    s->n = (size_t)(nx * ny);
    s->id = calloc(s->n, sizeof *s->id);
    s->x0 = calloc(s->n, sizeof *s->x0);
    s->x = calloc(s->n, sizeof *s->x);
    s->v = calloc(s->n, sizeof *s->v);
    s->surface = calloc(s->n, 1);
    s->fixed = calloc(s->n, 1);
    s->body = calloc(s->n, sizeof *s->body);
    if (!s->id || !s->x0 || !s->x || !s->v || !s->surface || !s->fixed || !s->body)
        return mps_err_set(err, MPS_ENOMEM, "fake solid: out of memory");
    size_t k = 0;
    for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++, k++) {
            s->id[k] = (int)k;
            s->x0[k][0] = b[0] + (i + 0.5) * s->dp;
            s->x0[k][1] = b[1] + (j + 0.5) * s->dp;
            /* the bottom face stands on the floor, but the bottom row's
             * side faces are wet (the fluid leaves out a row sunk into the
             * floor: fluid_coupling.c, in_walls) */
            s->surface[k] = i == 0 || i == nx - 1 || j == ny - 1;
        }
    place(s, 0.0);
    solid_probes_locate(&s->scene, s->n, (const double(*)[2])s->x0, s->probe_n, s->probe_i);
    solid_load_probes_init(&s->loadprobes, &s->scene);
    const char *names[FIXED_PROBES + SOLID_MAX_PROBES] = {"plate_fx", "plate_fy", "plate_dx",
                                                               "tip_EI"};
    for (int q = 0; q < s->scene.nprobes; q++)
        names[FIXED_PROBES + q] = s->scene.probes[q].name;
    proto_join_names(names, FIXED_PROBES + s->scene.nprobes, s->names, sizeof s->names);
    (void)out;
    (void)prefix;
    return MPS_OK;
}

static void fill_state(struct fake *s, struct proto_msg *m)
{
    m->payload = PROTO_STATE;
    m->count = s->n;
    m->id = s->id;
    m->x = (const double(*)[2])s->x;
    m->v = (const double(*)[2])s->v;
    m->surface = s->surface;
    m->fixed = s->fixed;
    m->dt = 1.0; /* a rigid path has no stability limit */
}

static enum mps_status ready(void *self, struct proto_msg *reply, struct mps_err *err)
{
    struct fake *s = self;
    fill_state(s, reply);
    reply->nprobes = FIXED_PROBES + s->scene.nprobes;
    reply->text = s->names;
    (void)err;
    return MPS_OK;
}

static enum mps_status advance(void *self, const struct proto_msg *in, struct proto_msg *reply,
                               struct mps_err *err)
{
    struct fake *s = self;
    if (s->fail_at >= 0.0 && in->time >= s->fail_at)
        abort(); /* a crash, as a buggy solver would */
    if (s->hang_at >= 0.0 && in->time >= s->hang_at)
        hang(s);
    s->force[0] = s->force[1] = s->tip_ei = 0.0;
    struct solid_loads loads = {0};
    if (in->payload == PROTO_LOADS) {
        for (size_t k = 0; k < in->count; k++) {
            if (in->id[k] < 0 || (size_t)in->id[k] >= s->n)
                return mps_err_set(err, MPS_EINPUT, "fake solid: load on unknown id %d",
                                   in->id[k]);
            s->force[0] += in->force[k][0];
            s->force[1] += in->force[k][1];
            int i = in->id[k];
            if (i >= 0 && (size_t)i < s->n) {
                double a = fmin(fmax(s->x0[i][1] - s->yc, 0.0), s->len);
                s->tip_ei += in->force[k][0] * a * a * (3.0 * s->len - a) / 6.0;
            }
        }
        loads = (struct solid_loads){in->count, in->id, in->pressure, in->force};
    }
    enum mps_status st = solid_load_probes_set(&s->loadprobes, &loads, err);
    if (st)
        return st;
    /* one step of dt from the positions the loads were computed at */
    solid_load_probes_step(&s->loadprobes, &s->scene, s->body, (const double(*)[2])s->x, in->dt);
    s->t = in->time + in->dt;
    place(s, s->t);
    fill_state(s, reply);
    if (in->flags & PROTO_F_PROBES) {
        s->probes[0] = s->force[0];
        s->probes[1] = s->force[1];
        s->probes[2] = s->x[0][0] - s->x0[0][0];
        s->probes[3] = s->tip_ei;
        for (int k = 0; k < s->scene.nprobes; k++)
            s->probes[FIXED_PROBES + k] = solid_probe_value(
                &s->scene, k, s->probe_n, (const size_t(*)[SOLID_PROBE_TIES])s->probe_i,
                (const double(*)[2])s->x, (const double(*)[2])s->x0, &s->loadprobes, s->body);
        solid_load_probes_restart(&s->loadprobes);
        reply->nprobes = FIXED_PROBES + s->scene.nprobes;
        reply->probes = s->probes;
    }
    return MPS_OK;
}

/* The path is a function of time: a repeated step needs only the load
 * probes' means restored. */
static struct solid_load_probes_mark kept_loadprobes;

static enum mps_status save(void *self, struct mps_err *err)
{
    solid_load_probes_keep(&((struct fake *)self)->loadprobes, &kept_loadprobes);
    (void)err;
    return MPS_OK;
}

static enum mps_status restore(void *self, struct mps_err *err)
{
    solid_load_probes_back(&((struct fake *)self)->loadprobes, &kept_loadprobes);
    (void)err;
    return MPS_OK;
}

static struct proto_solver_stats stats;

static char *finish(void *self, enum mps_status st, const struct mps_err *err)
{
    (void)self;
    (void)err;
    char *j = malloc(256);
    if (j)
        snprintf(j, 256, "{\"solver\": \"fake_solid\", \"status\": \"%s\", \"compute_seconds\": %.9g}",
                 mps_status_name(st), stats.compute_seconds);
    return j;
}

static volatile int stop_flag = 0;

int main(int argc, char **argv)
{
    struct fake s = {.amp = 0.0, .freq = 1.0, .fail_at = -1.0, .hang_at = -1.0};
    int rollback = 1;
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--no-rollback"))
            rollback = 0;
    for (int i = 1; i + 1 < argc; i++) {
        if (!strcmp(argv[i], "--amplitude"))
            s.amp = atof(argv[++i]);
        else if (!strcmp(argv[i], "--frequency"))
            s.freq = atof(argv[++i]);
        else if (!strcmp(argv[i], "--fail-at"))
            s.fail_at = atof(argv[++i]);
        else if (!strcmp(argv[i], "--hang-at"))
            s.hang_at = atof(argv[++i]);
        else if (!strcmp(argv[i], "--hang-in"))
            s.hang_in = argv[++i];
        else if (!strcmp(argv[i], "--hang-mark"))
            s.hang_mark = argv[++i];
    }
    const char *endpoint = NULL;
    int hello_ms;
    struct mps_err err = {0};
    if (proto_solver_args(argc, argv, &endpoint, &hello_ms, &err) != 1) {
        fprintf(stderr, "fake_solid: %s\n", err.msg[0] ? err.msg : "needs --connect ENDPOINT");
        return 2;
    }
    if (s.hang_in && !strcmp(s.hang_in, "hello"))
        hang(&s);
    /* a rigid plate fixed in the tank: it has no body forces to move
     * (moving_frame 0) */
    static const struct proto_solver_ops ops = {"solid", "fake", configure, ready,
                                                advance, finish,  save,      restore, 0,
                                                NULL,    NULL,    NULL};
    static const struct proto_solver_ops ops_fixed = {"solid", "fake", configure,
                                                      ready,   advance, finish, NULL, NULL, 0,
                                                      NULL,    NULL,    NULL};
    enum mps_status st = proto_solver_run(endpoint, rollback ? &ops : &ops_fixed, &s, hello_ms,
                                          &stop_flag, &stats, &err);
    if (st && !stats.coupler_reports) /* else the coupler said it, as the solvers do */
        fprintf(stderr, "fake_solid: %s: %s\n", mps_status_name(st), err.msg);
    free(s.id);
    free(s.x0);
    free(s.x);
    free(s.v);
    free(s.surface);
    free(s.fixed);
    free(s.body);
    solid_load_probes_free(&s.loadprobes);
    return mps_status_exit_code(st);
}
