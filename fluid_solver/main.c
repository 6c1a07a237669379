/* fluid_solver: the semi-implicit MPS fluid as a program.
 *   fluid_solver CASE.yml --out DIR [--set key=value]... [--quiet]
 * runs a fluid-only case standalone;
 *   fluid_solver --connect ENDPOINT
 * runs under the coupler (proto/PROTOCOL.md). Exit codes: 0 done, 2 bad
 * input, 1 failure (diverged, I/O, library, protocol), 130 interrupted. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "fluid_checkpoint.h"
#include "fluid_ppe.h"
#include "mps_case.h"
#include "mps_cli.h"
#include "mps_host.h"
#include "mps_json.h"
#include "mps_omp.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_restart.h"
#include "mps_prov.h"
#include "mps_simd.h"
#include "mps_timer.h"
#include "mps_version.h"
#include "proto_solver.h"

static volatile int stop_signal = 0;

static void on_signal(int sig)
{
    stop_signal = sig;
}

struct run {
    struct mps_case *cs;
    struct mps_motion *motion; /* the tank's motion; the fluid borrows it */
    struct fluid *f;
    struct mps_h5_series *h5;
    struct mps_probes *probes;
    struct mps_probes *steps;   /* fluid.step_log */
    const char *out;
    double wall0, t_output;
    int quiet;
    const char *summary_name;
    int coupled;
    struct proto_solver_stats peer;
    /* loads on the solid surface, sent back each coupled step */
    int *load_id;
    double *load_p, (*load_f)[MPS_DIM];
    size_t load_cap;
    char out_buf[4096];
    char probe_names[4096];
    char cpu_note[96];   /* what mps_omp_bind_threads did (standalone runs) */
    char prefix[64];     /* of its files: "fluid" */
    /* implicit coupling: the state at the step's start, and the snapshots
     * written by then (a repeated step writes its snapshot again) */
    struct fluid_ckpt ckpt;
    int saved_snapshots;
    /* checkpoints (docs/restart.md): the image written, the resolved case it
     * carries, where the outputs stood at the last one */
    struct mps_ckpt disk;
    char *case_yaml;
    struct mps_run_mark mark;
    int resumed;            /* restarted: the outputs continue from mark */
    double stop_at;         /* --stop-at */
    int stopped;            /* stopped there */
    long checkpoints;       /* written by this process */
    double t_checkpoint;    /* wall seconds spent writing them */
    char restart_path[4400]; /* the checkpoint restarted from, or "" */
    double restart_time;
    char restart_arith[256]; /* what differs from its run's arithmetic, or "" */
};

/* The fluid and its tank, [0, nfixed_end): a coupled solid's particles, the
 * segment after them, are the solid's to write (its own snapshots carry them
 * with their own ids and fields); written here too they would repeat its ids
 * and show twice in scene.xmf. */
static enum mps_status write_snapshot(struct run *r, struct mps_err *err)
{
    double t0 = mps_wall_seconds();
    struct mps_field fields[MPS_PARTICLES_MAX_FIELDS];
    int nf = fluid_output_fields(r->f, fields, MPS_PARTICLES_MAX_FIELDS);
    enum mps_status st = mps_h5_write(r->h5, r->f->time, r->f->step, r->f->nfixed_end,
                                      (const double(*)[MPS_DIM])r->f->x, fields, nf, err);
    r->t_output += mps_wall_seconds() - t0;
    return st;
}

static enum mps_status write_probes(struct run *r, struct mps_err *err)
{
    double v[FLUID_MAX_PROBES];
    for (int k = 0; k < r->f->prm.nprobes; k++)
        v[k] = fluid_probe(r->f, k);
    fluid_probes_restart(r->f);
    return mps_probes_write(r->probes, r->f->time, v, err);
}

/* The step log's columns after the time (fluid.step_log, docs/output.md). */
enum { STEP_COLUMNS = 7 };

/* One row of the step log (fluid.step_log), after each step. */
static enum mps_status write_step_row(struct run *r, struct mps_err *err)
{
    if (!r->steps)
        return MPS_OK;
    const struct fluid_step_stats *l = &r->f->last;
    double v[STEP_COLUMNS] = {l->dt,           l->ppe_iterations,     l->ppe_rows,
                              l->rows_at_zero, l->tension_solves,     (double)l->collisions,
                              l->neighbour_build};
    return mps_probes_write(r->steps, r->f->time, v, err);
}

/* A checkpoint at the fluid's time: the run's part (case, counters, where
 * the tables end, the snapshot index), then the fluid's state. */
static enum mps_status put_fluid(const void *f, struct mps_ckpt *c, struct mps_err *err)
{
    return fluid_state_put(f, c, err);
}

/* A checkpoint at the fluid's time (mps_restart.h). */
static enum mps_status write_checkpoint(struct run *r, struct mps_err *err)
{
    double t0 = mps_wall_seconds();
    r->mark.number++;
    r->mark.steps = r->f->step;
    r->mark.table_bytes[0] = mps_probes_bytes(r->probes);
    r->mark.table_bytes[1] = mps_probes_bytes(r->steps);
    enum mps_status st = mps_run_checkpoint(&r->disk, r->out, r->prefix, r->case_yaml, &r->mark,
                                            r->h5, r->f->time, put_fluid, r->f, err);
    if (st)
        return st;
    r->checkpoints++;
    r->t_checkpoint += mps_wall_seconds() - t0;
    return MPS_OK;
}

static void summary_json(const struct run *r, FILE *fp, enum mps_status st,
                         const struct mps_err *err)
{
    struct mps_json j;
    mps_json_begin(&j, fp);
    mps_json_str(&j, "solver", "fluid_solver");
    mps_json_str(&j, "version", MPS_VERSION);
    mps_json_str(&j, "git_rev", mps_git_rev);
    char host[256];
    mps_host_describe(host, sizeof host);
    mps_json_str(&j, "host", host);   /* the timings below are this machine's */
    mps_json_str(&j, "case", r->cs ? mps_case_path(r->cs) : "");
    if (r->cs) {
        mps_prov_json(r->cs, &j);
        mps_json_num(&j, "end_time", mps_case_double(r->cs, "end_time"));
    }
    mps_json_str(&j, "status", mps_status_name(st));
    mps_json_str(&j, "message", st ? err->msg : "");
    mps_json_num(&j, "wall_seconds", mps_wall_seconds() - r->wall0);
    mps_json_num(&j, "output_seconds", r->t_output);
    /* checkpoints: their cost, and where a restarted run came from */
    mps_json_int(&j, "checkpoints", r->checkpoints);
    mps_json_num(&j, "checkpoint_seconds", r->t_checkpoint);
    mps_json_int(&j, "checkpoint_bytes", (long long)r->disk.len);
    if (r->stopped)
        mps_json_num(&j, "stopped_at", r->f->time);
    if (r->restart_path[0]) {
        mps_json_object(&j, "restart");
        mps_json_str(&j, "checkpoint", r->restart_path);
        mps_json_num(&j, "time", r->restart_time);
        mps_json_int(&j, "step", r->f->step_start);
        if (r->restart_arith[0])
            mps_json_str(&j, "arith_differs", r->restart_arith);
        mps_json_close(&j);
    }
    if (r->peer.advances) {
        mps_json_num(&j, "setup_seconds", r->peer.setup_seconds);
        mps_json_num(&j, "compute_seconds", r->peer.compute_seconds);
        mps_json_num(&j, "wait_seconds", r->peer.wait_seconds);
        /* implicit coupling: repeated steps are in the step and PPE counts */
        mps_json_int(&j, "advances", r->peer.advances);
        mps_json_int(&j, "repeated_advances", r->peer.repeats);
        mps_json_num(&j, "rollback_seconds", r->peer.rollback_seconds);
    }
    if (r->cpu_note[0])
        mps_json_str(&j, "cpu_binding", r->cpu_note);
    /* the vector paths set the last bits of the results (MPS_SIMD=sse2) */
    mps_json_str(&j, "simd_paths", mps_simd_wide() ? "avx512" : "portable");
    if (r->motion) {
        mps_json_object(&j, "motion");
        mps_motion_summary(r->motion, &j);
        mps_json_close(&j);
    }
    if (r->f)
        fluid_summary(r->f, &j);
    mps_json_end(&j);
}

/* Writes OUT/<summary_name> and returns the same JSON as a malloc'd string. */
static char *write_summary(const struct run *r, enum mps_status st, const struct mps_err *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", r->out, r->summary_name);
    FILE *fp = fopen(path, "w");
    if (fp) {
        summary_json(r, fp, st, err);
        fclose(fp);
    } else {
        fprintf(stderr, "fluid_solver: warning: cannot write %s\n", path);
    }
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    if (mem) {
        summary_json(r, mem, st, err);
        fclose(mem);
    }
    return text;
}

/* The next step: the CFL step, shortened only to end the run at end_time
 * with no sliver of a step left before it. Output and probe times do not
 * shorten steps: a snapshot or probe row is written at the end of the first
 * step that reaches its time, and records that step's time, so the output
 * schedule never changes the solution (docs/pressure.md: shortened steps
 * made the pressure flicker). */
static double next_dt(const struct fluid *f, double t_end)
{
    double dt = fluid_cfl_dt(f), left = t_end - f->time;
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
    struct mps_run_mark *m = &r->mark;
    if (!r->resumed) {
        if (p->output_interval > 0.0 && (st = write_snapshot(r, err)))
            return st;
        if ((st = write_probes(r, err)))
            return st;
        m->out_k = m->probe_k = m->ck_k = 1;
    }
    const double eps = 1e-9 * p->end_time;
    while (r->f->time < p->end_time - eps) {
        if (stop_signal)
            return mps_err_set(err, MPS_EINTR, "interrupted by signal %d at t = %.6g s",
                               (int)stop_signal, r->f->time);
        if ((st = fluid_step(r->f, next_dt(r->f, p->end_time), err)) ||
            (st = write_step_row(r, err)))
            return st;
        const double t = r->f->time;
        if (mps_run_due(&m->probe_k, p->probe_interval, t, eps) && (st = write_probes(r, err)))
            return st;
        if (mps_run_due(&m->out_k, p->output_interval, t, eps) && (st = write_snapshot(r, err)))
            return st;
        /* last: the checkpoint holds the outputs of this step */
        if (mps_run_due(&m->ck_k, p->checkpoint_interval, t, eps) && t < p->end_time - eps) {
            if ((st = write_checkpoint(r, err)))
                return st;
            if (t >= r->stop_at - eps) {
                r->stopped = 1;
                break;
            }
        }
        mps_progress_update(&prog, r->f->time, r->f->step);
    }
    mps_progress_finish(&prog, r->f->time, r->f->step);
    return MPS_OK;
}

/* The keys this program knows (the solid's and the coupler's sections are
 * theirs to check) */
static const struct mps_key_spec *const case_tables[] = {mps_case_common_keys, fluid_case_keys,
                                                         mps_motion_keys};
#define NTABLES (int)(sizeof case_tables / sizeof *case_tables)

/* Loads the case (validated against case_tables) and builds the fluid and
 * its outputs. */
static enum mps_status setup(struct run *r, const char *case_path, const char *const *sets,
                             int nsets, const char *prefix, struct mps_err *err)
{
    const char *const ignore[] = {"solid.", "coupling.", NULL};
    /* standalone: this command is the run's record; under the coupler the
     * resolved case brings the coupler's */
    const char *all[MPS_CLI_MAX_SETS + MPS_PROV_NSETS];
    int nall = 0;
    for (int k = 0; k < nsets; k++)
        all[nall++] = sets[k];
    if (!r->coupled)
        mps_prov_sets(all, &nall, MPS_CLI_MAX_SETS + MPS_PROV_NSETS);
    enum mps_status st = mps_case_load(&r->cs, case_path, all, nall, case_tables, NTABLES, ignore, err);
    struct fluid_params prm;
    if (!st && !(st = fluid_params_read(&prm, r->cs, err)))
        st = mps_motion_read(&r->motion, r->cs, err);
    /* the fluid owns its keys: under the coupler a problem with one is a case
     * error, which the coupler prints as its own (PROTOCOL.md 8) */
    if (st && r->coupled)
        return proto_solver_case_error(st, err);
    if (st || (st = mps_mkdir_p(r->out, err)))
        return st;
    prm.motion = r->motion;
    if ((st = fluid_create(&r->f, &prm, err)))
        return st;
    r->case_yaml = mps_case_resolved_yaml(r->cs);
    if (!r->case_yaml)
        return mps_err_set(err, MPS_ENOMEM, "fluid: no memory for the resolved case");
    char path[4200];
    snprintf(path, sizeof path, "%s/probes.csv", r->out);
    const char *names[FLUID_MAX_PROBES];
    for (int k = 0; k < prm.nprobes; k++)
        names[k] = prm.probes[k].name;
    proto_join_names(names, prm.nprobes, r->probe_names, sizeof r->probe_names);
    if ((st = mps_probes_check_names(names, prm.nprobes, mps_case_path(r->cs), err)))
        return st;
    st = mps_h5_open(&r->h5, r->out, prefix, "fluid_solver", r->case_yaml, err);
    /* under the coupler, probes travel in RESULT and the coupler writes them */
    if (!st && !r->coupled && r->resumed) {
        st = mps_probes_resume(&r->probes, path, r->mark.table_bytes[0], prm.nprobes, err);
    } else if (!st && !r->coupled) {
        char *comment = mps_prov_comment(r->cs, "fluid_solver");
        st = mps_probes_open(&r->probes, path, comment, names, prm.nprobes, err);
        free(comment);
    }
    if (!st && prm.step_log) {
        static const char *const cols[STEP_COLUMNS] = {
            "dt",          "ppe_iterations",  "ppe_rows",        "rows_at_zero",
            "tension_solves", "collision_pairs", "neighbour_build"};
        snprintf(path, sizeof path, "%s/%s_steps.csv", r->out, prefix);
        if (r->resumed)
            return mps_probes_resume(&r->steps, path, r->mark.table_bytes[1], STEP_COLUMNS, err);
        char *comment = mps_prov_comment(r->cs, "fluid_solver");
        st = mps_probes_open(&r->steps, path, comment, cols, STEP_COLUMNS, err);
        free(comment);
    }
    return st;
}

/* A new run from the case, or with --restart the run in its directory from
 * its checkpoint: the case the checkpoint holds, the outputs continued where
 * it was taken, the fluid's state read back. */
static enum mps_status restart_or_setup(struct run *r, const struct mps_cli *cli,
                                        struct mps_err *err)
{
    if (!cli->restart_dir)
        return setup(r, cli->case_path, cli->sets, cli->nsets, "fluid", err);
    char case_path[4400];
    enum mps_status st = mps_run_restart_open(&r->disk, cli, "fluid", case_path,
                                              sizeof case_path, &r->mark, err);
    if (st)
        return st;
    r->resumed = 1;
    mps_ckpt_path(r->restart_path, sizeof r->restart_path, cli->restart_dir, "fluid",
                  r->mark.number);
    r->restart_time = r->disk.time;
    if ((st = setup(r, case_path, cli->sets, cli->nsets, "fluid", err)))
        return st;
    /* a block out of place: a checkpoint of another build (a field added) */
    if ((st = mps_run_get_rest(&r->disk, r->h5, err)) || (st = fluid_state_get(r->f, &r->disk, err)))
        return mps_err_prefix(err, "%s: ", r->restart_path);
    mps_run_arith_check(&r->disk, "fluid_solver", r->restart_path, r->restart_arith,
                        sizeof r->restart_arith);
    r->f->step_start = r->f->step;
    if (!cli->quiet)
        fprintf(stderr, "fluid_solver: restarting %s at t = %.9g s (step %ld)\n", cli->restart_dir,
                r->f->time, r->f->step);
    return MPS_OK;
}

static enum mps_status peer_configure(void *self, const char *case_path, const char *out_dir,
                                      const char *prefix, struct mps_err *err)
{
    struct run *r = self;
    snprintf(r->out_buf, sizeof r->out_buf, "%s", out_dir);
    r->out = r->out_buf;
    snprintf(r->prefix, sizeof r->prefix, "%s", prefix);
    enum mps_status st;
    /* CONFIG restart=N: where the outputs stood (the step log continues) */
    if (r->peer.restart &&
        (st = mps_run_read(&r->disk, out_dir, prefix, r->peer.restart, &r->mark, err)))
        return st;
    r->resumed = r->peer.restart > 0;
    st = setup(r, case_path, NULL, 0, prefix, err);
    if (!st && !r->resumed && r->f->prm.output_interval > 0.0)
        st = write_snapshot(r, err);
    return st;
}

/* caps=checkpoint (proto_solver.h): the same checkpoint as a run alone. */
static enum mps_status peer_checkpoint(void *self, long number, double time,
                                       struct mps_err *err)
{
    struct run *r = self;
    /* a repeated iteration (implicit coupling) rewrites checkpoint number */
    const int again = r->checkpoints > 0 && r->mark.number == number;
    r->mark.number = number - 1; /* write_checkpoint counts it */
    (void)time;                  /* the fluid's own time is the coupler's (peer_advance) */
    enum mps_status st = write_checkpoint(r, err);
    r->checkpoints -= again && !st;
    return st;
}

static enum mps_status peer_resume(void *self, long number, struct mps_err *err)
{
    struct run *r = self;
    enum mps_status st;
    mps_ckpt_path(r->restart_path, sizeof r->restart_path, r->out, r->prefix, number);
    /* a block out of place: a checkpoint of another build (a field added) */
    if ((st = mps_run_get_rest(&r->disk, r->h5, err)) ||
        (st = fluid_state_get(r->f, &r->disk, err)))
        return mps_err_prefix(err, "%s: ", r->restart_path);
    mps_run_arith_check(&r->disk, "fluid_solver", r->restart_path, r->restart_arith,
                        sizeof r->restart_arith);
    r->restart_time = r->f->time;
    r->f->step_start = r->f->step;
    return MPS_OK;
}

static enum mps_status peer_ready(void *self, struct proto_msg *reply, struct mps_err *err)
{
    struct run *r = self;
    reply->payload = PROTO_NONE;
    reply->dt = fluid_cfl_dt(r->f);
    enum mps_status st = fluid_check_step(r->f, reply->dt, err);
    if (st)
        return st;
    reply->nprobes = r->f->prm.nprobes;
    reply->text = r->probe_names[0] ? r->probe_names : NULL;
    return MPS_OK;
}

static enum mps_status peer_advance(void *self, const struct proto_msg *in,
                                    struct proto_msg *reply, struct mps_err *err)
{
    struct run *r = self;
    struct fluid *f = r->f;
    enum mps_status st;
    if (in->payload == PROTO_STATE &&
        (st = fluid_set_solid(f, in->count, in->id, in->x, in->v, in->surface, err)))
        return st;
    if (in->payload == PROTO_LOADS)
        return mps_err_set(err, MPS_EPROTO, "the fluid was sent LOADS; it takes STATE or NONE");
    if ((st = fluid_step(f, in->dt, err)))
        return st;
    /* the coupler's clock is the reference: no drift from summing steps */
    f->time = in->time + in->dt;
    if ((st = write_step_row(r, err)))
        return st;
    if (in->count > r->load_cap) {
        size_t cap = in->count + 64;
        int *id = realloc(r->load_id, cap * sizeof *id);
        double *p = realloc(r->load_p, cap * sizeof *p);
        double(*fo)[MPS_DIM] = realloc(r->load_f, cap * sizeof *fo);
        if (id)
            r->load_id = id;
        if (p)
            r->load_p = p;
        if (fo)
            r->load_f = fo;
        if (!id || !p || !fo)
            return mps_err_set(err, MPS_ENOMEM, "fluid: out of memory for %zu loads", cap);
        r->load_cap = cap;
    }
    size_t m = fluid_solid_loads(f, r->load_id, r->load_p, r->load_f, r->load_cap);
    reply->payload = PROTO_LOADS; /* empty when there is no solid */
    reply->count = m;
    reply->id = r->load_id;
    reply->pressure = r->load_p;
    reply->force = (const double(*)[MPS_DIM])r->load_f;
    reply->dt = fluid_cfl_dt(f);
    if ((st = fluid_check_step(f, reply->dt, err)))
        return st;
    if (in->flags & PROTO_F_PROBES) {
        static double values[FLUID_MAX_PROBES];
        for (int k = 0; k < f->prm.nprobes; k++)
            values[k] = fluid_probe(f, k);
        fluid_probes_restart(f); /* the coupler writes a row of these */
        reply->nprobes = f->prm.nprobes;
        reply->probes = values;
    }
    if (in->flags & PROTO_F_SNAPSHOT)
        st = write_snapshot(r, err);
    return st;
}

static enum mps_status peer_save(void *self, struct mps_err *err)
{
    struct run *r = self;
    r->saved_snapshots = mps_h5_count(r->h5);
    return fluid_ckpt_save(r->f, &r->ckpt, err);
}

static enum mps_status peer_restore(void *self, struct mps_err *err)
{
    struct run *r = self;
    enum mps_status st = fluid_ckpt_restore(r->f, &r->ckpt, err);
    return st ? st : mps_h5_rewind(r->h5, r->saved_snapshots, err);
}

static char *peer_finish(void *self, enum mps_status st, const struct mps_err *err)
{
    struct run *r = self;
    return write_summary(r, st, err);
}

static void teardown(struct run *r)
{
    mps_probes_close(&r->probes);
    mps_probes_close(&r->steps);
    mps_h5_close(&r->h5);
    fluid_destroy(&r->f);
    fluid_ckpt_free(&r->ckpt);
    mps_ckpt_free(&r->disk);
    free(r->case_yaml);
    mps_motion_destroy(&r->motion);
    mps_case_destroy(&r->cs);
    free(r->load_id);
    free(r->load_p);
    free(r->load_f);
}

static int run_coupled(const char *endpoint, int hello_timeout_ms)
{
    struct run r = {.out = ".", .quiet = 1, .summary_name = "fluid_summary.json", .coupled = 1,
                    .prefix = "fluid"};
    r.wall0 = mps_wall_seconds();
    struct mps_err err = {0};
    static const struct proto_solver_ops ops = {"fluid",     "mps",       peer_configure,
                                                peer_ready,  peer_advance, peer_finish,
                                                peer_save,   peer_restore, 1,
                                                peer_checkpoint, peer_resume, NULL};
    enum mps_status st =
        proto_solver_run(endpoint, &ops, &r, hello_timeout_ms, &stop_signal, &r.peer, &err);
    if (st && !r.peer.coupler_reports)
        fprintf(stderr, "fluid_solver: %s: %s\n", mps_status_name(st), err.msg);
    teardown(&r);
    return mps_status_exit_code(st);
}

int main(int argc, char **argv)
{
    struct mps_err err = {0};
    mps_prov_init(argc, argv);
    /* the PPE's sums and the neighbour loops' vector paths: docs/restart.md */
    mps_run_arith_set(MPS_ARITH_THREADS | MPS_ARITH_SIMD);
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    const char *endpoint = NULL;
    int hello_ms = 0;
    int coupled = proto_solver_args(argc, argv, &endpoint, &hello_ms, &err);
    if (coupled < 0) {
        fprintf(stderr, "fluid_solver: %s\n", err.msg);
        return 2;
    }
    if (coupled)
        return run_coupled(endpoint, hello_ms);

    struct mps_cli cli;
    struct mps_cli_extra extra[] = {
        {"--dump-ppe", 1, "write the PPE of step N as Matrix Market files, and its rhs's parts as ppe_terms.csv, into --out", NULL},
    };
    const char *usage = "usage: fluid_solver CASE.yml --out DIR [--set key=value]... [--quiet]\n"
                        "       fluid_solver --connect ENDPOINT [--timeout S]   (under the coupler)";
    enum mps_status st = mps_cli_parse(&cli, argc, argv, extra, 1, usage, &err);
    if (st == MPS_EINTR) {
        if (cli.keys) {
            const char *const titles[NTABLES] = {MPS_CASE_COMMON_KEYS_TITLE,
                                                 "fluid_solver: `fluid.*`",
                                                 MPS_MOTION_KEYS_TITLE};
            mps_case_print_keys(stdout, case_tables, titles, NTABLES);
        }
        return 0; /* --help, --version, --keys */
    }
    if (st) {
        fprintf(stderr, "fluid_solver: %s\n", err.msg);
        return mps_status_exit_code(st);
    }
    if (!cli.out_dir) {
        /* no silent ./out: a second run there would mix with the first */
        fprintf(stderr, "fluid_solver: missing --out DIR (see --help)\n");
        return 2;
    }
    long target = 0; /* --dump-ppe N */
    if (extra[0].value) {
        char *end = NULL;
        target = strtol(extra[0].value, &end, 10);
        if (end == extra[0].value || *end || target < 1) {
            fprintf(stderr, "fluid_solver: --dump-ppe '%s': not a step number (a whole number "
                            ">= 1: the step of that row of fluid_steps.csv)\n", extra[0].value);
            return 2;
        }
    }
    struct run r = {.out = cli.out_dir, .quiet = cli.quiet, .summary_name = "summary.json",
                    .prefix = "fluid",
                    .stop_at = cli.stop_at};
    r.wall0 = mps_wall_seconds();
    mps_omp_bind_threads(r.cpu_note, sizeof r.cpu_note);
    st = restart_or_setup(&r, &cli, &err);
    if (st == MPS_OK) {
        if (extra[0].value) {
            /* benchmark aid: run to step N and dump its PPE */
            r.f->keep_ppe_terms = 1;
            while (!st && r.f->step < target)
                st = fluid_step(r.f, fluid_cfl_dt(r.f), &err);
            char mpath[4200], bpath[4200], tpath[4200];
            snprintf(mpath, sizeof mpath, "%s/ppe_A.mtx", r.out);
            snprintf(bpath, sizeof bpath, "%s/ppe_b.mtx", r.out);
            snprintf(tpath, sizeof tpath, "%s/ppe_terms.csv", r.out);
            if (!st)
                st = fluid_ppe_dump(r.f, mpath, bpath, tpath, &err);
        } else {
            st = run_standalone(&r, &err);
        }
    }
    if (st)
        fprintf(stderr, "%sfluid_solver: %s: %s\n", r.f && r.f->step ? "\n" : "",
                mps_status_name(st), err.msg);
    if (r.f && r.f->lost > 0) /* a result, not progress: --quiet keeps it */
        fprintf(stderr, "fluid_solver: %ld fluid particle%s left over the open tank walls "
                        "(removed; lost_particles in summary.json)\n",
                r.f->lost, r.f->lost == 1 ? "" : "s");
    if (r.f) /* a run that started leaves its summary, even a failed one */
        free(write_summary(&r, st, &err));
    teardown(&r);
    return mps_status_exit_code(st);
}
