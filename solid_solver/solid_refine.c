#include "solid_refine.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solid_iface.h"
#include "solid_scene.h"

struct solid_refine {
    const struct solid_model_ops *inner;
    void *model;
    int refine;
    size_t nc;                        /* coupling particles */
    /* CSR by coupling particle, model particle indices: the block, and the
     * particles its load goes to */
    size_t *block_start, *block;
    size_t *load_start, *load;
    int *id;
    double (*x0)[MPS_DIM], (*x)[MPS_DIM], (*v)[MPS_DIM];
    unsigned char *surface, *fixed;
    struct solid_iface_cache iface;
    /* the loads handed to the model */
    int *load_id;
    double *load_p, (*load_f)[MPS_DIM];
    unsigned char *seen;
};

static void destroy(void **self)
{
    struct solid_refine *r = self ? *self : NULL;
    if (!r)
        return;
    if (r->model)
        r->inner->destroy(&r->model);
    free(r->block_start);
    free(r->block);
    free(r->load_start);
    free(r->load);
    free(r->id);
    free(r->x0);
    free(r->x);
    free(r->v);
    free(r->surface);
    free(r->fixed);
    solid_iface_cache_free(&r->iface);
    free(r->load_id);
    free(r->load_p);
    free(r->load_f);
    free(r->seen);
    free(r);
    *self = NULL;
}

/* The cell of the dp lattice holding model particle i, as an index over all
 * bodies' cells; -1 outside every body (cannot happen for a lattice the
 * scene filled). */
static long cell_of(const struct solid_scene *sc, const long *cell0, int b,
                    const double x0[MPS_DIM])
{
    const struct solid_body_def *d = &sc->bodies[b];
    long nx, ny;
    solid_scene_lattice(sc, b, &nx, &ny);
    nx /= sc->refine;
    ny /= sc->refine;
    long i = (long)floor((x0[0] - d->x0) / sc->dp_coupling);
    long j = (long)floor((x0[1] - d->y0) / sc->dp_coupling);
    if (i < 0 || j < 0 || i >= nx || j >= ny)
        return -1;
    return cell0[b] + i * ny + j;
}

/* Builds the blocks from the model's initial lattice. */
static enum mps_status build_map(struct solid_refine *r, const struct solid_scene *sc,
                                 struct mps_err *err)
{
    struct solid_particles_view pv;
    r->inner->particles(r->model, &pv);
    long cell0[SOLID_MAX_BODIES + 1];
    cell0[0] = 0;
    for (int b = 0; b < sc->nbodies; b++) {
        long nx, ny;
        solid_scene_lattice(sc, b, &nx, &ny);
        cell0[b + 1] = cell0[b] + (nx / sc->refine) * (ny / sc->refine);
    }
    const size_t ncell = (size_t)cell0[sc->nbodies], n = pv.n;
    long *cell = malloc((n + 1) * sizeof *cell);
    long *coupling = malloc((ncell + 1) * sizeof *coupling); /* cell -> c, -1 none yet */
    r->block_start = calloc(ncell + 2, sizeof *r->block_start);
    r->load_start = calloc(ncell + 2, sizeof *r->load_start);
    r->block = malloc((n + 1) * sizeof *r->block);
    r->load = malloc((n + 1) * sizeof *r->load);
    r->load_id = malloc((n + 1) * sizeof *r->load_id);
    r->load_p = malloc((n + 1) * sizeof *r->load_p);
    r->load_f = malloc((n + 1) * sizeof *r->load_f);
    enum mps_status st = MPS_OK;
    if (!cell || !coupling || !r->block_start || !r->load_start || !r->block || !r->load ||
        !r->load_id || !r->load_p || !r->load_f) {
        st = mps_err_set(err, MPS_ENOMEM, "solid: out of memory (refinement of %zu particles)",
                         n);
        goto done;
    }
    /* coupling particles numbered in the order the model's particles first
     * meet their cells: the order the model gives an unrefined lattice */
    for (size_t k = 0; k < ncell; k++)
        coupling[k] = -1;
    r->nc = 0;
    for (size_t i = 0; i < n; i++) {
        cell[i] = cell_of(sc, cell0, pv.body[i], pv.x0[i]);
        if (cell[i] < 0) {
            st = mps_err_set(err, MPS_ESOLVE, "solid: refinement: particle %zu at (%g, %g) "
                             "outside its body's lattice", i, pv.x0[i][0], pv.x0[i][1]);
            goto done;
        }
        if (coupling[cell[i]] < 0)
            coupling[cell[i]] = (long)r->nc++;
        r->block_start[coupling[cell[i]] + 1]++;
    }
    const size_t nc = r->nc;
    r->id = malloc((nc + 1) * sizeof *r->id);
    r->x0 = calloc(nc + 1, sizeof *r->x0);
    r->x = calloc(nc + 1, sizeof *r->x);
    r->v = calloc(nc + 1, sizeof *r->v);
    r->surface = calloc(nc + 1, 1);
    r->fixed = malloc(nc + 1);
    r->seen = calloc(nc + 1, 1);
    if (!r->id || !r->x0 || !r->x || !r->v || !r->surface || !r->fixed || !r->seen) {
        st = mps_err_set(err, MPS_ENOMEM, "solid: out of memory (%zu coupling particles)", nc);
        goto done;
    }
    for (size_t c = 0; c < nc; c++) {
        r->block_start[c + 1] += r->block_start[c];
        r->id[c] = (int)c;
        r->fixed[c] = 1;
    }
    size_t *fill = calloc(nc + 1, sizeof *fill);
    if (!fill) {
        st = mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        size_t c = (size_t)coupling[cell[i]];
        r->block[r->block_start[c] + fill[c]++] = i;
        r->surface[c] |= pv.surface[i] != 0;
        r->fixed[c] &= pv.fixed[i] != 0;
    }
    free(fill);
    for (size_t c = 0; c < nc; c++) {
        const size_t b0 = r->block_start[c], b1 = r->block_start[c + 1];
        for (size_t e = b0; e < b1; e++)
            for (int a = 0; a < MPS_DIM; a++)
                r->x0[c][a] += pv.x0[r->block[e]][a] / (double)(b1 - b0);
        size_t m = r->load_start[c];
        for (size_t e = b0; e < b1; e++)
            if (pv.surface[r->block[e]] || !r->surface[c])
                r->load[m++] = r->block[e];
        r->load_start[c + 1] = m;
    }
done:
    free(cell);
    free(coupling);
    return st;
}

static double op_stable_dt(const void *self)
{
    const struct solid_refine *r = self;
    return r->inner->stable_dt(r->model);
}

/* The load on coupling particle c, shared by its load particles. */
static enum mps_status op_set_loads(void *self, const struct solid_loads *f,
                                    struct mps_err *err)
{
    struct solid_refine *r = self;
    size_t m = 0;
    enum mps_status st = MPS_OK;
    memset(r->seen, 0, r->nc);
    for (size_t k = 0; f && k < f->n; k++) {
        int c = f->id[k];
        if (c < 0 || (size_t)c >= r->nc) {
            st = mps_err_set(err, MPS_EINPUT, "solid: load on unknown particle id %d (ids are "
                             "0..%zu)", c, r->nc - 1);
            break;
        }
        if (r->seen[c]++) {
            st = mps_err_set(err, MPS_EINPUT, "solid: two loads on particle id %d", c);
            break;
        }
        const size_t e0 = r->load_start[c], e1 = r->load_start[c + 1];
        for (size_t e = e0; e < e1; e++, m++) {
            r->load_id[m] = (int)r->load[e];
            r->load_p[m] = f->pressure[k];
            for (int a = 0; a < MPS_DIM; a++)
                r->load_f[m][a] = f->force[k][a] / (double)(e1 - e0);
        }
    }
    if (st)
        return st;
    struct solid_loads fine = {m, r->load_id, r->load_p, (const double(*)[MPS_DIM])r->load_f};
    return r->inner->set_loads(r->model, &fine, err);
}

static enum mps_status op_advance(void *self, double dt, struct mps_err *err)
{
    struct solid_refine *r = self;
    return r->inner->advance(r->model, dt, err);
}

static enum mps_status op_interface(void *self, double depth, struct solid_iface *out,
                                    struct mps_err *err)
{
    struct solid_refine *r = self;
    if (depth != r->iface.depth) {
        enum mps_status st = solid_iface_cache_build(&r->iface, r->nc,
                                                     (const double(*)[MPS_DIM])r->x0,
                                                     r->surface, r->id, r->fixed, depth, err);
        if (st)
            return st;
    }
    /* only the coupling particles the interface holds: the rest stay unread */
    struct solid_particles_view pv;
    r->inner->particles(r->model, &pv);
    for (size_t k = 0; k < r->iface.n; k++) {
        const size_t c = r->iface.idx[k], b0 = r->block_start[c], b1 = r->block_start[c + 1];
        double x[MPS_DIM] = {0}, v[MPS_DIM] = {0};
        for (size_t e = b0; e < b1; e++)
            for (int a = 0; a < MPS_DIM; a++) {
                x[a] += pv.x[r->block[e]][a];
                v[a] += pv.v[r->block[e]][a];
            }
        for (int a = 0; a < MPS_DIM; a++) {
            r->x[c][a] = x[a] / (double)(b1 - b0);
            r->v[c][a] = v[a] / (double)(b1 - b0);
        }
    }
    solid_iface_cache_fill(&r->iface, (const double(*)[MPS_DIM])r->x,
                           (const double(*)[MPS_DIM])r->v, out);
    return MPS_OK;
}

static int op_probe_count(const void *self)
{
    const struct solid_refine *r = self;
    return r->inner->probe_count(r->model);
}

static const char *op_probe_name(const void *self, int k)
{
    const struct solid_refine *r = self;
    return r->inner->probe_name(r->model, k);
}

static double op_probe_value(const void *self, int k)
{
    const struct solid_refine *r = self;
    return r->inner->probe_value(r->model, k);
}

static void op_probe_restart(void *self)
{
    struct solid_refine *r = self;
    r->inner->probe_restart(r->model);
}

static size_t op_snapshot(void *self, const double (**x)[MPS_DIM], struct mps_field *fields,
                          int max_fields, int *nfields)
{
    struct solid_refine *r = self;
    return r->inner->snapshot(r->model, x, fields, max_fields, nfields);
}

static void op_summary(const void *self, struct mps_json *j)
{
    const struct solid_refine *r = self;
    r->inner->summary(r->model, j);
    struct solid_particles_view pv;
    r->inner->particles(r->model, &pv);
    mps_json_int(j, "refine", r->refine);
    mps_json_int(j, "solid_particles", (long long)pv.n);
    mps_json_int(j, "coupling_particles", (long long)r->nc);
}

static enum mps_status op_state_put(const void *self, struct mps_ckpt *c, struct mps_err *err)
{
    const struct solid_refine *r = self;
    return r->inner->state_put(r->model, c, err);
}

static enum mps_status op_state_get(void *self, struct mps_ckpt *c, struct mps_err *err)
{
    struct solid_refine *r = self;
    return r->inner->state_get(r->model, c, err);
}

static enum mps_status op_rollback_check(const void *self, struct mps_err *err)
{
    const struct solid_refine *r = self;
    return r->inner->rollback_check(r->model, err);
}

static void op_particles(const void *self, struct solid_particles_view *out)
{
    const struct solid_refine *r = self;
    r->inner->particles(r->model, out);
}

/* Not reached: solid_refine_wrap builds the wrapper around a built model. */
static enum mps_status op_create(void **self, const struct mps_case *c, struct mps_err *err)
{
    (void)c;
    *self = NULL;
    return mps_err_set(err, MPS_ESOLVE, "solid: the refinement is built by solid_refine_wrap");
}

/* One table per model wrapped, named like it, with the model's optional
 * entries present exactly when the model has them. */
#define MAX_WRAPPED 8
static struct solid_model_ops wrapped[MAX_WRAPPED];
static const struct solid_model_ops *wrapped_inner[MAX_WRAPPED];

static const struct solid_model_ops *table_for(const struct solid_model_ops *inner)
{
    int k = 0;
    while (k < MAX_WRAPPED && wrapped_inner[k] && wrapped_inner[k] != inner)
        k++;
    if (k == MAX_WRAPPED)
        return NULL;
    if (!wrapped_inner[k]) {
        wrapped[k] = (struct solid_model_ops){
            .name = inner->name,
            .create = op_create,
            .stable_dt = op_stable_dt,
            .set_loads = op_set_loads,
            .advance = op_advance,
            .interface = op_interface,
            .probe_count = op_probe_count,
            .probe_name = op_probe_name,
            .probe_value = op_probe_value,
            .probe_restart = op_probe_restart,
            .snapshot = op_snapshot,
            .summary = op_summary,
            .destroy = destroy,
            .state_put = inner->state_put ? op_state_put : NULL,
            .state_get = inner->state_get ? op_state_get : NULL,
            .rollback_check = inner->rollback_check ? op_rollback_check : NULL,
            .particles = op_particles,
        };
        wrapped_inner[k] = inner;
    }
    return &wrapped[k];
}

enum mps_status solid_refine_wrap(const struct solid_model_ops **ops, void **self,
                                  const struct mps_case *c, struct mps_err *err)
{
    const struct solid_model_ops *inner = *ops;
    struct solid_refine *r = calloc(1, sizeof *r);
    struct solid_scene *sc = malloc(sizeof *sc);
    const struct solid_model_ops *table = table_for(inner);
    enum mps_status st = MPS_OK;
    if (!r || !sc)
        st = mps_err_set(err, MPS_ENOMEM, "solid: out of memory (refinement)");
    else if (!inner->particles || !table)
        st = mps_case_fail(c, err, "solid.refine", "the solid model %s cannot run refined",
                           inner->name);
    if (!st) {
        r->inner = inner;
        r->model = *self;
        *self = NULL;
        solid_iface_cache_init(&r->iface);
        st = solid_scene_read(sc, c, err);
    }
    if (!st) {
        r->refine = sc->refine;
        st = build_map(r, sc, err);
    }
    free(sc);
    if (st) {
        if (*self) /* not handed to the wrapper yet */
            inner->destroy(self);
        void *w = r;
        destroy(&w);
        *self = NULL;
        return st;
    }
    *ops = table;
    *self = r;
    return MPS_OK;
}
