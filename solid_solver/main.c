/* solid_solver: the solid alone.
 *   solid_solver CASE.yml --out DIR [--set key=value]... [--quiet] [--model NAME]
 * Steps the chosen model with its own stable step up to end_time, landing
 * exactly on every snapshot and probe time, and writes DIR/solid_*.h5 +
 * solid.xmf, DIR/probes.csv and DIR/summary.json.
 *   solid_solver [--model NAME] --connect ENDPOINT [--timeout S]
 * runs under the coupler (proto/PROTOCOL.md, solid_peer.c). --model NAME is
 * --set solid.model=NAME, so the files record the model that ran. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_case.h"
#include "mps_cli.h"
#include "mps_h5.h"
#include "mps_host.h"
#include "mps_json.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_prov.h"
#include "mps_restart.h"
#include "mps_timer.h"
#include "mps_version.h"
#include "proto_solver.h"
#include "solid_model.h"
#include "solid_peer.h"
#include "solid_scene.h"

static const char usage[] =
    "usage: solid_solver CASE.yml --out DIR [--set key=value]... [--quiet] [--model NAME]\n"
    "       solid_solver [--model NAME] --connect ENDPOINT [--timeout S]   (under the coupler)\n"
    "Runs the elastic solid of a case alone (keys dp, end_time, gravity.*, output.*, solid.*),\n"
    "or as the coupler's solid: the coupler starts it with --connect (its --solid \"COMMAND\"\n"
    "or the case key solid_solver names the command, e.g. \"solid_solver --model tlsph\").";

#define MAX_FIELDS 24

struct run {
    const struct solid_model_ops *ops;
    void *model;
    struct mps_h5_series *h5;
    struct mps_probes *probes;
    double *pvals;
    int nprobes;
    double t_output;   /* wall seconds spent writing */
    /* checkpoints (docs/restart.md) */
    struct mps_ckpt disk;
    struct mps_run_mark mark;
    long checkpoints;
    double t_checkpoint;
    double stopped_at;        /* --stop-at stopped the run here, or -1 */
    char restart_path[4400];  /* the checkpoint restarted from, or "" */
    double restart_time;
    long step_start;          /* its step: the timings are this process's steps' */
    char restart_arith[256];  /* what differs from its run's arithmetic, or "" */
};

static enum mps_status write_checkpoint(struct run *r, const char *dir, const char *yaml,
                                        double t, long step, struct mps_err *err)
{
    double w0 = mps_wall_seconds();
    r->mark.number++;
    r->mark.steps = step;
    r->mark.table_bytes[0] = mps_probes_bytes(r->probes);
    enum mps_status st = mps_run_checkpoint(&r->disk, dir, "solid", yaml, &r->mark, r->h5, t,
                                            r->ops->state_put, r->model, err);
    r->checkpoints += st == MPS_OK;
    r->t_checkpoint += mps_wall_seconds() - w0;
    return st;
}

static enum mps_status write_snapshot(struct run *r, double t, long step, struct mps_err *err)
{
    return solid_model_snapshot(r->ops, r->model, r->h5, t, step, &r->t_output, err);
}

static enum mps_status write_probes(struct run *r, double t, struct mps_err *err)
{
    for (int k = 0; k < r->nprobes; k++)
        r->pvals[k] = r->ops->probe_value(r->model, k);
    r->ops->probe_restart(r->model);
    return mps_probes_write(r->probes, t, r->pvals, err);
}

static enum mps_status write_summary(const struct run *r, const struct mps_case *c,
                                     const char *dir, size_t n, long steps, double t,
                                     double wall_loop, double wall_total, struct mps_err *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return mps_err_set(err, MPS_EIO, "cannot create '%s'", path);
    struct mps_json j;
    mps_json_begin(&j, f);
    mps_json_str(&j, "solver", "solid_solver");
    mps_json_str(&j, "version", MPS_VERSION);
    mps_json_str(&j, "git_rev", mps_git_rev);
    char host[256];
    mps_host_describe(host, sizeof host);
    mps_json_str(&j, "host", host);   /* the timings below are this machine's */
    mps_json_str(&j, "case", mps_case_path(c));
    mps_prov_json(c, &j);
    mps_json_str(&j, "model", r->ops->name);
    mps_json_int(&j, "particles", (long long)n);
    /* steps from the run's start; the timings are this process's steps' */
    mps_json_int(&j, "steps", steps);
    mps_json_int(&j, "steps_run", steps - r->step_start);
    mps_json_num(&j, "time", t);
    mps_json_num(&j, "wall_seconds", wall_total);
    mps_json_num(&j, "step_seconds", wall_loop);
    mps_json_num(&j, "output_seconds", r->t_output);
    mps_json_int(&j, "checkpoints", r->checkpoints);
    mps_json_num(&j, "checkpoint_seconds", r->t_checkpoint);
    mps_json_int(&j, "checkpoint_bytes", (long long)r->disk.len);
    if (r->stopped_at >= 0.0)
        mps_json_num(&j, "stopped_at", r->stopped_at);
    if (r->restart_path[0]) {
        mps_json_object(&j, "restart");
        mps_json_str(&j, "checkpoint", r->restart_path);
        mps_json_num(&j, "time", r->restart_time);
        mps_json_int(&j, "step", r->step_start);
        if (r->restart_arith[0])
            mps_json_str(&j, "arith_differs", r->restart_arith);
        mps_json_close(&j);
    }
    double ps = (double)n * (double)(steps - r->step_start);
    mps_json_num(&j, "ns_per_particle_step", ps > 0 ? 1e9 * wall_loop / ps : NAN);
    mps_json_num(&j, "particle_steps_per_second", wall_loop > 0 ? ps / wall_loop : NAN);
    mps_json_object(&j, "solid");
    r->ops->summary(r->model, &j);
    mps_json_close(&j);
    mps_json_object(&j, "probes");
    for (int k = 0; k < r->nprobes; k++)
        mps_json_num(&j, r->ops->probe_name(r->model, k), r->pvals[k]);
    mps_json_close(&j);
    mps_json_end(&j);
    if (fclose(f) != 0)
        return mps_err_set(err, MPS_EIO, "cannot write '%s'", path);
    return MPS_OK;
}

/* k-th event time of a period (products, not sums: no drift). */
static double event(long k, double period)
{
    return period > 0.0 ? (double)k * period : INFINITY;
}

static enum mps_status run(const struct mps_cli *cli, const char *model_name,
                           struct mps_err *err)
{
    double wall_start = mps_wall_seconds();
    const char *const ignore[] = {"fluid.", "coupling.", NULL};
    if (model_name && !solid_model_find(model_name))
        return mps_err_set(err, MPS_EINPUT, "--model %s: unknown solid model (known: %s)",
                           model_name, solid_model_names());
    /* --model is solid.model (after the user's --set), and this command is
     * the run's record: the files say what ran */
    const char *sets[MPS_CLI_MAX_SETS + 1 + MPS_PROV_NSETS];
    char model_set[64];
    int nsets = 0;
    for (int k = 0; k < cli->nsets; k++)
        sets[nsets++] = cli->sets[k];
    if (model_name) {
        snprintf(model_set, sizeof model_set, "solid.model=%s", model_name);
        sets[nsets++] = model_set;
    }
    mps_prov_sets(sets, &nsets, MPS_CLI_MAX_SETS + 1 + MPS_PROV_NSETS);
    struct mps_case *c = NULL;
    struct run r = {.stopped_at = -1.0};
    /* --restart: the case the checkpoint holds (mps_restart.h) */
    const char *case_path = cli->case_path;
    char restart_case[4400];
    enum mps_status st = MPS_OK;
    if (cli->restart_dir) {
        if (model_name)
            st = mps_err_set(err, MPS_EINPUT, "--model with --restart: the model is the "
                             "checkpoint's");
        else
            st = mps_run_restart_open(&r.disk, cli, "solid", restart_case, sizeof restart_case,
                                      &r.mark, err);
        if (st) {
            mps_ckpt_free(&r.disk);
            return st;
        }
        case_path = restart_case;
        mps_ckpt_path(r.restart_path, sizeof r.restart_path, cli->restart_dir, "solid",
                      r.mark.number);
        r.restart_time = r.disk.time;
    }
    st = mps_case_load(&c, case_path, sets, nsets, solid_case_tables, SOLID_NTABLES, ignore, err);
    if (st != MPS_OK) {
        mps_ckpt_free(&r.disk);
        return st;
    }
    char *yaml = NULL;
    /* solid.model's choices are the models' names */
    r.ops = solid_model_find(mps_case_string(c, "solid.model"));
    if (!cli->out_dir) {
        st = mps_err_set(err, MPS_EINPUT, "missing --out DIR (see --help)");
        goto done;
    }
    if ((st = solid_model_open(&r.ops, &r.model, c, err)) != MPS_OK ||
        (st = solid_model_check_step(r.ops, r.model, c, err)) != MPS_OK)
        goto done;
    if ((st = mps_mkdir_p(cli->out_dir, err)) != MPS_OK)
        goto done;

    const double end = mps_case_double(c, "end_time");
    const double out_dt = mps_case_double(c, "output.interval");
    const double probe_dt = mps_case_double(c, "output.probe_interval");
    const double ck_dt = mps_case_double(c, "output.checkpoint_interval");
    yaml = mps_case_resolved_yaml(c);
    if (out_dt > 0.0 &&
        (st = mps_h5_open(&r.h5, cli->out_dir, "solid", "solid_solver", yaml, err)) != MPS_OK)
        goto done;
    r.nprobes = r.ops->probe_count(r.model);
    const char **names = calloc((size_t)r.nprobes + 1, sizeof *names);
    r.pvals = calloc((size_t)r.nprobes + 1, sizeof *r.pvals);
    if (!names || !r.pvals) {
        free(names);
        st = mps_err_set(err, MPS_ENOMEM, "out of memory");
        goto done;
    }
    for (int k = 0; k < r.nprobes; k++)
        names[k] = r.ops->probe_name(r.model, k);
    if ((st = mps_probes_check_names(names, r.nprobes, mps_case_path(c), err)))
        goto done;
    char path[4096];
    snprintf(path, sizeof path, "%s/probes.csv", cli->out_dir);
    if (cli->restart_dir) {
        st = mps_probes_resume(&r.probes, path, r.mark.table_bytes[0], r.nprobes, err);
    } else {
        char *comment = mps_prov_comment(c, "solid_solver");
        st = mps_probes_open(&r.probes, path, comment, names, r.nprobes, err);
        free(comment);
    }
    free(names);
    if (st != MPS_OK)
        goto done;
    /* a block out of place: a checkpoint of another build (a field added) */
    if (cli->restart_dir && ((st = mps_run_get_rest(&r.disk, r.h5, err)) != MPS_OK ||
                             (st = r.ops->state_get(r.model, &r.disk, err)) != MPS_OK)) {
        mps_err_prefix(err, "%s: ", r.restart_path);
        goto done;
    }
    if (cli->restart_dir)
        mps_run_arith_check(&r.disk, "solid_solver", r.restart_path, r.restart_arith,
                            sizeof r.restart_arith);
    if (!r.ops->state_put && ck_dt > 0.0) {
        st = mps_err_set(err, MPS_EINPUT, "output.checkpoint_interval = %g: the solid model %s "
                         "cannot checkpoint (set it to 0)", ck_dt, r.ops->name);
        goto done;
    }

    const double(*x)[MPS_DIM] = NULL;
    struct mps_field f[MAX_FIELDS];
    int nf = 0;
    size_t n = r.ops->snapshot(r.model, &x, f, MAX_FIELDS, &nf);
    const double dt_stable = r.ops->stable_dt(r.model);
    if (!cli->quiet)
        fprintf(stderr, "solid_solver: %s, model %s, %zu particles, dt = %.4g s, %.0f steps\n",
                mps_case_path(c), r.ops->name, n, dt_stable, ceil(end / dt_stable));

    struct mps_progress prog;
    mps_progress_init(&prog, "solid", end, cli->quiet);
    double t = 0.0, wall_loop = 0.0;
    long step = 0, kout = 1, kprobe = 1, kck = 1;
    double last_snapshot = -1.0;
    const double eps = 1e-9 * end;
    if (cli->restart_dir) {
        /* exactly where the checkpointed run was, its next events included */
        t = r.disk.time;
        step = r.step_start = r.mark.steps;
        kout = r.mark.out_k;
        kprobe = r.mark.probe_k;
        kck = r.mark.ck_k;
        if (!cli->quiet)
            fprintf(stderr, "solid_solver: restarting %s at t = %.9g s (step %ld)\n",
                    cli->restart_dir, t, step);
    } else {
        if (r.h5 && (st = write_snapshot(&r, t, step, err)) != MPS_OK)
            goto done;
        last_snapshot = 0.0;
        if ((st = write_probes(&r, t, err)) != MPS_OK)
            goto done;
    }
    while (t < end) {
        double t_out = event(kout, out_dt), t_probe = event(kprobe, probe_dt);
        double target = fmin(fmin(t_out, t_probe), end);
        /* Equal steps that land exactly on the next event. */
        double nsub = ceil((target - t) / dt_stable * (1.0 - 1e-12));
        if (nsub < 1.0)
            nsub = 1.0;
        double dt = (target - t) / nsub;
        double w0 = mps_wall_seconds();
        for (long k = 0; k < (long)nsub && st == MPS_OK; k++) {
            st = r.ops->advance(r.model, dt, err);
            if ((k & 1023) == 1023)
                mps_progress_update(&prog, t + (double)(k + 1) * dt, step + k + 1);
        }
        wall_loop += mps_wall_seconds() - w0;
        step += (long)nsub;
        if (st != MPS_OK)
            goto done;
        t = target;
        if (t >= t_probe) {
            if ((st = write_probes(&r, t, err)) != MPS_OK)
                goto done;
            kprobe++;
        }
        if (r.h5 && (t >= t_out || t >= end) && last_snapshot != t) {
            if ((st = write_snapshot(&r, t, step, err)) != MPS_OK)
                goto done;
            last_snapshot = t;
        }
        if (t >= t_out)
            kout++;
        /* after the outputs of t, which the checkpoint then includes */
        r.mark.out_k = kout;
        r.mark.probe_k = kprobe;
        if (mps_run_due(&kck, ck_dt, t, eps) && t < end - eps) {
            r.mark.ck_k = kck;
            if ((st = write_checkpoint(&r, cli->out_dir, yaml, t, step, err)) != MPS_OK)
                goto done;
            if (t >= cli->stop_at - eps) {
                r.stopped_at = t;
                break;
            }
        }
        mps_progress_update(&prog, t, step);
    }
    mps_progress_finish(&prog, t, step);
    st = write_summary(&r, c, cli->out_dir, n, step, t, wall_loop,
                       mps_wall_seconds() - wall_start, err);
    if (st == MPS_OK && !cli->quiet) {
        const long steps_run = step - r.step_start; /* a restart's: the timings' */
        fprintf(stderr, "solid_solver: %ld steps in %.3g s, %.1f ns per particle-step\n",
                steps_run, wall_loop,
                steps_run > 0 ? 1e9 * wall_loop / ((double)n * (double)steps_run) : 0.0);
    }
done:
    mps_probes_close(&r.probes);
    mps_h5_close(&r.h5);
    free(r.pvals);
    free(yaml);
    mps_ckpt_free(&r.disk);
    if (r.ops && r.model)
        r.ops->destroy(&r.model);
    mps_case_destroy(&c);
    return st;
}

static volatile int stop_signal = 0;

static void on_signal(int sig)
{
    stop_signal = sig;
}

/* Under the coupler: solid_solver [--model NAME] --connect ENDPOINT. Without
 * --model the case's solid.model decides (read when CONFIG arrives). */
static int run_coupled(int argc, char **argv, const char *endpoint, int hello_ms)
{
    const struct solid_model_ops *ops = NULL;
    for (int i = 1; i + 1 < argc; i++)
        if (strcmp(argv[i], "--model") == 0 && !(ops = solid_model_find(argv[i + 1]))) {
            fprintf(stderr, "solid_solver: --model %s: unknown model (known: %s)\n", argv[i + 1],
                    solid_model_names());
            return 2;
        }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    return solid_peer_run(endpoint, ops, hello_ms, &stop_signal);
}

int main(int argc, char **argv)
{
    mps_prov_init(argc, argv);
    struct mps_cli cli;
    struct mps_err err = {0};
    const char *endpoint = NULL;
    int hello_ms = 0, coupled = proto_solver_args(argc, argv, &endpoint, &hello_ms, &err);
    if (coupled < 0) {
        fprintf(stderr, "solid_solver: %s\n", err.msg);
        return 2;
    }
    if (coupled)
        return run_coupled(argc, argv, endpoint, hello_ms);
    struct mps_cli_extra extra[] = {
        {"--model", 1, "solid model (default: the case's solid.model)", NULL},
    };
    enum mps_status st = mps_cli_parse(&cli, argc, argv, extra, 1, usage, &err);
    if (st == MPS_EINTR) {
        if (cli.keys) {
            const char *const titles[SOLID_NTABLES] = {
                MPS_CASE_COMMON_KEYS_TITLE,
                "solid_solver: `solid.*` (both models, `mps` and `tlsph`)", MPS_MOTION_KEYS_TITLE};
            mps_case_print_keys(stdout, solid_case_tables, titles, SOLID_NTABLES);
        }
        return 0; /* --help, --version, --keys */
    }
    if (st == MPS_OK)
        st = run(&cli, extra[0].value, &err);
    if (st != MPS_OK)
        fprintf(stderr, "solid_solver: %s\n", err.msg);
    return mps_status_exit_code(st);
}
