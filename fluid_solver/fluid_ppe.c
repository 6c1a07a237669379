#include "fluid_ppe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_shadow.h"
#include "mps_kernel.h"
#include "mps_mem.h"
#include "mps_omp.h"
#include "mps_simd.h"

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = need + need / 2 + 16;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

/* ppe_flag bits: what pass 1 needs to know of a neighbour, one load */
enum { PPE_F_UNKNOWN = 1, PPE_F_GHOST = 2, PPE_F_SURFACE_FLUID = 4, PPE_F_ROW = 8 };

/* Sums of pass 1 over a row's candidates (see row_weights). */
struct pass1_acc {
    double dsum, mom[2], srf[2], ws;
    int m, q;
};

/* Pass 1 over one chunk of candidates: their offsets bx, by, their weights
 * c w in wk, their ppe_flag bits in fb; packs the kept ones at wcol, wlap +
 * a->q. wlap + a->q may be wk itself, behind the candidate being read. */
static void pass1_chunk(size_t len, const int *nj, const double *bx, const double *by,
                        const double *wk, const int *fb, struct pass1_acc *a, int *wcol,
                        double *wlap)
{
    double dsum = 0.0, mom0 = 0.0, mom1 = 0.0, srf0 = 0.0, srf1 = 0.0, ws = 0.0;
    int m = 0, q = a->q;
    for (size_t k = 0; k < len; k++) {
        const int fl = fb[k];
        const double dx = bx[k], dy = by[k];
        const double cw = wk[k] * (double)((fl & (PPE_F_UNKNOWN | PPE_F_GHOST)) != 0);
        const double cu = cw * (double)(fl & PPE_F_UNKNOWN),
                     cs = cw * (double)((fl & PPE_F_SURFACE_FLUID) != 0);
        dsum += cu;
        /* same predicate as pass 2: r == re rounds to w = 0 */
        m += (cu > 0.0) & ((fl & PPE_F_ROW) != 0);
        mom0 += cw * dx;
        mom1 += cw * dy;
        srf0 += cs * dx;
        srf1 += cs * dy;
        ws += cs;
        wcol[q] = nj[k];
        wlap[q] = cw;
        q += cw > 0.0;
    }
    a->dsum += dsum;
    a->mom[0] += mom0;
    a->mom[1] += mom1;
    a->srf[0] += srf0;
    a->srf[1] += srf1;
    a->ws += ws;
    a->m += m;
    a->q = q;
}

#ifdef MPS_HAVE_WIDE
/* pass1_chunk eight candidates at a time (mps_simd_wide): masks instead of
 * products by 0 or 1, the kept ones packed by compress. Same terms, summed
 * in eight partial sums: other last bits. A store packs at most the lanes
 * of the group just loaded, so it never reaches a candidate not yet read. */
__attribute__((target("avx512f"))) static void pass1_chunk_avx512(
    size_t len, const int *nj, const double *bx, const double *by, const double *wk,
    const int *fb, struct pass1_acc *a, int *wcol, double *wlap)
{
    const __m512d zero = _mm512_setzero_pd();
    const __m512i f_ug = _mm512_set1_epi32(PPE_F_UNKNOWN | PPE_F_GHOST),
                  f_u = _mm512_set1_epi32(PPE_F_UNKNOWN),
                  f_s = _mm512_set1_epi32(PPE_F_SURFACE_FLUID), f_r = _mm512_set1_epi32(PPE_F_ROW);
    __m512d dsum = zero, mom0 = zero, mom1 = zero, srf0 = zero, srf1 = zero, ws = zero;
    int m = 0, q = a->q;
    for (size_t k = 0; k < len; k += 8) {
        const __mmask8 in = mps_lanes8(len - k);
        /* flags and indices: 32-bit lanes, the low eight used */
        const __m512i fl = _mm512_maskz_loadu_epi32(in, fb + k), j = _mm512_maskz_loadu_epi32(in, nj + k);
        const __m512d dx = _mm512_maskz_loadu_pd(in, bx + k), dy = _mm512_maskz_loadu_pd(in, by + k);
        const __m512d cw = _mm512_maskz_loadu_pd((__mmask8)_mm512_test_epi32_mask(fl, f_ug) & in, wk + k);
        const __m512d cu = _mm512_maskz_mov_pd((__mmask8)_mm512_test_epi32_mask(fl, f_u), cw);
        const __m512d cs = _mm512_maskz_mov_pd((__mmask8)_mm512_test_epi32_mask(fl, f_s), cw);
        dsum = _mm512_add_pd(dsum, cu);
        m += __builtin_popcount(_mm512_cmp_pd_mask(cu, zero, _CMP_GT_OQ) &
                                (__mmask8)_mm512_test_epi32_mask(fl, f_r));
        mom0 = _mm512_fmadd_pd(cw, dx, mom0);
        mom1 = _mm512_fmadd_pd(cw, dy, mom1);
        srf0 = _mm512_fmadd_pd(cs, dx, srf0);
        srf1 = _mm512_fmadd_pd(cs, dy, srf1);
        ws = _mm512_add_pd(ws, cs);
        const __mmask8 keep = _mm512_cmp_pd_mask(cw, zero, _CMP_GT_OQ);
        const int nk = __builtin_popcount(keep);
        const __mmask8 first = mps_lanes8((size_t)nk);
        _mm512_mask_storeu_pd(wlap + q, first, _mm512_maskz_compress_pd(keep, cw));
        _mm512_mask_storeu_epi32(wcol + q, first, _mm512_maskz_compress_epi32(keep, j));
        q += nk;
    }
    a->dsum += _mm512_reduce_add_pd(dsum);
    a->mom[0] += _mm512_reduce_add_pd(mom0);
    a->mom[1] += _mm512_reduce_add_pd(mom1);
    a->srf[0] += _mm512_reduce_add_pd(srf0);
    a->srf[1] += _mm512_reduce_add_pd(srf1);
    a->ws += _mm512_reduce_add_pd(ws);
    a->m += m;
    a->q = q;
}
#endif

/* Pass 1 for row particle i: packs the Laplacian neighbours that enter row i
 * (nonzero weight) at the front of its range of the list, their index in
 * f->wcol and c w_ij in f->wlap; returns their number in *nw, the number of
 * unknown neighbours, and the diagonal in *diag.
 * Paper walls (4.3): the neighbours that carry a pressure (fluid, wall, solid
 * surface); dummy particles are left out.
 * Neumann walls: fluid neighbours enter as unknowns (or P = 0 on the free
 * surface); boundary neighbours (wall, dummy, solid) take the pressure
 * P_j = P_i + rho g.(x_j - x_i), so their P_i - P_j is known and goes to
 * the right-hand side (pass 2), not to the diagonal.
 * solid_ppe: the solid surface as in the paper, the tank as with Neumann
 * walls. f->unknown and f->ghost (fluid_update_masks) hold who is which.
 * The loop has no data-dependent branch: a third of the skin list lies
 * beyond re, in an order the branch predictor cannot learn, so every
 * candidate is computed, masked and written, the write position advancing
 * only for kept ones; pass 2 then walks only the kept ones. Measured on the
 * 3 mm dam break, 2 threads: 1.60 to 1.52 ms per step for the assembly
 * (the same branch-free weight took the viscous Laplacian from 1.00 to
 * 0.65 ms). The weights are then computed apart, packed (mps_weights_r2):
 * 3.5 mm dam break, 2 threads, 1.05 to 0.82 ms. With AVX-512 the masks,
 * sums and packing go eight at a time (pass1_chunk_avx512): 0.76 to
 * 0.61 ms. */
static int row_weights(struct fluid *f, size_t i, double c, int wide, double *diag, int *nw)
{
    const double re = f->prm.re_lap * f->prm.dp;
    const int ghosts = f->prm.wall_bc != FLUID_WALL_PPE;
    const size_t k0 = f->nl.start[i], k1 = f->nl.start[i + 1];
    /* locals, so the stores below cannot make the compiler reload them */
    const int *restrict nj = f->nl.j;
    const double(*restrict x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    const unsigned char *restrict flag = f->ppe_flag;
    int *wcol = f->wcol + k0;
    double *wlap = f->wlap + k0;
    const double xi = x[i][0], yi = x[i][1];
    struct pass1_acc a = {0};
    /* In chunks: the offsets and flags (gathered), their weights
     * (mps_weights_r2), then the masks, sums and packing. wlap holds the
     * chunk's r^2 and then c w before the kept values are packed at its
     * front. */
    double bx[MPS_WEIGHT_CHUNK], by[MPS_WEIGHT_CHUNK];
    int fb[MPS_WEIGHT_CHUNK];
    /* the solid surface particles within re, for the shadow test */
    int near[FLUID_SHADOW_MAX];
    const int nnear = f->prm.body_shadow ? fluid_shadow_near(f, i, near) : -1;
    for (size_t c0 = k0; c0 < k1; c0 += MPS_WEIGHT_CHUNK) {
        const size_t len = k1 - c0 < MPS_WEIGHT_CHUNK ? k1 - c0 : MPS_WEIGHT_CHUNK;
        double *wk = wlap + (c0 - k0);
        for (size_t k = 0; k < len; k++) {
            const int j = nj[c0 + k];
            const double dx = x[j][0] - xi, dy = x[j][1] - yi;
            bx[k] = dx;
            by[k] = dy;
            wk[k] = dx * dx + dy * dy;
            fb[k] = flag[j];
        }
        mps_weights_r2(wk, len, re, c);
        if (nnear >= 0)
            for (size_t k = 0; k < len; k++)
                if (wk[k] > 0.0 && fluid_shadowed(f, i, (size_t)nj[c0 + k], near, nnear))
                    wk[k] = 0.0;
#ifdef MPS_HAVE_WIDE
        if (wide)
            pass1_chunk_avx512(len, nj + c0, bx, by, wk, fb, &a, wcol, wlap);
        else
#endif
            pass1_chunk(len, nj + c0, bx, by, wk, fb, &a, wcol, wlap);
    }
    const int m = a.m, q = a.q;
    double dsum = a.dsum;
    const double *mom = a.mom, *srf = a.srf, ws = a.ws;
    *nw = q;
    double mn = sqrt(mom[0] * mom[0] + mom[1] * mom[1]);
    if (ghosts && f->prm.surface_closure && ws > 0.0 && mn > 0.0) {
        /* Free-surface closure: the neighbours missing beyond the free surface
         * would contribute sum_missing c w (P_j - P_i) = -grad P . m_i for a
         * linear field, with m_i = sum_present c w r_ij (the full lattice sums
         * to zero). With grad P = -(P_i / h_i) n, n = -m_i / |m_i| the outward
         * normal and h_i the mean depth of i below its surface neighbours
         * (where P = 0), that is -(|m_i| / h_i) P_i: a diagonal term, so the
         * matrix stays symmetric. Exact for a flat surface under hydrostatic
         * pressure; left out, the truncated sum acts as a zero-flux wall and
         * lifts the pressure of the layers under the surface. */
        const double hmin = 0.5 * f->prm.dp;
        double h = -(srf[0] * mom[0] + srf[1] * mom[1]) / (ws * mn);
        dsum += mn / (h > hmin ? h : hmin);
    }
    *diag = dsum;
    return m;
}

/* Eq. 10's sum over row i's kept Laplacian pairs (wcol, wlap of pass 1):
 * sum_j c w_ij (v*_j - v*_i).r_ij / r_ij^2, a pair closer than
 * fluid.divergence_floor read there (c w_ij rescaled to the floor's
 * weight). A second sweep of the row's pairs, taken only by the rows that
 * need it (fluid.divergence_stencil). */
static double row_divergence_sum(const struct fluid *f, size_t i)
{
    const double(*x)[MPS_DIM] = (const double(*)[MPS_DIM])f->x;
    const double(*vs)[MPS_DIM] = (const double(*)[MPS_DIM])f->vstar;
    const size_t k0 = f->nl.start[i];
    const double re = f->prm.re_lap * f->prm.dp;
    const double rf = f->prm.divergence_floor * f->prm.dp, rf2 = rf * rf;
    double dsum = 0.0;
    for (size_t k = k0; k < k0 + (size_t)f->nwlap[i]; k++) {
        const int j = f->wcol[k];
        double r2 = 0.0, dv = 0.0;
        for (int d = 0; d < MPS_DIM; d++) {
            double dx = x[j][d] - x[i][d];
            r2 += dx * dx;
            dv += (vs[j][d] - vs[i][d]) * dx;
        }
        if (r2 > 0.0 && r2 < rf2) /* wlap = c w(r): c times the floor's factor */
            dsum += f->wlap[k] / (re / sqrt(r2) - 1.0) * mps_divergence_floor_factor(r2, re, rf) * dv;
        else
            dsum += r2 > 0.0 ? f->wlap[k] * dv / r2 : 0.0;
    }
    return dsum;
}

/* fluid.density_dead_band: the density error less the band, 0 inside it.
 * Errors of a few hundredths of a percent are the lattice's own noise (a
 * square lattice jittered by 0.02 dp reads +0.08%); corrected at the paper's rate
 * they feed a lattice-scale mode that sets still water moving after 2-3 s
 * at 1 ms steps and within a second at 0.2 ms, pairs its particles up and
 * expands it 2.4% (docs/pressure.md). Without a correction inside the band
 * that mode has nothing to grow from; beyond it the error's excess is
 * corrected at the paper's rate, so the volume drifts by at most about the
 * band. Soft, not a cut-off, so that the source stays continuous in the
 * error (a cut-off would kick a particle whose error crosses the band). */
static double dead_band(double dn, double band)
{
    return dn > band ? dn - band : dn < -band ? dn + band : 0.0;
}

enum mps_status fluid_ppe_assemble(struct fluid *f, double dt, struct mps_err *err)
{
    const struct fluid_params *p = &f->prm;
    const size_t n = f->ps.n;
    int nrows = 0;
    const int ghosts = p->wall_bc != FLUID_WALL_PPE;
    for (size_t i = 0; i < n; i++)
        f->row[i] = (f->unknown[i] && !f->surface[i]) ? nrows++ : -1;
    f->nrows = nrows;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        f->ppe_flag[i] = (unsigned char)((f->unknown[i] ? PPE_F_UNKNOWN : 0) |
                                         (f->ghost[i] ? PPE_F_GHOST : 0) |
                                         (f->is_fluid[i] && f->surface[i] ? PPE_F_SURFACE_FLUID : 0) |
                                         (f->row[i] >= 0 ? PPE_F_ROW : 0));

    size_t rcap = f->cap_rows;
    if (grow((void **)&f->rowptr, &rcap, (size_t)nrows + 1, sizeof(int)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows", nrows);
    size_t rcap2 = f->cap_rows, rcap3 = f->cap_rows;
    if (grow((void **)&f->rhs, &rcap2, (size_t)nrows + 1, sizeof(double)) ||
        grow((void **)&f->sol, &rcap3, (size_t)nrows + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows", nrows);
    f->cap_rows = rcap < rcap2 ? (rcap < rcap3 ? rcap : rcap3) : (rcap2 < rcap3 ? rcap2 : rcap3);
    double *terms = NULL;
    if (f->keep_ppe_terms) {
        if (grow((void **)&f->ppe_terms, &f->cap_ppe_terms, ((size_t)nrows + 1) * FLUID_PPE_TERMS,
                 sizeof(double)))
            return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows' terms", nrows);
        terms = f->ppe_terms;
    }

    const double c = 2.0 * MPS_DIM / (f->lambda_lap * f->n0_lap);
    /* The first step has no earlier pressure that belongs to the flow (the
     * initial field is a guess: hydrostatic under a gate that has just
     * gone), so it solves the incompressible problem; from then on the
     * compressibility term acts on the change of pressure (fluid_ppe.h).
     * Starting from the guess instead sent a rarefaction through the dam
     * break's column: 90% of it at P = 0 after 1.6 ms, 20 ms to recover
     * (docs/pressure.md). */
    const int first = f->step == 0 && p->mixed_source && ghosts;
    const double comp = first ? 0.0 : f->rho_inertial * p->alpha / (dt * dt);
    /* Eq. 23's kappa rho/dt^2 corrects a fraction kappa of the density
     * error per step: its pressure scales as 1/dt^2, so a step halved (an
     * output time, an impact) quadrupled it, and the persistent deficit
     * under the surface turned most of the water to P = 0 for a step
     * (docs/pressure.md). Steps shorter than fluid.kappa_dt correct
     * kappa dt / kappa_dt instead, a fixed rate whatever the step; longer
     * ones correct kappa, never more (at 2 kappa per step still water at
     * dt = 1 ms drifted to 0.05 m/s in 2 s). The default, kappa_dt = 0, is
     * Eq. 23 as printed: at 5e-4 s the correction was too weak at the 3 mm
     * plate's steps and its water expanded over the walls (1756 of its 4656
     * particles lost by 0.67 s; docs/pressure.md). A step shorter than
     * the CFL step (the run's last, cut to land on end_time) corrects
     * kappa dt / dt_cfl: as printed, the last snapshot of the 4 mm dam
     * break had 95% of its interior at P = 0. */
    double dtk = dt > p->kappa_dt ? dt : p->kappa_dt;
    if (f->last.dt_cfl > dtk)
        dtk = f->last.dt_cfl;
    /* fluid.kappa_step_decay: the CFL step drops by half in one step when
     * the front hits a wall or a splash speeds up, and with it Eq. 23's
     * pressure quadruples against a density deficit built up under the
     * weaker correction: in the 6 mm plate 34 steps of 1 s had over half of
     * the interior at P = 0, each right after such a drop. Letting the
     * reference step fall at most by the decay per step spreads that
     * over several steps (docs/pressure.md). */
    if (p->kappa_step_decay > 0.0 && p->kappa_step_decay * f->dt_kappa > dtk)
        dtk = p->kappa_step_decay * f->dt_kappa;
    f->last.dt_kappa = dtk;
    /* fluid.kappa_step_decay_expansion: in expanded water (n < n0) Eq. 23
     * pulls the pressure down, by 1/(dt dtk). When the CFL step keeps
     * falling for several steps (it fell 3.5 times in 5 ms at 0.34 s in the
     * 3 mm plate) dtk at 0.95 a step keeps pace within about 25 steps, the
     * tension in the deep water's rows outgrows its hydrostatic pressure,
     * and the clamp set 53-97% of the pool to P = 0 for a step. A slower
     * decay on those rows alone holds the tension while the compression
     * rows, which resist an impact, still follow the step as before
     * (docs/pressure.md, "Expanded water follows the step more slowly"). */
    double dtk_expansion = dtk;
    if (p->kappa_step_decay_expansion > 0.0 &&
        p->kappa_step_decay_expansion * f->dt_kappa_expansion > dtk_expansion)
        dtk_expansion = p->kappa_step_decay_expansion * f->dt_kappa_expansion;
    f->last.dt_kappa_expansion = dtk_expansion;
    const double src = p->kappa * f->rho_inertial / (dt * dtk) / f->n0;
    const double src_expansion = p->kappa * f->rho_inertial / (dt * dtk_expansion) / f->n0;
    const double band = p->density_dead_band * f->n0;
    const int mixed = p->mixed_source;
    /* rho_inertial: rho, or with side walls rho (1 + delta / b), the inertia
     * the pressure's correction moves (fluid_create) */
    const double div_coef = f->rho_inertial / dt;
    /* Eq. 10 on the Laplacian's neighbours (fluid.divergence_stencil), from
     * the weights pass 1 packed: d / n0 at re_lap times sum_j w_ij
     * (v*_j - v*_i).r_ij / r_ij^2, w_ij being wlap / c. Most of the
     * divergence Eq. 10 measures is left after the projection and comes
     * back the next step, projected again as pressure noise times rho/dt;
     * over re_lap Eq. 10 measures about half as much of it as over re_n
     * (docs/pressure.md, "The divergence on the Laplacian's stencil"). */
    const int div_wide = mixed && p->divergence_wide;
    /* fluid.divergence_stencil = near_bodies: the rows that reach a solid
     * particle within re_lap (and the solid's own rows) take it on the
     * Laplacian's stencil too, the others keep Eq. 10 at re_n from
     * fluid.c: the plate's force is then as smooth as with the wide
     * divergence everywhere, and the free surface away from bodies keeps
     * the narrow one, without which Eq. 7's density term lets still water
     * go unstable (docs/pressure.md, "The divergence near bodies"). */
    const int div_near = mixed && p->divergence_near_bodies && n > f->nfixed_end;
    const double div_norm = MPS_DIM / (c * f->n0_lap);

    /* pass 1: weights, and entries per row (+1 for the diagonal); the
     * diagonal sum goes to rhs temporarily */
    size_t npairs = f->nl.start[f->nl.n];
    size_t wcap = f->cap_wlap;
    if (grow((void **)&f->wlap, &wcap, npairs + 1, sizeof(double)) ||
        grow((void **)&f->wcol, &f->cap_wlap, npairs + 1, sizeof(int)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %zu pairs", npairs);
    if (wcap < f->cap_wlap)
        f->cap_wlap = wcap;
    int *rowptr = f->rowptr;
    rowptr[0] = 0;
    const int wide = mps_simd_wide();
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < n; i++)
        if (f->row[i] >= 0)
            rowptr[f->row[i] + 1] = row_weights(f, i, c, wide, &f->rhs[f->row[i]], &f->nwlap[i]) + 1;
    for (int r = 0; r < nrows; r++)
        rowptr[r + 1] += rowptr[r];
    size_t nnz = (size_t)rowptr[nrows], ccap = f->cap_nnz, vcap = f->cap_nnz;
    if (grow((void **)&f->col, &ccap, nnz + 1, sizeof(int)) ||
        grow((void **)&f->val, &vcap, nnz + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %zu nonzeros", nnz);
    f->cap_nnz = ccap < vcap ? ccap : vcap;

    /* pass 2: values. Neighbour lists are sorted by particle index and rows
     * follow particle order, so columns come out sorted; the diagonal is
     * inserted in its place. */
#pragma omp parallel for schedule(dynamic, MPS_OMP_ROW_CHUNK)
    for (size_t i = 0; i < n; i++) {
        int r = f->row[i];
        if (r < 0)
            continue;
        int s = rowptr[r], m = rowptr[r + 1] - s - 1;
        int *cols = f->col + s;
        double *vals = f->val + s, diag = f->rhs[r];
        int q = 1;
        double ghost = 0.0;
        int body = div_near && i >= f->nfixed_end;
        const size_t k0 = f->nl.start[i];
        for (size_t k = k0; k < k0 + (size_t)f->nwlap[i]; k++) {
            int j = f->wcol[k];
            body |= div_near && (size_t)j >= f->nfixed_end;
            if (f->row[j] >= 0) {
                cols[q] = f->row[j];
                vals[q++] = -f->wlap[k];
            } else if (f->ghost[j]) {
                /* c w_ij (P_j - P_i) = c w_ij rho g.(x_j - x_i), to the right */
                double gx = 0.0;
                for (int d = 0; d < MPS_DIM; d++)
                    gx += f->acc[i][d] * (f->x[j][d] - f->x[i][d]);
                ghost += f->wlap[k] * p->rho * gx;
            }
        }
        int k = 0;
        while (k < m && cols[k + 1] < r) {
            cols[k] = cols[k + 1];
            vals[k] = vals[k + 1];
            k++;
        }
        cols[k] = r;
        vals[k] = diag + comp;
        /* Eq. 23's density term, its error relative to n0 either way */
        double dn = p->density_quadratic ? f->n0 * (f->nq[i] / f->nq0 - 1.0) : f->nd[i] - f->n0;
        dn = dead_band(dn, band);
        const double density = (dn < 0.0 ? src_expansion : src) * dn;
        f->rhs[r] = ghost + density;
        if (div_wide || body)
            f->div[i] = div_norm * row_divergence_sum(f, i);
        double memory = 0.0, divergence = 0.0;
        if (mixed) { /* with Neumann walls compressibility acts on the change of
                      * pressure, see fluid_ppe.h */
            memory = ghosts ? comp * f->p[i] : 0.0;
            divergence = -f->div[i] * div_coef;
            f->rhs[r] += memory + divergence;
        }
        if (terms) {
            double *rec = terms + (size_t)r * FLUID_PPE_TERMS;
            for (int d = 0; d < MPS_DIM; d++)
                rec[d] = f->x[i][d];
            rec[MPS_DIM] = ghost;
            rec[MPS_DIM + 1] = density;
            rec[MPS_DIM + 2] = memory;
            rec[MPS_DIM + 3] = divergence;
        }
        f->sol[r] = f->p[i]; /* warm start */
    }
    return MPS_OK;
}

static int cmp_key_row(const void *a, const void *b)
{
    const long long *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : (x[1] > y[1]) - (x[1] < y[1]);
}

/* pcg_defl's aggregates: the PPE rows in each square cell of side
 * fluid.ppe_coarse_cell spacings (at x*). A direct cell -> aggregate map,
 * numbered along the box's shorter side first, when the rows' bounding box
 * has few enough cells, else a sort by cell (row-major). */
static enum mps_status ppe_aggregates(struct fluid *f, int *nagg, struct mps_err *err)
{
    const size_t n = f->ps.n, nr = (size_t)f->nrows;
    const double h = f->prm.ppe_coarse_cell * f->prm.dp;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        if (f->row[i] >= 0)
            for (int d = 0; d < 2; d++) {
                lo[d] = f->x[i][d] < lo[d] ? f->x[i][d] : lo[d];
                hi[d] = f->x[i][d] > hi[d] ? f->x[i][d] : hi[d];
            }
    const double nxd = floor((hi[0] - lo[0]) / h) + 1.0, nyd = floor((hi[1] - lo[1]) / h) + 1.0;
    const int direct = nxd * nyd <= 16.0 * (double)nr + 65536.0;
    const size_t ncell = direct ? (size_t)nxd * (size_t)nyd : 0, nx = (size_t)nxd;
    if (grow((void **)&f->agg, &f->cap_agg, nr + 1, sizeof *f->agg) ||
        (direct && grow((void **)&f->aggmap, &f->cap_aggmap, ncell + 1, sizeof *f->aggmap)) ||
        (!direct && grow((void **)&f->aggkey, &f->cap_aggkey, 2 * nr + 2, sizeof *f->aggkey)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for the coarse space");
    int m = 0;
    if (direct) {
        /* each row's cell (in agg for now) and the occupied cells, then
         * the cells numbered along the shorter side of the box first: E's
         * bandwidth is then the short side's count of cells, small enough
         * on a spread-out flow for a band factor (fluid_defl.c,
         * NATURAL_MAX_BW) */
        const size_t ny = (size_t)nyd;
        for (size_t c = 0; c < ncell; c++)
            f->aggmap[c] = -1;
        for (size_t i = 0; i < n; i++) {
            int r = f->row[i];
            if (r < 0)
                continue;
            size_t cx = (size_t)((f->x[i][0] - lo[0]) / h), cy = (size_t)((f->x[i][1] - lo[1]) / h);
            f->agg[r] = (int)(cy * nx + cx);
            f->aggmap[cy * nx + cx] = 0;
        }
        const int y_fast = ny <= nx;
        const size_t nslow = y_fast ? nx : ny, nfast = y_fast ? ny : nx;
        for (size_t a = 0; a < nslow; a++)
            for (size_t b = 0; b < nfast; b++) {
                int *c = &f->aggmap[y_fast ? b * nx + a : a * nx + b];
                if (*c == 0)
                    *c = ++m;
            }
        for (size_t r = 0; r < nr; r++)
            f->agg[r] = f->aggmap[f->agg[r]] - 1;
    } else {
        for (size_t i = 0, k = 0; i < n; i++) {
            if (f->row[i] < 0)
                continue;
            long long cx = (long long)((f->x[i][0] - lo[0]) / h);
            long long cy = (long long)((f->x[i][1] - lo[1]) / h);
            f->aggkey[2 * k] = cy * (long long)(nxd + 1.0) + cx;
            f->aggkey[2 * k++ + 1] = f->row[i];
        }
        qsort(f->aggkey, nr, 2 * sizeof *f->aggkey, cmp_key_row);
        for (size_t k = 0; k < nr; k++) {
            m += k > 0 && f->aggkey[2 * k] != f->aggkey[2 * k - 2];
            f->agg[f->aggkey[2 * k + 1]] = m;
        }
        m += nr > 0;
    }
    *nagg = m;
    return MPS_OK;
}

/* The per-row arrays of release_tension, grown together to one capacity. */
static int grow_held_rows(struct fluid *f, size_t need)
{
    if (need <= f->cap_held_rows)
        return 0;
    const size_t c = need + need / 2 + 16;
    int fail = 0;
    f->rhs_assembled = mps_realloc_or_flag(f->rhs_assembled, c, sizeof(double), &fail);
    f->row_list = mps_realloc_or_flag(f->row_list, c, sizeof(int), &fail);
    f->row_touched = mps_realloc_or_flag(f->row_touched, c, 1, &fail);
    f->row_seed = mps_realloc_or_flag(f->row_seed, c, 1, &fail);
    f->row_is_fluid = mps_realloc_or_flag(f->row_is_fluid, c, 1, &fail);
    f->row_held = mps_realloc_or_flag(f->row_held, c, 1, &fail);
    f->row_held_next = mps_realloc_or_flag(f->row_held_next, c, 1, &fail);
    if (fail)
        return -1; /* those that grew stay valid; the capacity stays the smaller */
    f->cap_held_rows = c;
    return 0;
}

/* The first held set, from projected Gauss-Seidel sweeps (fluid.tension_sweeps)
 * on the assembled system. Holding just the rows the first solve left
 * negative takes 2-3 more solves a step to settle (4 mm dam break): their
 * neighbours, computed against them, go negative in turn, and rows held
 * too early are let go. The sweeps, from the clamped pressure, let the
 * rows around a negative one feel it clamped; on the recorded event steps
 * they left within 2-3 rows the set the solves settle on (bench/tension_sets.py).
 * Only the rows within three neighbour rings of a negative one are swept:
 * elsewhere the first solve's pressure stands. Serial, in row order, so
 * the start is the same for any thread count. seed: the rows swept around,
 * the first solve's negative fluid rows with f->sol its pressure, or
 * (fluid.tension_start = last_step) the rows the last step held with
 * f->sol the last step's pressure, then the first solve's rows newly
 * negative; held: out, the swept rows' entries set (P = 0 or not), the
 * others kept (seed may be held); f->sol the swept pressure (the next
 * solve's warm start). mark: scratch, one byte a row. Returns the rows
 * held. */
static int held_start_sweeps(struct fluid *f, const unsigned char *is_fluid, const unsigned char *seed,
                             unsigned char *held, unsigned char *mark)
{
    const int nr = f->nrows;
    int *local = f->row_list, nlocal = 0;
    memset(mark, 0, (size_t)nr);
    for (int r = 0; r < nr; r++)
        if (seed[r]) {
            mark[r] = 1;
            local[nlocal++] = r;
        }
    for (int ring = 0, from = 0; ring < 3; ring++) {
        const int to = nlocal;
        for (int k = from; k < to; k++)
            for (int e = f->rowptr[local[k]]; e < f->rowptr[local[k] + 1]; e++) {
                const int q = f->col[e];
                if (!mark[q]) {
                    mark[q] = 1;
                    local[nlocal++] = q;
                }
            }
        from = to;
    }
    /* row order: the sweep then runs as a plain Gauss-Seidel over the rows */
    nlocal = 0;
    for (int r = 0; r < nr; r++)
        if (mark[r])
            local[nlocal++] = r;
    double *P = f->sol;
    for (int k = 0; k < nlocal; k++)
        if (is_fluid[local[k]] && P[local[k]] < 0.0)
            P[local[k]] = 0.0;
    for (int sweep = 0; sweep < f->prm.tension_sweeps; sweep++)
        for (int k = 0; k < nlocal; k++) {
            const int r = local[k];
            double off = 0.0, diag = 0.0;
            for (int e = f->rowptr[r]; e < f->rowptr[r + 1]; e++) {
                if (f->col[e] == r)
                    diag = f->val[e];
                else
                    off += f->val[e] * P[f->col[e]];
            }
            if (!(diag > 0.0))
                continue; /* not the PPE's M-matrix row: leave it as solved */
            const double v = (f->rhs[r] - off) / diag;
            P[r] = (is_fluid[r] && v < 0.0) ? 0.0 : v;
        }
    for (int k = 0; k < nlocal; k++) {
        const int r = local[k];
        held[r] = is_fluid[r] && P[r] <= 0.0;
    }
    int nheld = 0;
    for (int r = 0; r < nr; r++)
        nheld += held[r];
    return nheld;
}

/* The rows whose matrix values change when the rows with now[r] != was[r]
 * (was = NULL: all clear) change between held and not: those rows and
 * their neighbours, the pattern being symmetric. Into f->row_list in row
 * order; returns how many. */
static int rows_touched(struct fluid *f, const unsigned char *now, const unsigned char *was)
{
    const int nr = f->nrows;
    unsigned char *touched = f->row_touched;
    memset(touched, 0, (size_t)nr);
    for (int r = 0; r < nr; r++)
        if (now[r] != (was ? was[r] : 0)) {
            touched[r] = 1;
            for (int e = f->rowptr[r]; e < f->rowptr[r + 1]; e++)
                touched[f->col[e]] = 1;
        }
    int n = 0;
    for (int r = 0; r < nr; r++)
        if (touched[r])
            f->row_list[n++] = r;
    return n;
}

/* Water holds no tension (fluid.tension_solves). Clamping the solution
 * after one solve leaves each row next to a negative one with the pressure
 * computed against that negative value, too low: in the 4 mm dam break's
 * thin water behind the front half of it then went to P = 0 for a step
 * whenever the divergence part of the source dipped (docs/pressure.md,
 * "The two halves of the mixed source"). Here the fluid rows are split
 * into those held at P = 0 (the water there may expand: A P - b >= 0) and
 * the rest (A P = b, P >= 0), a linear complementarity problem; A is an
 * M-matrix, for which the primal-dual active set below (hold the rows
 * that came out negative, let go the held ones whose equation asks for a
 * pressure, solve again) settles in a few solves, to the one solution
 * whatever the set it starts from. The held rows are decoupled, not
 * removed, so the matrix keeps its pattern and rows. warm: the set starts
 * from the rows the last step held (fluid.tension_start = last_step), and
 * the first solve is the first with rows held: the tension moves little in
 * a step, so the solve without any held that would find it again is spared
 * (0.8 mm dam break: 3.5 solves a step -> 2.1, docs/fluid_speed.md). */
static enum mps_status release_tension(struct fluid *f, struct fluid_linsolve_stats *stats,
                                       int warm, struct mps_err *err)
{
    const int nr = f->nrows;
    const size_t nnz = (size_t)f->rowptr[nr];
    if (grow((void **)&f->val_assembled, &f->cap_held_nnz, nnz + 1, sizeof(double)))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %zu nonzeros", nnz);
    if (grow_held_rows(f, (size_t)nr + 1))
        return mps_err_set(err, MPS_ENOMEM, "PPE: out of memory for %d rows", nr);
    unsigned char *is_fluid = f->row_is_fluid, *held = f->row_held, *next = f->row_held_next;
    double *val0 = f->val_assembled, *rhs0 = f->rhs_assembled;
    for (size_t i = 0; i < f->ps.n; i++)
        if (f->row[i] >= 0)
            is_fluid[f->row[i]] = f->is_fluid[i];
    int nheld = 0;
    if (warm) {
        for (size_t i = 0; i < f->ps.n; i++)
            if (f->row[i] >= 0)
                held[f->row[i]] = is_fluid[f->row[i]] && f->ppe_held[i];
        for (int r = 0; r < nr; r++)
            nheld += held[r];
    } else {
        for (int r = 0; r < nr; r++) {
            held[r] = is_fluid[r] && f->sol[r] < 0.0;
            nheld += held[r];
        }
    }
    if (nheld == 0)
        return MPS_OK;
    /* warm: the sweeps may let go every row; the loop's first solve is then
     * the plain one */
    if (f->prm.tension_sweeps > 0)
        nheld = held_start_sweeps(f, is_fluid, held, held, next);
    memcpy(val0, f->val, nnz * sizeof(double));
    memcpy(rhs0, f->rhs, (size_t)nr * sizeof(double));
    struct fluid_csr A = {nr, f->rowptr, f->col, f->val};
    enum mps_status st = MPS_OK;
    int solves = 0, changed = 1;
    int nlist = rows_touched(f, held, NULL);
    while (changed && solves < f->prm.tension_solves + warm) {
        /* a held row keeps its diagonal and rhs 0, so its solution is 0;
         * only the rows the last change of the set touched are rewritten */
        const int *list = f->row_list;
#pragma omp parallel for schedule(static)
        for (int k = 0; k < nlist; k++) {
            const int r = list[k];
            f->rhs[r] = held[r] ? 0.0 : rhs0[r];
            for (int e = f->rowptr[r]; e < f->rowptr[r + 1]; e++) {
                int q = f->col[e];
                f->val[e] = (q != r && (held[r] || held[q])) ? 0.0 : val0[e];
            }
            if (held[r])
                f->sol[r] = 0.0;
        }
        struct fluid_linsolve_stats ls;
        const int first = warm && solves == 0; /* a new matrix: set up in full */
        if (!first)
            fluid_linsolve_changed_rows(f->ls, list, nlist); /* held rows keep their zeros */
        st = fluid_linsolve_solve(f->ls, &A, f->rhs, f->sol, first ? stats : &ls, err);
        if (st) {
            mps_err_prefix(err, "PPE at t = %.6g s, solve %d with %d rows under tension held "
                                "at P = 0: ", f->time, solves + 2 - warm, nheld);
            break;
        }
        if (!first)
            stats->iterations += ls.iterations;
        solves++;
        /* exactly 0: pcg_defl's coarse correction leaves a round-off there */
#pragma omp parallel for schedule(static)
        for (int r = 0; r < nr; r++)
            if (held[r])
                f->sol[r] = 0.0;
        changed = 0;
        nheld = 0;
#pragma omp parallel for schedule(static) reduction(| : changed) reduction(+ : nheld)
        for (int r = 0; r < nr; r++) {
            if (held[r]) { /* let go if its equation asks for a pressure */
                double w = -rhs0[r];
                for (int k = f->rowptr[r]; k < f->rowptr[r + 1]; k++)
                    w += val0[k] * f->sol[f->col[k]];
                next[r] = w >= 0.0;
            } else {
                next[r] = is_fluid[r] && f->sol[r] < 0.0;
            }
            changed |= next[r] != held[r];
            nheld += next[r];
        }
        if (changed && first && f->prm.tension_sweeps > 0) {
            /* rows newly under tension, the last step's held rows not near
             * them (an impact, a new sheet): swept as a first solve's
             * negative rows are, the rest of the set kept (0.8 mm dam
             * break: 1.1 more solves a step against 1.3 without) */
            unsigned char *seed = f->row_seed;
            int nseed = 0;
            for (int r = 0; r < nr; r++) {
                seed[r] = !held[r] && is_fluid[r] && f->sol[r] < 0.0;
                nseed += seed[r];
            }
            if (nseed > 0) {
                nheld = held_start_sweeps(f, is_fluid, seed, next, f->row_touched);
                changed = 0;
                for (int r = 0; r < nr; r++)
                    changed |= next[r] != held[r];
            }
        }
        if (changed)
            nlist = rows_touched(f, next, held);
        unsigned char *t = held;
        held = next;
        next = t;
    }
    f->row_held = held;
    f->row_held_next = next;
    f->last.tension_solves = solves - warm;
    /* the system as assembled, as --dump-ppe writes it */
    memcpy(f->val, val0, nnz * sizeof(double));
    memcpy(f->rhs, rhs0, (size_t)nr * sizeof(double));
    return st;
}

enum mps_status fluid_ppe_solve(struct fluid *f, struct fluid_linsolve_stats *stats,
                                struct mps_err *err)
{
    struct fluid_csr A = {f->nrows, f->rowptr, f->col, f->val};
    enum mps_status st = MPS_OK;
    if (f->nrows > 0 && fluid_linsolve_uses_aggregates(f->ls)) {
        int nagg = 0;
        st = ppe_aggregates(f, &nagg, err);
        if (!st)
            st = fluid_linsolve_set_aggregates(f->ls, f->agg, f->nrows, nagg, err);
        if (st)
            return st;
    }
    if (f->nrows > 0) {
        int warm = 0;
        if (f->prm.tension_solves > 0 && f->prm.tension_start_last)
            for (size_t i = 0; i < f->ps.n && !warm; i++)
                warm = f->row[i] >= 0 && f->is_fluid[i] && f->ppe_held[i];
        if (warm) {
            if ((st = release_tension(f, stats, 1, err)))
                return st;
        } else {
            st = fluid_linsolve_solve(f->ls, &A, f->rhs, f->sol, stats, err);
            if (st)
                return mps_err_prefix(err, "PPE at t = %.6g s (%d unknowns): ", f->time, f->nrows);
            if (f->prm.tension_solves > 0 && (st = release_tension(f, stats, 0, err)))
                return st;
        }
        const unsigned char *held = f->row_held;
        for (size_t i = 0; i < f->ps.n; i++)
            f->ppe_held[i] = f->prm.tension_solves > 0 && f->row[i] >= 0 && held[f->row[i]];
    } else {
        *stats = (struct fluid_linsolve_stats){0};
        memset(f->ppe_held, 0, f->ps.n);
    }
    const int clamp = f->prm.clamp_negative;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->ps.n; i++) {
        int r = f->row[i];
        double pi = r >= 0 ? f->sol[r] : 0.0;
        f->p[i] = (clamp && pi < 0.0) ? 0.0 : pi;
    }
    return st;
}

void fluid_ppe_boundary_pressure(struct fluid *f)
{
    const struct fluid_params *p = &f->prm;
    const double re = (p->re_n + 1.0) * p->dp, re2 = re * re;
    const size_t n = f->ps.n;
    /* Adami, Hu & Adams (2012): P_b = sum_f w (P_f + rho g.(x_b - x_f)) / sum_f w,
     * the hydrostatic extrapolation of the fluid pressures around b. Only the
     * gradient uses P_b (the PPE extrapolates from each row particle itself),
     * and it reaches the wall layer and the next one: a radius of re_n + dp
     * lets both see two rows of fluid. A wider one (re_lap) spreads impact
     * pressures along the wall and pushes the water off it (measured:
     * dam-break runs failed sooner, docs/fluid.md). */
#pragma omp parallel for schedule(static)
    for (size_t b = f->nfluid; b < n; b++) {
        if (!f->ghost[b])
            continue; /* a PPE unknown (solid_ppe: the solid surface) or no pressure */
        double s = 0.0, ws = 0.0;
        /* a tank particle's fluid neighbours are in nl_tank, a solid's in nl */
        const struct mps_nbr_list *l = f->nbr_query[b] ? &f->nl : &f->nl_tank;
        for (size_t k = l->start[b]; k < l->start[b + 1]; k++) {
            int j = l->j[k];
            if (!f->is_fluid[j])
                continue;
            double dx[MPS_DIM], r2 = 0.0, gx = 0.0;
            for (int d = 0; d < MPS_DIM; d++) {
                dx[d] = f->x[b][d] - f->x[j][d];
                r2 += dx[d] * dx[d];
                gx += f->acc[j][d] * dx[d];
            }
            if (r2 >= re2)
                continue;
            double w = mps_weight(sqrt(r2), re);
            s += w * (f->p[j] + p->rho * gx);
            ws += w;
        }
        /* not clamped: above the water line this is the linear extension
         * the PPE assumed; fluid_ppe_boundary_clamp() clamps after use */
        f->p[b] = ws > 0.0 ? s / ws : 0.0;
        f->surface[b] = ws == 0.0; /* dry: no fluid within reach */
    }
}

void fluid_ppe_boundary_clamp(struct fluid *f)
{
    if (!f->prm.clamp_negative)
        return;
    for (size_t b = f->nfluid; b < f->ps.n; b++)
        if (f->p[b] < 0.0)
            f->p[b] = 0.0;
}

enum mps_status fluid_ppe_dump(const struct fluid *f, const char *matrix_path,
                               const char *rhs_path, const char *terms_path,
                               struct mps_err *err)
{
    FILE *m = fopen(matrix_path, "w");
    if (!m)
        return mps_err_set(err, MPS_EIO, "%s: cannot write", matrix_path);
    size_t lower = 0;
    for (int r = 0; r < f->nrows; r++)
        for (int k = f->rowptr[r]; k < f->rowptr[r + 1]; k++)
            lower += f->col[k] <= r;
    fprintf(m, "%%%%MatrixMarket matrix coordinate real symmetric\n%d %d %zu\n", f->nrows,
            f->nrows, lower);
    for (int r = 0; r < f->nrows; r++)
        for (int k = f->rowptr[r]; k < f->rowptr[r + 1]; k++)
            if (f->col[k] <= r)
                fprintf(m, "%d %d %.17g\n", r + 1, f->col[k] + 1, f->val[k]);
    int bad = fclose(m);
    FILE *b = fopen(rhs_path, "w");
    if (bad || !b)
        return mps_err_set(err, MPS_EIO, "%s: cannot write", bad ? matrix_path : rhs_path);
    fprintf(b, "%%%%MatrixMarket matrix array real general\n%d 1\n", f->nrows);
    for (int r = 0; r < f->nrows; r++)
        fprintf(b, "%.17g\n", f->rhs[r]);
    if (fclose(b))
        return mps_err_set(err, MPS_EIO, "%s: cannot write", rhs_path);
    if (!terms_path || !f->ppe_terms)
        return MPS_OK;
    FILE *t = fopen(terms_path, "w");
    if (!t)
        return mps_err_set(err, MPS_EIO, "%s: cannot write", terms_path);
    fprintf(t, "# the rhs of each PPE row (ppe_b.mtx) in its parts, which sum to it; "
               "x at the assembly (m), parts in the rhs's units; pressure: the step's "
               "solution (Pa), before the clamp, the rows under tension held at 0 "
               "(fluid.tension_solves)\n");
    fprintf(t, MPS_DIM == 2 ? "row,x,y,ghost,density,compressibility,divergence,pressure\n"
                            : "row,x,y,z,ghost,density,compressibility,divergence,pressure\n");
    for (int r = 0; r < f->nrows; r++) {
        const double *q = f->ppe_terms + (size_t)r * FLUID_PPE_TERMS;
        fprintf(t, "%d", r + 1);
        for (int k = 0; k < FLUID_PPE_TERMS; k++)
            fprintf(t, ",%.17g", q[k]);
        fprintf(t, ",%.17g\n", f->sol[r]);
    }
    if (fclose(t))
        return mps_err_set(err, MPS_EIO, "%s: cannot write", terms_path);
    return MPS_OK;
}
