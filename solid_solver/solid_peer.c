#include "solid_peer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_case.h"
#include "mps_cli.h"
#include "mps_host.h"
#include "mps_json.h"
#include "mps_prov.h"
#include "mps_restart.h"
#include "mps_version.h"
#include "mps_timer.h"
#include "proto_solver.h"
#include "solid_scene.h"

struct peer {
    const struct solid_model_ops *ops;
    void *model;
    struct mps_case *cs;
    struct mps_h5_series *h5;
    char out[4096];
    char probe_names[4096];
    double *probes;
    double depth;          /* interface depth, m */
    double t_output;
    long substeps;         /* from the run's start (a restart's checkpoint holds them) */
    long substeps_start;   /* the checkpoint's, on a restart: advances are this process's */
    double max_ratio;      /* largest sub-step / stable step seen */
    struct proto_solver_stats stats;
    double wall0;
    int saved_snapshots;   /* snapshots written at the last save (rollback) */
    struct mps_ckpt rollback; /* the model's state at the last save */
    /* checkpoints (caps=checkpoint, docs/restart.md) */
    struct mps_ckpt disk;
    struct mps_run_mark mark;
    char *case_yaml;
    char prefix[64];
    char restart_path[4400];
    double restart_time;
    char restart_arith[256]; /* what differs from its run's arithmetic, or "" */
    int fracture;          /* the scene has fracture or contact (solid.eps_max, solid.contact) */
};

static enum mps_status snapshot(struct peer *p, double t, long step, struct mps_err *err)
{
    return solid_model_snapshot(p->ops, p->model, p->h5, t, step, &p->t_output, err);
}

static enum mps_status state(struct peer *p, struct proto_msg *m, struct mps_err *err)
{
    struct solid_iface iface;
    enum mps_status st = p->ops->interface(p->model, p->depth, &iface, err);
    if (st)
        return st;
    m->payload = PROTO_STATE;
    m->count = iface.n;
    m->id = iface.id;
    m->x = iface.x;
    m->v = iface.v;
    m->surface = iface.surface;
    m->fixed = iface.fixed;
    m->dt = p->ops->stable_dt(p->model);
    return MPS_OK;
}

static enum mps_status configure(void *self, const char *case_path, const char *out,
                                 const char *prefix, struct mps_err *err)
{
    struct peer *p = self;
    snprintf(p->out, sizeof p->out, "%s", out);
    snprintf(p->prefix, sizeof p->prefix, "%s", prefix);
    const char *const ignore[] = {"fluid.", "coupling.", NULL};
    /* --model NAME is solid.model, so the snapshots' /config says what runs */
    char model_set[64];
    const char *sets[1] = {model_set};
    if (p->ops)
        snprintf(model_set, sizeof model_set, "solid.model=%s", p->ops->name);
    enum mps_status st =
        mps_case_load(&p->cs, case_path, sets, p->ops ? 1 : 0, solid_case_tables, SOLID_NTABLES,
                      ignore, err);
    /* the solid owns its keys: a problem with one, or across them, is a case
     * error, which the coupler prints as its own (PROTOCOL.md 8); what the
     * model then cannot do is a plain input error of this solver */
    struct solid_scene *sc = st ? NULL : malloc(sizeof *sc);
    if (!st && !sc)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    if (!st)
        st = solid_scene_read(sc, p->cs, err);
    if (!st)
        p->fracture = sc->eps_max > 0.0 || sc->contact != SOLID_CONTACT_NONE;
    free(sc);
    if (st)
        return proto_solver_case_error(st, err);
    if (!p->ops && !(p->ops = solid_model_find(mps_case_string(p->cs, "solid.model"))))
        return mps_case_fail(p->cs, err, "solid.model", "unknown model (known: %s)",
                             solid_model_names());
    if ((st = solid_model_open(&p->ops, &p->model, p->cs, err)))
        return st;
    if ((st = solid_model_check_step(p->ops, p->model, p->cs, err)))
        return proto_solver_case_error(st, err);
    p->depth = mps_case_double(p->cs, "solid.interface_depth") * mps_case_double(p->cs, "dp");
    int n = p->ops->probe_count(p->model);
    const char *names[256];
    for (int k = 0; k < n && k < 256; k++)
        names[k] = p->ops->probe_name(p->model, k);
    proto_join_names(names, n < 256 ? n : 256, p->probe_names, sizeof p->probe_names);
    p->probes = calloc((size_t)n + 1, sizeof *p->probes);
    if (!p->probes)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    if (!(p->case_yaml = mps_case_resolved_yaml(p->cs)))
        return mps_err_set(err, MPS_ENOMEM, "solid: no memory for the resolved case");
    st = mps_h5_open(&p->h5, out, prefix, "solid_solver", p->case_yaml, err);
    /* CONFIG restart=N: the snapshots continue from the checkpoint (resume) */
    if (!st && !p->stats.restart && mps_case_double(p->cs, "output.interval") > 0.0)
        st = snapshot(p, 0.0, 0, err);
    return st;
}

/* caps=checkpoint (proto_solver.h): the model's state (state_put, the one
 * rollback keeps) and the snapshot index, as the program alone writes it. */
static enum mps_status checkpoint(void *self, long number, double time, struct mps_err *err)
{
    struct peer *p = self;
    if (!p->ops->state_put)
        return mps_err_set(err, MPS_EINPUT, "solid model %s cannot checkpoint", p->ops->name);
    p->mark.number = number;
    p->mark.steps = p->substeps;
    return mps_run_checkpoint(&p->disk, p->out, p->prefix, p->case_yaml, &p->mark, p->h5, time,
                              p->ops->state_put, p->model, err);
}

static enum mps_status resume(void *self, long number, struct mps_err *err)
{
    struct peer *p = self;
    enum mps_status st;
    if (!p->ops->state_get)
        return mps_err_set(err, MPS_EINPUT, "solid model %s cannot restart", p->ops->name);
    if ((st = mps_run_read(&p->disk, p->out, p->prefix, number, &p->mark, err)))
        return st;
    mps_ckpt_path(p->restart_path, sizeof p->restart_path, p->out, p->prefix, number);
    /* a block out of place: a checkpoint of another build (a field added) */
    if ((st = mps_run_get_rest(&p->disk, p->h5, err)) ||
        (st = p->ops->state_get(p->model, &p->disk, err)))
        return mps_err_prefix(err, "%s: ", p->restart_path);
    mps_run_arith_check(&p->disk, "solid_solver", p->restart_path, p->restart_arith,
                        sizeof p->restart_arith);
    p->substeps = p->substeps_start = p->mark.steps;
    p->restart_time = p->disk.time;
    return MPS_OK;
}

static enum mps_status ready(void *self, struct proto_msg *reply, struct mps_err *err)
{
    struct peer *p = self;
    reply->nprobes = p->ops->probe_count(p->model);
    reply->text = p->probe_names[0] ? p->probe_names : NULL;
    return state(p, reply, err);
}

static enum mps_status advance(void *self, const struct proto_msg *in, struct proto_msg *reply,
                               struct mps_err *err)
{
    struct peer *p = self;
    enum mps_status st;
    if (in->payload == PROTO_STATE)
        return mps_err_set(err, MPS_EPROTO, "the solid was sent STATE; it takes LOADS or NONE");
    struct solid_loads loads = {0};
    if (in->payload == PROTO_LOADS)
        loads = (struct solid_loads){in->count, in->id, in->pressure, in->force};
    if ((st = p->ops->set_loads(p->model, &loads, err)))
        return st;
    /* n_sub sub-steps of dt/n_sub, the fluid's load held over them (paper 4.6) */
    double h = in->dt / in->n_sub, stable = p->ops->stable_dt(p->model);
    if (h > stable * (1.0 + 1e-9))
        return mps_err_set(err, MPS_EPROTO,
                           "sub-step %.3g s (dt %.3g s / %d) exceeds the stable step %.3g s", h,
                           in->dt, in->n_sub, stable);
    if (h / stable > p->max_ratio)
        p->max_ratio = h / stable;
    for (int k = 0; k < in->n_sub; k++)
        if ((st = p->ops->advance(p->model, h, err)))
            return mps_err_prefix(err, "t = %.6g s: ", in->time + k * h);
    p->substeps += in->n_sub;
    if ((st = state(p, reply, err)))
        return st;
    if (in->flags & PROTO_F_PROBES) {
        reply->nprobes = p->ops->probe_count(p->model);
        for (int k = 0; k < reply->nprobes; k++)
            p->probes[k] = p->ops->probe_value(p->model, k);
        p->ops->probe_restart(p->model); /* the coupler writes a row of these */
        reply->probes = p->probes;
    }
    if (in->flags & PROTO_F_SNAPSHOT)
        st = snapshot(p, in->time + in->dt, in->step + 1, err);
    return st;
}

/* Implicit coupling (proto_solver.h): the model's state, and the snapshot
 * series, which a repeated step must write again under the same names. */
static enum mps_status save(void *self, struct mps_err *err)
{
    struct peer *p = self;
    /* the first save, with rollback=on before READY: implicit coupling
     * iterates on a fixed interface (coupling_iter.h), which fracture and
     * contact change; a problem of the case's keys, said as one */
    if (p->fracture && p->stats.advances == 0)
        return proto_solver_case_error(
            mps_case_fail(p->cs, err, "coupling.scheme",
                          "implicit coupling cannot be used with fracture or contact "
                          "(solid.eps_max, solid.contact): the interface would change "
                          "within a step"),
            err);
    enum mps_status st;
    if (!p->ops->state_put)
        return mps_err_set(err, MPS_EINPUT, "solid model %s cannot roll back a step",
                           p->ops->name);
    if (p->ops->rollback_check && (st = p->ops->rollback_check(p->model, err)))
        return st;
    p->saved_snapshots = mps_h5_count(p->h5);
    mps_ckpt_clear(&p->rollback);
    return p->ops->state_put(p->model, &p->rollback, err);
}

static enum mps_status restore(void *self, struct mps_err *err)
{
    struct peer *p = self;
    if (!p->rollback.len)
        return mps_err_set(err, MPS_EINPUT, "solid: restore without a save");
    mps_ckpt_rewind(&p->rollback);
    enum mps_status st = p->ops->state_get(p->model, &p->rollback, err);
    return st ? st : mps_h5_rewind(p->h5, p->saved_snapshots, err);
}

static void summary_json(struct peer *p, FILE *fp, enum mps_status st, const struct mps_err *err)
{
    struct mps_json j;
    mps_json_begin(&j, fp);
    mps_json_str(&j, "solver", "solid_solver");
    mps_json_str(&j, "model", p->ops ? p->ops->name : "");
    mps_json_str(&j, "version", MPS_VERSION);
    mps_json_str(&j, "git_rev", mps_git_rev);
    char host[256];
    mps_host_describe(host, sizeof host);
    mps_json_str(&j, "host", host);
    if (p->cs) {
        mps_json_str(&j, "case", mps_case_path(p->cs));
        mps_prov_json(p->cs, &j);
    }
    mps_json_str(&j, "status", mps_status_name(st));
    mps_json_str(&j, "message", st ? err->msg : "");
    mps_json_num(&j, "wall_seconds", mps_wall_seconds() - p->wall0);
    mps_json_num(&j, "setup_seconds", p->stats.setup_seconds);
    mps_json_num(&j, "compute_seconds", p->stats.compute_seconds);
    mps_json_num(&j, "wait_seconds", p->stats.wait_seconds);
    mps_json_num(&j, "output_seconds", p->t_output);
    mps_json_int(&j, "coupling_steps", p->stats.advances - p->stats.repeats);
    mps_json_int(&j, "advances", p->stats.advances); /* repeated iterations included */
    mps_json_num(&j, "rollback_seconds", p->stats.rollback_seconds);
    mps_json_int(&j, "checkpoints", p->stats.checkpoints - p->stats.restart);
    mps_json_num(&j, "checkpoint_seconds", p->stats.checkpoint_seconds);
    mps_json_int(&j, "checkpoint_bytes", (long long)p->disk.len);
    if (p->restart_path[0]) {
        mps_json_object(&j, "restart");
        mps_json_str(&j, "checkpoint", p->restart_path);
        mps_json_num(&j, "time", p->restart_time);
        mps_json_int(&j, "substeps", p->substeps_start);
        if (p->restart_arith[0])
            mps_json_str(&j, "arith_differs", p->restart_arith);
        mps_json_close(&j);
    }
    mps_json_int(&j, "substeps", p->substeps);
    mps_json_num(&j, "substeps_per_coupling_step",
                 p->stats.advances ? (double)(p->substeps - p->substeps_start) / p->stats.advances
                                   : 0.0);
    mps_json_num(&j, "largest_substep_over_stable", p->max_ratio);
    if (p->model && p->ops->summary) {
        mps_json_object(&j, "model_summary");
        p->ops->summary(p->model, &j);
        mps_json_close(&j);
    }
    mps_json_end(&j);
}

static char *finish(void *self, enum mps_status st, const struct mps_err *err)
{
    struct peer *p = self;
    char path[4200];
    snprintf(path, sizeof path, "%s/solid_summary.json", p->out);
    FILE *fp = fopen(path, "w");
    if (fp) {
        summary_json(p, fp, st, err);
        fclose(fp);
    }
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    if (mem) {
        summary_json(p, mem, st, err);
        fclose(mem);
    }
    return text;
}

int solid_peer_run(const char *endpoint, const struct solid_model_ops *ops, int hello_timeout_ms,
                   volatile const int *stop_flag)
{
    struct peer p = {.ops = ops};
    p.wall0 = mps_wall_seconds();
    /* every model of this program can roll back (a scene that cannot is
     * refused by its save) */
    struct proto_solver_ops pops = {"solid", ops ? ops->name : "case", configure, ready, advance,
                                    finish, save, restore, 1, checkpoint, resume, NULL};
    /* --model NAME is solid.model, recorded by the coupler in the run's case */
    char sets[96];
    if (ops && (size_t)snprintf(sets, sizeof sets, "solid.model:%s", ops->name) < sizeof sets)
        pops.sets = sets;
    struct mps_err err = {0};
    enum mps_status st =
        proto_solver_run(endpoint, &pops, &p, hello_timeout_ms, stop_flag, &p.stats, &err);
    if (st && !p.stats.coupler_reports)
        fprintf(stderr, "solid_solver: %s: %s\n", mps_status_name(st), err.msg);
    mps_h5_close(&p.h5);
    if (p.model)
        p.ops->destroy(&p.model);
    mps_case_destroy(&p.cs);
    free(p.probes);
    mps_ckpt_free(&p.rollback);
    mps_ckpt_free(&p.disk);
    free(p.case_yaml);
    return mps_status_exit_code(st);
}
