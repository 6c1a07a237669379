#include "solid_mps_fracture.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mps_kernel.h"
#include "solid_mps.h"

/* A cell list hashed into about 2n buckets: its size follows the number of
 * points, not the area they cover (the dense grid of mps_nbr would grow with
 * the square of the distance a chipped-off particle has flown). Cells that
 * share a bucket are told apart by the cell stored with each point. */
struct hgrid {
    size_t nb, cap_b, cap_n;
    size_t *start;                   /* nb + 1 */
    size_t *idx;                     /* points by bucket */
    long (*cell)[2];                 /* cell of each point */
    double inv;                      /* 1 / cell width */
};

static size_t hbucket(const struct hgrid *h, long cx, long cy)
{
    return (size_t)(((unsigned long)cx * 73856093UL) ^ ((unsigned long)cy * 19349663UL)) &
           (h->nb - 1);
}

static void hgrid_free(struct hgrid *h)
{
    free(h->start);
    free(h->idx);
    free(h->cell);
    memset(h, 0, sizeof *h);
}

static enum mps_status hgrid_build(struct hgrid *h, const double (*x)[MPS_DIM], size_t n,
                                   double cell, struct mps_err *err)
{
    size_t nb = 16;
    while (nb < 2 * n)
        nb *= 2;
    if (nb + 1 > h->cap_b) {
        size_t *p = realloc(h->start, (nb + 1) * sizeof *p);
        if (!p)
            return mps_err_set(err, MPS_ENOMEM, "solid: no memory for a cell list of %zu", n);
        h->start = p;
        h->cap_b = nb + 1;
    }
    if (n > h->cap_n) {
        size_t *p = realloc(h->idx, n * sizeof *p);
        if (p)
            h->idx = p;
        long(*c)[2] = realloc(h->cell, n * sizeof *c);
        if (c)
            h->cell = c;
        if (!p || !c)
            return mps_err_set(err, MPS_ENOMEM, "solid: no memory for a cell list of %zu", n);
        h->cap_n = n;
    }
    h->nb = nb;
    h->inv = 1.0 / cell;
    memset(h->start, 0, (nb + 1) * sizeof *h->start);
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(x[i][0] + x[i][1]) || fabs(x[i][0]) + fabs(x[i][1]) > 1e12 * cell)
            return mps_err_set(err, MPS_EDIVERGED, "solid: a particle is at (%g, %g): the "
                               "state has diverged", x[i][0], x[i][1]);
        h->cell[i][0] = (long)floor(x[i][0] * h->inv);
        h->cell[i][1] = (long)floor(x[i][1] * h->inv);
        h->start[hbucket(h, h->cell[i][0], h->cell[i][1]) + 1]++;
    }
    for (size_t b = 0; b < nb; b++)
        h->start[b + 1] += h->start[b];
    for (size_t i = n; i-- > 0;) /* back to front: ascending within a bucket */
        h->idx[--h->start[hbucket(h, h->cell[i][0], h->cell[i][1]) + 1]] = i;
    /* start[b + 1] is now the start of bucket b */
    memmove(h->start, h->start + 1, nb * sizeof *h->start);
    h->start[nb] = n;
    return MPS_OK;
}

/* Calls fn(ctx, a, b, r2) once for each pair a < b of the n points of h
 * closer than sqrt(rad2) <= the cell width. Serial: the callers' loops are
 * short, and threads would cost more than they save. */
static void hgrid_pairs(const struct hgrid *h, const double (*x)[MPS_DIM], size_t n, double rad2,
                        void (*fn)(void *, size_t, size_t, double), void *ctx)
{
    for (size_t a = 0; a < n; a++)
        for (long cy = h->cell[a][1] - 1; cy <= h->cell[a][1] + 1; cy++)
            for (long cx = h->cell[a][0] - 1; cx <= h->cell[a][0] + 1; cx++) {
                size_t bk = hbucket(h, cx, cy);
                for (size_t k = h->start[bk]; k < h->start[bk + 1]; k++) {
                    size_t b = h->idx[k];
                    if (b <= a || h->cell[b][0] != cx || h->cell[b][1] != cy)
                        continue;
                    double dx = x[b][0] - x[a][0], dy = x[b][1] - x[a][1];
                    double r2 = dx * dx + dy * dy;
                    if (r2 < rad2)
                        fn(ctx, a, b, r2);
                }
            }
}

struct solid_mps_frac {
    long broken;                     /* bonds broken, pairs */
    /* contact (scene.contact != NONE) */
    double modulus[SOLID_MAX_BODIES];  /* M = lambda + 2 mu, Pa */
    double minv[SOLID_MAX_BODIES];     /* 1 / (rho dp^2), per metre depth */
    size_t m, cap_m;                 /* surface particles listed */
    size_t *sidx;                    /* their indices */
    double (*sx)[MPS_DIM];           /* their positions when listed */
    struct hgrid g;
    size_t np, cap_p;                /* pairs within (1 + SKIN) l0 when listed */
    int (*pair)[2];
    double *pk;                      /* K_ij, Pa */
    int valid;
    long built_broken;               /* broken when listed */
    long builds, active_max;
    double gap_min;
};

int solid_mps_bond_intact(const struct solid_mps *s, size_t b)
{
    return s->bk[b] != 0.0; /* k_ij > 0 for every bond built (solid_mps.c) */
}

/* 1 if i and j are joined by an intact bond. Bonds of i are sorted by j. */
static int bonded(const struct solid_mps *s, size_t i, int j)
{
    for (size_t b = s->bstart[i]; b < s->bstart[i + 1] && s->bj[b] <= j; b++)
        if (s->bj[b] == j)
            return s->bk[b] != 0.0;
    return 0;
}

enum mps_status solid_mps_frac_create(struct solid_mps *s, struct mps_err *err)
{
    s->frac = NULL;
    if (s->scene.eps_max <= 0.0 && s->scene.contact == SOLID_CONTACT_NONE)
        return MPS_OK;
    struct solid_mps_frac *f = calloc(1, sizeof *f);
    if (!f)
        return mps_err_set(err, MPS_ENOMEM, "solid: out of memory");
    for (int b = 0; b < s->scene.nbodies; b++) {
        f->modulus[b] = s->mat[b].lambda + 2.0 * s->mat[b].mu;
        f->minv[b] = 1.0 / (s->mat[b].rho * s->dp * s->dp);
    }
    f->gap_min = INFINITY;
    if (s->nden) /* fracture: n_i of the intact bonds starts as n0_i */
        memcpy(s->nden, s->n0, s->n * sizeof *s->nden);
    s->frac = f;
    return MPS_OK;
}

void solid_mps_frac_destroy(struct solid_mps_frac **fp)
{
    if (!fp || !*fp)
        return;
    struct solid_mps_frac *f = *fp;
    free(f->sidx);
    free(f->sx);
    free(f->pair);
    free(f->pk);
    hgrid_free(&f->g);
    free(f);
    *fp = NULL;
}

void solid_mps_frac_strain(struct solid_mps *s)
{
    const size_t n = s->n;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    const double *blen = s->blen, *kq = s->kq;
    double *bk = s->bk, *bb = s->bb, *bbr = s->bbr, *q = s->q, *nden = s->nden;
    const size_t *bstart = s->bstart;
    const int *bj = s->bj;
    unsigned char *surface = s->surface;
    const double eps = s->scene.eps_max, re = SOLID_MPS_RE * s->dp;
    const double nlim = s->n0_lattice - SOLID_MPS_NC;
    long ends = 0, flipped = 0;
#pragma omp parallel for schedule(static) if (n >= SOLID_MPS_OMP_MIN) reduction(+ : ends, flipped)
    for (size_t i = 0; i < n; i++) {
        double xi = x[i][0], yi = x[i][1], sum = 0.0;
        int broke = 0;
        for (size_t b = bstart[i]; b < bstart[i + 1]; b++) {
            int j = bj[b];
            double rx = x[j][0] - xi, ry = x[j][1] - yi;
            double dl = sqrt(rx * rx + ry * ry) - blen[b];
            if (dl > eps * blen[b] && bk[b] != 0.0) { /* Eq. 47: w_ij = 0 for good */
                bk[b] = bb[b] = bbr[b] = 0.0;
                nden[i] -= mps_weight(blen[b], re);
                broke++;
            }
            sum += bb[b] * dl; /* Eq. 30 over the intact bonds */
        }
        q[i] = kq[i] * sum;
        if (broke) {
            ends += broke;
            if (!surface[i] && nden[i] < nlim) { /* Eq. 48, irreversible */
                surface[i] = 1;
                flipped++;
            }
        }
    }
    s->frac->broken += ends / 2; /* each bond breaks at both ends in the same pass */
    if (flipped)
        s->surface_rev++;
}

static enum mps_status grow_pairs(struct solid_mps_frac *f, struct mps_err *err)
{
    size_t cap = f->cap_p ? 2 * f->cap_p : 256;
    int(*p)[2] = realloc(f->pair, cap * sizeof *p);
    if (p)
        f->pair = p;
    double *pk = realloc(f->pk, cap * sizeof *pk);
    if (pk)
        f->pk = pk;
    if (!p || !pk)
        return mps_err_set(err, MPS_ENOMEM, "solid: no memory for %zu contact pairs", cap);
    f->cap_p = cap;
    return MPS_OK;
}

struct pair_ctx {
    struct solid_mps *s;
    enum mps_status st;
    struct mps_err *err;
};

/* A listed pair of surface particles that may touch: no intact bond between
 * them, and of different bodies if scene.contact says so. */
static void add_pair(void *vctx, size_t a, size_t b, double r2)
{
    struct pair_ctx *ctx = vctx;
    struct solid_mps *s = ctx->s;
    struct solid_mps_frac *f = s->frac;
    size_t i = f->sidx[a], j = f->sidx[b];
    int bi = s->body[i], bj = s->body[j];
    if (ctx->st != MPS_OK ||
        (s->scene.contact == SOLID_CONTACT_BODIES ? bi == bj : bonded(s, i, (int)j)))
        return;
    if (f->np == f->cap_p && (ctx->st = grow_pairs(f, ctx->err)) != MPS_OK)
        return;
    f->pair[f->np][0] = (int)i;
    f->pair[f->np][1] = (int)j;
    f->pk[f->np] = 2.0 * f->modulus[bi] * f->modulus[bj] / (f->modulus[bi] + f->modulus[bj]);
    f->np++;
}

/* The particles the contact sees: the surface (Eq. 48), and those that lost a
 * bond without becoming surface (one diagonal bond, w = 0.485 < nc): else a
 * loose particle at the other end of that bond could slip into the body
 * unseen (solid_mps_fracture.h). */
static int in_contact_set(const struct solid_mps *s, size_t i)
{
    return s->surface[i] || (s->nden && s->nden[i] < s->n0[i]);
}

/* Room for m particles in the contact set (their indices and positions). */
static enum mps_status grow_contact_set(struct solid_mps_frac *f, size_t m, struct mps_err *err)
{
    if (m <= f->cap_m)
        return MPS_OK;
    size_t *si = realloc(f->sidx, m * sizeof *si);
    if (si)
        f->sidx = si;
    double(*sx)[MPS_DIM] = realloc(f->sx, m * sizeof *sx);
    if (sx)
        f->sx = sx;
    if (!si || !sx)
        return mps_err_set(err, MPS_ENOMEM, "solid: no memory for %zu contact particles", m);
    f->cap_m = m;
    return MPS_OK;
}

/* Lists the pairs of the contact set closer than (1 + SKIN) l0 that may
 * touch: no intact bond between them, and of different bodies if
 * scene.contact says so. */
static enum mps_status build_pairs(struct solid_mps *s, struct mps_err *err)
{
    struct solid_mps_frac *f = s->frac;
    size_t m = 0;
    for (size_t i = 0; i < s->n; i++)
        m += in_contact_set(s, i);
    enum mps_status st = grow_contact_set(f, m, err);
    if (st)
        return st;
    m = 0;
    for (size_t i = 0; i < s->n; i++)
        if (in_contact_set(s, i)) {
            f->sidx[m] = i;
            f->sx[m][0] = s->x[i][0];
            f->sx[m][1] = s->x[i][1];
            m++;
        }
    f->m = m;
    const double rad = (1.0 + SOLID_FRAC_SKIN) * s->dp;
    const double(*sx)[MPS_DIM] = (const double(*)[MPS_DIM])f->sx;
    st = hgrid_build(&f->g, sx, m, rad, err);
    if (st != MPS_OK)
        return st;
    struct pair_ctx ctx = {s, MPS_OK, err};
    f->np = 0;
    hgrid_pairs(&f->g, sx, m, rad * rad, add_pair, &ctx);
    if (ctx.st != MPS_OK)
        return ctx.st;
    f->valid = 1;
    f->built_broken = f->broken;
    f->builds++;
    return MPS_OK;
}

/* The list holds every pair that can be closer than l0 until a listed
 * particle has moved half the skin, or a bond broke (new surface, new pair). */
static int list_stale(const struct solid_mps *s)
{
    const struct solid_mps_frac *f = s->frac;
    if (!f->valid || f->built_broken != f->broken)
        return 1;
    const double lim = 0.5 * SOLID_FRAC_SKIN * s->dp, lim2 = lim * lim;
    for (size_t a = 0; a < f->m; a++) {
        size_t i = f->sidx[a];
        double dx = s->x[i][0] - f->sx[a][0], dy = s->x[i][1] - f->sx[a][1];
        if (dx * dx + dy * dy > lim2)
            return 1;
    }
    return 0;
}

enum mps_status solid_mps_frac_contact(struct solid_mps *s, double dt, struct mps_err *err)
{
    struct solid_mps_frac *f = s->frac;
    if (list_stale(s)) {
        enum mps_status st = build_pairs(s, err);
        if (st != MPS_OK)
            return st;
    }
    const double l0 = s->dp, l02 = l0 * l0;
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    double(*v)[MPS_DIM] = s->v;
    const unsigned char *fixed = s->fixed;
    const int *body = s->body;
    long active = 0;
    double rmin = f->gap_min;
    for (size_t p = 0; p < f->np; p++) {
        int i = f->pair[p][0], j = f->pair[p][1];
        double rx = x[j][0] - x[i][0], ry = x[j][1] - x[i][1], r2 = rx * rx + ry * ry;
        if (r2 >= l02)
            continue;
        double r = sqrt(r2);
        active++;
        rmin = fmin(rmin, r);
        if (r <= 0.0)
            continue; /* no direction: the neighbours of the pair will part them */
        double fr = dt * f->pk[p] * (l0 - r) / r; /* |F| dt / |r_ij| */
        if (!fixed[i]) {
            double c = fr * f->minv[body[i]];
            v[i][0] -= c * rx;
            v[i][1] -= c * ry;
        }
        if (!fixed[j]) {
            double c = fr * f->minv[body[j]];
            v[j][0] += c * rx;
            v[j][1] += c * ry;
        }
    }
    f->gap_min = rmin;
    if (active > f->active_max)
        f->active_max = active;
    return MPS_OK;
}

double solid_mps_frac_energy(const struct solid_mps *s)
{
    const struct solid_mps_frac *f = s->frac;
    if (!f)
        return 0.0;
    double e = 0.0;
    for (size_t p = 0; p < f->np; p++) {
        int i = f->pair[p][0], j = f->pair[p][1];
        double r = hypot(s->x[j][0] - s->x[i][0], s->x[j][1] - s->x[i][1]);
        if (r < s->dp)
            e += 0.5 * f->pk[p] * (s->dp - r) * (s->dp - r);
    }
    return e;
}

struct gap_ctx {
    const struct solid_mps *s;
    double best2;
};

static void gap_pair(void *vctx, size_t i, size_t j, double r2)
{
    struct gap_ctx *ctx = vctx;
    if (r2 < ctx->best2 && !bonded(ctx->s, i, (int)j))
        ctx->best2 = r2;
}

double solid_mps_min_gap(const struct solid_mps *s, double radius)
{
    struct hgrid g = {0};
    struct mps_err err = {0};
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])s->x;
    struct gap_ctx ctx = {s, radius * radius};
    double best = NAN;
    if (hgrid_build(&g, x, s->n, radius, &err) == MPS_OK) {
        hgrid_pairs(&g, x, s->n, radius * radius, gap_pair, &ctx);
        best = sqrt(ctx.best2);
    }
    hgrid_free(&g);
    return best;
}

struct frac_scalars {
    int64_t broken, valid, built_broken, builds, active_max, m, np;
    double gap_min;
};

enum mps_status solid_mps_frac_put(const struct solid_mps *s, struct mps_ckpt *c,
                                   struct mps_err *err)
{
    const struct solid_mps_frac *f = s->frac;
    struct frac_scalars sc = {f->broken, f->valid, f->built_broken, f->builds, f->active_max,
                              (int64_t)f->m, (int64_t)f->np, f->gap_min};
    enum mps_status st;
    if ((st = mps_ckpt_put(c, "fracture", &sc, sizeof sc, err)) ||
        (st = mps_ckpt_put(c, "contact.sidx", f->sidx, f->m * sizeof *f->sidx, err)) ||
        (st = mps_ckpt_put(c, "contact.sx", f->sx, f->m * sizeof *f->sx, err)) ||
        (st = mps_ckpt_put(c, "contact.pair", f->pair, f->np * sizeof *f->pair, err)))
        return st;
    return mps_ckpt_put(c, "contact.k", f->pk, f->np * sizeof *f->pk, err);
}

enum mps_status solid_mps_frac_get(struct solid_mps *s, struct mps_ckpt *c, struct mps_err *err)
{
    struct solid_mps_frac *f = s->frac;
    struct frac_scalars sc;
    enum mps_status st = mps_ckpt_get(c, "fracture", &sc, sizeof sc, err);
    if (st)
        return st;
    if (sc.m < 0 || (size_t)sc.m > s->n || sc.np < 0)
        return mps_err_set(err, MPS_EINPUT, "checkpoint: contact list of %lld particles, "
                           "%lld pairs, for %zu particles", (long long)sc.m, (long long)sc.np,
                           s->n);
    size_t m = (size_t)sc.m, np = (size_t)sc.np;
    if ((st = grow_contact_set(f, m, err)))
        return st;
    while (np > f->cap_p)
        if ((st = grow_pairs(f, err)))
            return st;
    if ((st = mps_ckpt_get(c, "contact.sidx", f->sidx, m * sizeof *f->sidx, err)) ||
        (st = mps_ckpt_get(c, "contact.sx", f->sx, m * sizeof *f->sx, err)) ||
        (st = mps_ckpt_get(c, "contact.pair", f->pair, np * sizeof *f->pair, err)) ||
        (st = mps_ckpt_get(c, "contact.k", f->pk, np * sizeof *f->pk, err)))
        return st;
    for (size_t k = 0; k < np; k++)
        if (f->pair[k][0] < 0 || (size_t)f->pair[k][0] >= s->n || f->pair[k][1] < 0 ||
            (size_t)f->pair[k][1] >= s->n)
            return mps_err_set(err, MPS_EINPUT, "checkpoint: contact pair %zu out of range", k);
    for (size_t k = 0; k < m; k++)
        if (f->sidx[k] >= s->n)
            return mps_err_set(err, MPS_EINPUT, "checkpoint: contact particle %zu out of range", k);
    f->m = m;
    f->np = np;
    f->broken = sc.broken;
    f->valid = (int)sc.valid;
    f->built_broken = sc.built_broken;
    f->builds = sc.builds;
    f->active_max = sc.active_max;
    f->gap_min = sc.gap_min;
    return MPS_OK;
}

void solid_mps_frac_stats(const struct solid_mps *s, struct solid_mps_frac_stats *st)
{
    const struct solid_mps_frac *f = s->frac;
    memset(st, 0, sizeof *st);
    st->gap_min = INFINITY;
    for (size_t i = 0; i < s->n; i++)
        st->surface += s->surface[i];
    if (!f)
        return;
    st->broken = f->broken;
    st->builds = f->builds;
    st->pairs = (long)f->np;
    st->active_max = f->active_max;
    st->gap_min = f->gap_min;
}

void solid_mps_frac_summary(const struct solid_mps *s, struct mps_json *j)
{
    static const char *const modes[] = {"none", "bodies", "all"};
    struct solid_mps_frac_stats st;
    solid_mps_frac_stats(s, &st);
    mps_json_object(j, "fracture");
    if (s->scene.eps_max > 0.0)
        mps_json_num(j, "eps_max", s->scene.eps_max);
    mps_json_str(j, "contact", modes[s->scene.contact]);
    mps_json_int(j, "broken_bonds", st.broken);
    mps_json_int(j, "surface_particles", st.surface);
    mps_json_int(j, "contact_list_builds", st.builds);
    mps_json_int(j, "contacts_max", st.active_max);
    /* smallest distance of two touching surface particles over the run, / l0 */
    mps_json_num(j, "contact_gap_min_over_l0", isfinite(st.gap_min) ? st.gap_min / s->dp : NAN);
    mps_json_close(j);
}
