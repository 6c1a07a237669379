#include "fluid_shadow.h"

#include <math.h>

#include "mps_kernel.h"

/* A pair is shadowed when the line between its particles enters the body:
 * some solid surface particle s on or near the segment (a line crossing a
 * row of particles dp apart passes within dp/2 of one) has an end of the
 * segment more than dp/2 behind its face; s may be an end itself. n_s points
 * away from s's solid neighbours, as the face loads' normal
 * (fluid_coupling.c). The test is made on the pair in index order with s
 * among the solid surface particles within re_lap of both ends, so rows i
 * and j decide alike and the PPE matrix stays symmetric. */
#define SHADOW_NEAR 0.6   /* dp: a crossing line passes this close to a face particle */
#define SHADOW_BEHIND 0.5 /* dp: an end this far behind a face is beyond it */

static double dist2(const double *a, const double *b)
{
    double s = 0.0;
    for (int d = 0; d < MPS_DIM; d++)
        s += (a[d] - b[d]) * (a[d] - b[d]);
    return s;
}

/* how far x lies in front of the face of solid surface particle s */
static double in_front(const struct fluid *f, size_t s, const double *x)
{
    double e = 0.0;
    for (int d = 0; d < MPS_DIM; d++)
        e += (x[d] - f->x[s][d]) * f->body_n[s][d];
    return e;
}

void fluid_body_outward(const struct fluid *f, size_t i, double out[MPS_DIM])
{
    const double re = f->prm.re_n * f->prm.dp, re2 = re * re;
    for (int d = 0; d < MPS_DIM; d++)
        out[d] = 0.0;
    for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
        int j = f->nl.j[k];
        if (f->type[j] < SOLID_SURF_P)
            continue;
        double dx[MPS_DIM], r2 = mps_pair_delta((const double(*)[MPS_DIM])f->x, i, (size_t)j, dx);
        if (r2 >= re2 || r2 <= 0.0)
            continue;
        double w = mps_weight(sqrt(r2), re);
        for (int d = 0; d < MPS_DIM; d++)
            out[d] -= w * dx[d];
    }
}

void fluid_shadow_normals(struct fluid *f)
{
    const double re = f->prm.re_n * f->prm.dp, re2 = re * re;
#pragma omp parallel for schedule(static)
    for (size_t i = f->nfixed_end; i < f->ps.n; i++) {
        double out[MPS_DIM] = {0}, norm = 0.0;
        if (f->type[i] == SOLID_SURF_P)
            fluid_body_outward(f, i, out);
        for (int d = 0; d < MPS_DIM; d++)
            norm += out[d] * out[d];
        norm = sqrt(norm);
        for (int d = 0; d < MPS_DIM; d++)
            f->body_n[i][d] = norm > 0.0 ? out[d] / norm : 0.0;
    }
    /* A fluid particle that has crept behind a face (the creep at a wall,
     * docs/pressure.md) would be cut off from the water it came from and
     * left with the body's pressures alone: 8e7 Pa and 240 m/s in a rigid
     * plate at rest at 3 mm. It keeps all its pairs, and the pressure that
     * pushes it out. */
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->nfluid; i++) {
        double best = re2;
        int inside = 0;
        for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1]; k++) {
            int j = f->nl.j[k];
            if (f->type[j] != SOLID_SURF_P)
                continue;
            double r2 = dist2(f->x[i], f->x[j]);
            if (r2 < best) {
                best = r2;
                inside = in_front(f, (size_t)j, f->x[i]) < 0.0;
            }
        }
        f->in_body[i] = (unsigned char)inside;
    }
}


static double re_lap2(const struct fluid *f)
{
    const double re = f->prm.re_lap * f->prm.dp;
    return re * re;
}

int fluid_shadow_near(const struct fluid *f, size_t i, int *near)
{
    if (f->ps.n <= f->nfixed_end)
        return -1;
    const double re2 = re_lap2(f);
    int m = 0;
    for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1] && m < FLUID_SHADOW_MAX; k++) {
        const int j = f->nl.j[k];
        if (f->type[j] == SOLID_SURF_P && (size_t)j != i && dist2(f->x[j], f->x[i]) < re2)
            near[m++] = j;
    }
    return m > 0 || f->type[i] == SOLID_SURF_P ? m : -1;
}

int fluid_shadowed(const struct fluid *f, size_t i, size_t j, const int *near, int nnear)
{
    const size_t a = i < j ? i : j, b = i < j ? j : i;
    const double *xa = f->x[a], *xb = f->x[b], behind = -SHADOW_BEHIND * f->prm.dp,
                 near2 = SHADOW_NEAR * SHADOW_NEAR * f->prm.dp * f->prm.dp, re2 = re_lap2(f);
    if ((a < f->nfluid && f->in_body[a]) || (b < f->nfluid && f->in_body[b]))
        return 0;
    if ((f->type[a] == SOLID_SURF_P && in_front(f, a, xb) < behind) ||
        (f->type[b] == SOLID_SURF_P && in_front(f, b, xa) < behind))
        return 1;
    double ab[MPS_DIM], l2 = 0.0;
    for (int d = 0; d < MPS_DIM; d++) {
        ab[d] = xb[d] - xa[d];
        l2 += ab[d] * ab[d];
    }
    if (!(l2 > 0.0))
        return 0;
    for (int m = 0; m < nnear; m++) {
        const size_t s = (size_t)near[m];
        if (s == a || s == b || dist2(f->x[s], f->x[j]) >= re2)
            continue;
        double t = 0.0, q2 = 0.0;
        for (int d = 0; d < MPS_DIM; d++)
            t += (f->x[s][d] - xa[d]) * ab[d];
        t /= l2;
        if (t <= 0.0 || t >= 1.0)
            continue;
        for (int d = 0; d < MPS_DIM; d++) {
            double q = xa[d] + t * ab[d] - f->x[s][d];
            q2 += q * q;
        }
        if (q2 < near2) {
            double ea = in_front(f, s, xa), eb = in_front(f, s, xb);
            if ((ea < eb ? ea : eb) < behind)
                return 1;
        }
    }
    return 0;
}

void fluid_shadow_mask(const struct fluid *f, const struct mps_nbr_list *nl,
                       const unsigned char *query, unsigned char *use)
{
#pragma omp parallel for schedule(dynamic, 256)
    for (size_t i = 0; i < nl->n; i++) {
        if (query && !query[i])
            continue;
        int near[FLUID_SHADOW_MAX];
        const int nnear = fluid_shadow_near(f, i, near);
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; k++)
            use[k] = nnear < 0 || !fluid_shadowed(f, i, (size_t)nl->j[k], near, nnear);
    }
}

void fluid_shadow_dry(struct fluid *f)
{
    const double re2 = re_lap2(f);
#pragma omp parallel for schedule(dynamic, 64)
    for (size_t i = f->nfixed_end; i < f->ps.n; i++) {
        if (f->type[i] != SOLID_SURF_P || f->surface[i])
            continue;
        int near[FLUID_SHADOW_MAX], wet = 0;
        const int nnear = fluid_shadow_near(f, i, near);
        for (size_t k = f->nl.start[i]; k < f->nl.start[i + 1] && !wet; k++) {
            const size_t j = (size_t)f->nl.j[k];
            wet = f->is_fluid[j] && dist2(f->x[i], f->x[j]) < re2 &&
                  !fluid_shadowed(f, i, j, near, nnear);
        }
        f->surface[i] = (unsigned char)!wet;
    }
}
