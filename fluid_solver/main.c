/* fluid_solver: the semi-implicit MPS fluid as a program.
 *   fluid_solver CASE.yml --out DIR [--set key=value]... [--quiet]
 * runs a fluid-only case standalone. Exit codes: 0 done, 2 bad input,
 * 1 failure (diverged, I/O, library), 130 interrupted. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "fluid_ppe.h"
#include "mps_case.h"
#include "mps_cli.h"
#include "mps_json.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_timer.h"

static volatile sig_atomic_t stop_signal = 0;

static void on_signal(int sig)
{
    stop_signal = sig;
}

struct run {
    struct mps_case *cs;
    struct fluid *f;
    struct mps_h5_series *h5;
    struct mps_probes *probes;
    const char *out;
    double wall0, t_output;
    int quiet;
};

static enum mps_status write_snapshot(struct run *r, struct mps_err *err)
{
    double t0 = mps_wall_seconds();
    struct mps_field fields[MPS_PARTICLES_MAX_FIELDS];
    int nf = fluid_output_fields(r->f, fields, MPS_PARTICLES_MAX_FIELDS);
    enum mps_status st = mps_h5_write(r->h5, r->f->time, r->f->step, r->f->ps.n,
                                      (const double(*)[MPS_DIM])r->f->x, fields, nf, err);
    r->t_output += mps_wall_seconds() - t0;
    return st;
}

static enum mps_status write_probes(struct run *r, struct mps_err *err)
{
    double v[FLUID_MAX_PROBES];
    for (int k = 0; k < r->f->prm.nprobes; k++)
        v[k] = fluid_probe(r->f, k);
    return mps_probes_write(r->probes, r->f->time, v, err);
}

static void write_summary(const struct run *r, enum mps_status st, const struct mps_err *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/summary.json", r->out);
    FILE *fp = fopen(path, "w");
    if (!fp) {
        fprintf(stderr, "fluid_solver: warning: cannot write %s\n", path);
        return;
    }
    struct mps_json j;
    mps_json_begin(&j, fp);
    mps_json_str(&j, "solver", "fluid_solver");
    mps_json_str(&j, "version", MPS_VERSION);
    mps_json_str(&j, "git_rev", MPS_GIT_REV);
    mps_json_str(&j, "case", mps_case_path(r->cs));
    mps_json_str(&j, "status", mps_status_name(st));
    mps_json_str(&j, "message", st ? err->msg : "");
    mps_json_num(&j, "wall_seconds", mps_wall_seconds() - r->wall0);
    mps_json_num(&j, "output_seconds", r->t_output);
    if (r->f)
        fluid_summary(r->f, &j);
    mps_json_end(&j);
    fclose(fp);
}

/* The next step: the CFL step, shortened so output times are hit exactly and
 * no sliver of a step is left before them. */
static double next_dt(const struct fluid *f, double t_next)
{
    double dt = fluid_cfl_dt(f), left = t_next - f->time;
    if (left <= dt * (1.0 + 1e-9))
        return left;
    if (left < 2.0 * dt)
        return 0.5 * left;
    return dt;
}

static enum mps_status run_standalone(struct run *r, struct mps_err *err)
{
    const struct fluid_params *p = &r->f->prm;
    struct mps_progress prog;
    mps_progress_init(&prog, "fluid", p->end_time, r->quiet);
    enum mps_status st;
    if (p->output_interval > 0.0 && (st = write_snapshot(r, err)))
        return st;
    if ((st = write_probes(r, err)))
        return st;
    long out_k = 1, probe_k = 1;
    const double eps = 1e-9 * p->end_time;
    while (r->f->time < p->end_time - eps) {
        if (stop_signal)
            return mps_err_set(err, MPS_EINTR, "interrupted by signal %d at t = %.6g s",
                               (int)stop_signal, r->f->time);
        double t_out = p->output_interval > 0.0 ? out_k * p->output_interval : INFINITY;
        double t_next = fmin(t_out, p->end_time);
        if ((st = fluid_step(r->f, next_dt(r->f, t_next), err)))
            return st;
        if (r->f->time >= probe_k * p->probe_interval - eps) {
            if ((st = write_probes(r, err)))
                return st;
            while (probe_k * p->probe_interval <= r->f->time + eps)
                probe_k++;
        }
        if (r->f->time >= t_out - eps) {
            if ((st = write_snapshot(r, err)))
                return st;
            out_k++;
        }
        mps_progress_update(&prog, r->f->time, r->f->step);
    }
    mps_progress_finish(&prog, r->f->time, r->f->step);
    return MPS_OK;
}

int main(int argc, char **argv)
{
    struct mps_err err = {0};
    struct mps_cli cli;
    struct mps_cli_extra extra[] = {
        {"--dump-ppe", 1, "write the PPE of step N as Matrix Market files into --out", NULL},
    };
    const char *usage = "usage: fluid_solver CASE.yml --out DIR [--set key=value]... [--quiet]";
    enum mps_status st = mps_cli_parse(&cli, argc, argv, extra, 1, usage, &err);
    if (st == MPS_EINTR)
        return 0; /* --help */
    if (st) {
        fprintf(stderr, "fluid_solver: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    struct run r = {.out = cli.out_dir ? cli.out_dir : "out", .quiet = cli.quiet};
    r.wall0 = mps_wall_seconds();
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, fluid_case_keys};
    const char *const ignore[] = {"solid.", "coupling.", NULL};
    st = mps_case_load(&r.cs, cli.case_path, cli.sets, cli.nsets, tables, 2, ignore, &err);
    if (st) {
        fprintf(stderr, "fluid_solver: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    struct fluid_params prm;
    if ((st = fluid_params_read(&prm, r.cs, &err)) || (st = mps_mkdir_p(r.out, &err)) ||
        (st = fluid_create(&r.f, &prm, &err))) {
        fprintf(stderr, "fluid_solver: %s\n", err.msg);
        mps_case_destroy(&r.cs);
        return mps_status_exit_code(st);
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);

    char *yaml = mps_case_resolved_yaml(r.cs);
    char path[4096];
    snprintf(path, sizeof path, "%s/probes.csv", r.out);
    const char *names[FLUID_MAX_PROBES];
    for (int k = 0; k < prm.nprobes; k++)
        names[k] = prm.probes[k].name;
    if (!(st = mps_h5_open(&r.h5, r.out, "fluid", "fluid_solver", yaml ? yaml : "", &err)) &&
        !(st = mps_probes_open(&r.probes, path, names, prm.nprobes, &err))) {
        if (extra[0].value) {
            /* benchmark aid: run to step N and dump its PPE */
            long target = atol(extra[0].value);
            while (!st && r.f->step < target)
                st = fluid_step(r.f, fluid_cfl_dt(r.f), &err);
            char mpath[4096], bpath[4096];
            snprintf(mpath, sizeof mpath, "%s/ppe_A.mtx", r.out);
            snprintf(bpath, sizeof bpath, "%s/ppe_b.mtx", r.out);
            if (!st)
                st = fluid_ppe_dump(r.f, mpath, bpath, &err);
        } else {
            st = run_standalone(&r, &err);
        }
    }
    free(yaml);
    if (st)
        fprintf(stderr, "\nfluid_solver: %s: %s\n", mps_status_name(st), err.msg);
    write_summary(&r, st, &err);
    mps_probes_close(&r.probes);
    mps_h5_close(&r.h5);
    fluid_destroy(&r.f);
    mps_case_destroy(&r.cs);
    return mps_status_exit_code(st);
}
