#include "mps_nbr.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_simd.h"

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 256;
    while (c < need)
        c = c * 3 / 2 + 1;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

enum mps_status mps_nbr_grid_build(struct mps_nbr_grid *g, size_t n, const double (*x)[MPS_DIM],
                                   double cell, struct mps_err *err)
{
    double lo[MPS_DIM], hi[MPS_DIM];
    for (int d = 0; d < MPS_DIM; d++) {
        lo[d] = INFINITY;
        hi[d] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < MPS_DIM; d++) {
            double v = x[i][d];
            if (!isfinite(v))
                return mps_err_set(err, MPS_EDIVERGED,
                                   "particle %zu has a non-finite position (%g)", i, v);
            if (v < lo[d])
                lo[d] = v;
            if (v > hi[d])
                hi[d] = v;
        }
    if (n == 0)
        for (int d = 0; d < MPS_DIM; d++)
            lo[d] = hi[d] = 0.0;
    size_t ncells = 1;
    for (int d = 0; d < MPS_DIM; d++) {
        g->lo[d] = lo[d] - 0.5 * cell;
        double span = hi[d] - g->lo[d] + 0.5 * cell;
        double nd = floor(span / cell) + 1.0;
        if (nd > 1e7)
            return mps_err_set(err, MPS_EDIVERGED,
                               "particles spread over %g m along axis %d (%g cells): "
                               "a particle has flown away",
                               hi[d] - lo[d], d, nd);
        g->dims[d] = (int)nd;
        ncells *= (size_t)g->dims[d];
    }
    if (ncells > 200000000u)
        return mps_err_set(err, MPS_EDIVERGED, "neighbour grid would need %zu cells", ncells);
    g->cell = cell;
    g->ncells = ncells;
    g->n = n;
    if (grow((void **)&g->cell_start, &g->cap_cells, ncells + 1, sizeof(size_t)) ||
        grow((void **)&g->sorted, &g->cap_n, n + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory");
    /* cell_of shares cap_n with sorted; grow it to the same capacity. */
    size_t *co = realloc(g->cell_of, (g->cap_n) * sizeof(size_t));
    if (!co)
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory");
    g->cell_of = co;
    memset(g->cell_start, 0, (ncells + 1) * sizeof(size_t));
    double inv = 1.0 / cell;
    for (size_t i = 0; i < n; i++) {
        size_t c = 0;
        for (int d = MPS_DIM - 1; d >= 0; d--) {
            int k = (int)((x[i][d] - g->lo[d]) * inv);
            c = c * (size_t)g->dims[d] + (size_t)k;
        }
        g->cell_of[i] = c;
        g->cell_start[c + 1]++;
    }
    for (size_t c = 0; c < ncells; c++)
        g->cell_start[c + 1] += g->cell_start[c];
    /* Stable counting sort: particles stay in index order within a cell. */
    for (size_t i = 0; i < n; i++)
        g->sorted[g->cell_start[g->cell_of[i]]++] = i;
    for (size_t c = ncells; c > 0; c--)
        g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    if (grow((void **)&g->xs, &g->cap_xs, n + 1, sizeof *g->xs))
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory");
    for (size_t k = 0; k < n; k++)
        memcpy(g->xs[k], x[g->sorted[k]], sizeof g->xs[k]);
    return MPS_OK;
}

void mps_nbr_grid_free(struct mps_nbr_grid *g)
{
    free(g->cell_start);
    free(g->sorted);
    free(g->cell_of);
    free(g->xs);
    memset(g, 0, sizeof *g);
}


/* Room for npairs pairs in l: j, and r2 unless l->no_r2. */
static int grow_pairs(struct mps_nbr_list *l, size_t npairs)
{
    size_t c1 = l->cap_pairs, c2 = l->cap_pairs;
    if (grow((void **)&l->j, &c1, npairs + 1, sizeof(int)) ||
        (!l->no_r2 && grow((void **)&l->r2, &c2, npairs + 1, sizeof(double))))
        return -1;
    l->cap_pairs = l->no_r2 ? c1 : (c1 < c2 ? c1 : c2);
    return 0;
}

/* The block of cells around particle i's cell that a query visits: columns
 * a0..a1 of rows b0..b1, clipped to the grid. */
struct cell_window {
    int a0, a1, b0, b1;
};

static struct cell_window cell_window(const struct mps_nbr_grid *g, size_t i)
{
#if MPS_DIM != 2
#error "mps_nbr: only MPS_DIM == 2 is implemented"
#endif
    size_t c = g->cell_of[i];
    int cx = (int)(c % (size_t)g->dims[0]), cy = (int)(c / (size_t)g->dims[0]);
    struct cell_window w = {cx > 0 ? cx - 1 : 0, cx + 1 < g->dims[0] ? cx + 1 : g->dims[0] - 1,
                            cy > 0 ? cy - 1 : 0, cy + 1 < g->dims[1] ? cy + 1 : g->dims[1] - 1};
    return w;
}

/* Upper bound on the candidates in a window: the particles of its cells
 * (each row of cells is a contiguous stretch of sorted[]). */
static size_t candidates(const struct mps_nbr_grid *g, const struct cell_window *w)
{
    size_t m = 0;
    for (int b = w->b0; b <= w->b1; b++) {
        size_t row = (size_t)b * (size_t)g->dims[0];
        m += g->cell_start[row + (size_t)w->a1 + 1] - g->cell_start[row + (size_t)w->a0];
    }
    return m;
}

/* Writes the neighbours of i found in window w into jout/r2out (room for
 * candidates(g, w)) sorted by j and returns their number. Within a cell
 * particles are in index order; tmp (same room) holds these runs before
 * they are merged. */
#ifdef MPS_HAVE_WIDE
/* The candidate loop of visit() over slots k .. kend of one cell, eight at a
 * time (mps_simd_wide): the kept j (and r2) packed by compress at jtmp (and
 * r2tmp) + m; returns the new m. r2 is computed as in the scalar loop
 * (products, then the sum; no FMA), so the list is the same, bit for bit. */
__attribute__((target("avx512f"))) static size_t visit_cell_avx512(
    const struct mps_nbr_grid *g, size_t k, size_t kend, double xi, double yi, size_t i,
    double r2max, int *jtmp, double *r2tmp, int want_r2, size_t m)
{
    const __m512i even = _mm512_set_epi64(14, 12, 10, 8, 6, 4, 2, 0),
                  odd = _mm512_set_epi64(15, 13, 11, 9, 7, 5, 3, 1),
                  vi = _mm512_set1_epi64((long long)i);
    const __m512d vxi = _mm512_set1_pd(xi), vyi = _mm512_set1_pd(yi), vr2 = _mm512_set1_pd(r2max);
    for (; k < kend; k += 8) {
        const size_t left = kend - k;
        const __mmask8 in = mps_lanes8(left);
        /* the interleaved x, y of the eight: 16 doubles, the tail masked */
        const __mmask8 in_lo = mps_lanes8(2 * left), in_hi = left > 4 ? mps_lanes8(2 * (left - 4)) : 0;
        const __m512d lo = _mm512_maskz_loadu_pd(in_lo, &g->xs[k][0]),
                      hi = _mm512_maskz_loadu_pd(in_hi, &g->xs[k][0] + 8);
        const __m512d dx = _mm512_sub_pd(_mm512_permutex2var_pd(lo, even, hi), vxi),
                      dy = _mm512_sub_pd(_mm512_permutex2var_pd(lo, odd, hi), vyi);
        const __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
        const __m512i j = _mm512_maskz_loadu_epi64(in, g->sorted + k);
        const __mmask8 keep = _mm512_cmp_pd_mask(r2, vr2, _CMP_LT_OQ) &
                              _mm512_cmpneq_epi64_mask(j, vi) & in;
        const int nk = __builtin_popcount(keep);
        const __mmask16 first = mps_lanes8((size_t)nk);
        _mm512_mask_storeu_epi32(
            jtmp + m, first,
            _mm512_maskz_compress_epi32((__mmask16)keep,
                                        _mm512_castsi256_si512(_mm512_cvtepi64_epi32(j))));
        if (want_r2)
            _mm512_mask_storeu_pd(r2tmp + m, (__mmask8)first, _mm512_maskz_compress_pd(keep, r2));
        m += (size_t)nk;
    }
    return m;
}
#endif

static size_t visit(const struct mps_nbr_grid *g, const double (*x)[MPS_DIM], size_t i,
                    const struct cell_window *w, double r2max, int *jout, double *r2out,
                    int *jtmp, double *r2tmp, const int want_r2, const int wide)
{
    const double xi = x[i][0], yi = x[i][1];
    size_t runs[3 * 3 + 1], nruns = 0, m = 0;
    runs[0] = 0;
    for (int b = w->b0; b <= w->b1; b++) {
        size_t row = (size_t)b * (size_t)g->dims[0];
        for (int a = w->a0; a <= w->a1; a++) {
            /* one run per cell: sorted by index within the cell */
            const size_t k0 = g->cell_start[row + (size_t)a], k1 = g->cell_start[row + (size_t)a + 1];
#ifdef MPS_HAVE_WIDE
            if (wide)
                m = visit_cell_avx512(g, k0, k1, xi, yi, i, r2max, jtmp, r2tmp, want_r2, m);
            else
#endif
            for (size_t k = k0; k < k1; k++) {
                double dx = g->xs[k][0] - xi, dy = g->xs[k][1] - yi;
                double r2 = dx * dx + dy * dy;
                size_t j = g->sorted[k];
                /* written always, kept by advancing m: a third of the
                 * candidates pass, in no learnable order */
                jtmp[m] = (int)j;
                if (want_r2)
                    r2tmp[m] = r2;
                m += (r2 < r2max) & (j != i);
            }
            /* A cell whose first kept j follows the last one before it
             * extends the current run rather than opening one to merge:
             * the fluid is numbered in the grid's cell order (fluid.c), so
             * most windows arrive sorted but for the tank's cells. */
            if (m > runs[nruns]) {
                if (nruns > 0 && jtmp[runs[nruns]] > jtmp[runs[nruns] - 1])
                    runs[nruns] = m;
                else
                    runs[++nruns] = m;
            }
        }
    }
    /* merge the runs pairwise until one is left, ping-ponging between the
     * two buffers (at most 9 runs: 4 rounds) */
    int *js = jtmp, *jd = jout;
    double *rs = r2tmp, *rd = r2out;
    while (nruns > 1) {
        size_t o = 0, nr = 0;
        for (size_t q = 0; q < nruns; q += 2) {
            size_t p1 = runs[q], e1 = runs[q + 1];
            size_t p2 = q + 1 < nruns ? runs[q + 1] : e1, e2 = q + 1 < nruns ? runs[q + 2] : e1;
            while (p1 < e1 && p2 < e2) {
                size_t from = js[p1] < js[p2] ? p1++ : p2++;
                jd[o] = js[from];
                if (want_r2)
                    rd[o] = rs[from];
                o++;
            }
            for (; p1 < e1; p1++, o++) {
                jd[o] = js[p1];
                if (want_r2)
                    rd[o] = rs[p1];
            }
            for (; p2 < e2; p2++, o++) {
                jd[o] = js[p2];
                if (want_r2)
                    rd[o] = rs[p2];
            }
            runs[++nr] = o;
        }
        nruns = nr;
        int *tj = js;
        js = jd;
        jd = tj;
        double *tr = rs;
        rs = rd;
        rd = tr;
    }
    if (js != jout) {
        memcpy(jout, js, m * sizeof *jout);
        if (want_r2)
            memcpy(r2out, rs, m * sizeof *r2out);
    }
    return m;
}

enum mps_status mps_nbr_list_build(struct mps_nbr_list *l, const struct mps_nbr_grid *g,
                                   const double (*x)[MPS_DIM], size_t nquery, double radius,
                                   struct mps_err *err)
{
    return mps_nbr_list_build_masked(l, g, x, nquery, NULL, radius, err);
}

struct mps_nbr_scratch {
    int *jb, *jt;          /* the thread's rows; one query's runs before the merge */
    double *rb, *rt;
    size_t cap, cap2, capt, capt2;
};

/* One scratch per thread, kept in the list so a rebuild allocates nothing. */
static int reserve_scratch(struct mps_nbr_list *l, int ntmax)
{
    if (l->nscratch >= ntmax)
        return 0;
    struct mps_nbr_scratch *sc = realloc(l->scratch, (size_t)ntmax * sizeof *sc);
    if (!sc)
        return -1;
    memset(sc + l->nscratch, 0, (size_t)(ntmax - l->nscratch) * sizeof *sc);
    l->scratch = sc;
    l->nscratch = ntmax;
    return 0;
}

/* Called by every thread of a parallel region once its buffer sc holds the
 * used pairs of its contiguous block of rows from lo, and l->start[i + 1]
 * the count of each of its rows: turns the counts into offsets, makes room
 * and copies each block into place. *fail (shared): 1 if a thread could not
 * fill its buffer (lfail), 2 if there is no room for the pairs. */
static void publish_rows(struct mps_nbr_list *l, size_t lo, const struct mps_nbr_scratch *sc,
                         size_t used, int lfail, int *fail)
{
    if (lfail) {
#pragma omp atomic write
        *fail = 1;
    }
#pragma omp barrier
#pragma omp single
    {
        for (size_t i = 0; i < l->n && !*fail; i++)
            l->start[i + 1] += l->start[i];
        if (!*fail && grow_pairs(l, l->start[l->n]))
            *fail = 2;
    }
    if (!*fail && used > 0) {
        memcpy(l->j + l->start[lo], sc->jb, used * sizeof *sc->jb);
        if (!l->no_r2)
            memcpy(l->r2 + l->start[lo], sc->rb, used * sizeof *sc->rb);
    }
}

/* One pass: each thread visits a contiguous block of queries into its own
 * buffer, then copies it to its place once the row offsets are known. */
enum mps_status mps_nbr_list_build_masked(struct mps_nbr_list *l, const struct mps_nbr_grid *g,
                                          const double (*x)[MPS_DIM], size_t nquery,
                                          const unsigned char *query, double radius,
                                          struct mps_err *err)
{
    if (radius > g->cell * (1.0 + 1e-12))
        return mps_err_set(err, MPS_EINPUT, "neighbour radius %g exceeds cell width %g", radius,
                           g->cell);
    if (grow((void **)&l->start, &l->cap_n, nquery + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    const double r2max = radius * radius;
    const int want_r2 = !l->no_r2;
    l->n = nquery;
    l->radius = radius;
    l->start[0] = 0;
    int fail = 0;
    /* Threads take contiguous blocks with equal numbers of queried rows: a
     * fluid queries its first particles only, and an even split by index
     * gave one thread nearly all the work. */
    const int ntmax = omp_get_max_threads(), wide = mps_simd_wide();
    if (reserve_scratch(l, ntmax))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    size_t *bound = malloc(((size_t)ntmax + 1) * sizeof *bound);
    if (!bound)
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    size_t nq = 0;
    for (size_t i = 0; i < nquery; i++)
        nq += !query || query[i];
    bound[0] = 0;
    for (size_t i = 0, seen = 0, t = 1; t <= (size_t)ntmax; t++) {
        size_t want = nq * t / (size_t)ntmax;
        while (i < nquery && seen < want)
            seen += !query || query[i++];
        bound[t] = t == (size_t)ntmax ? nquery : i;
    }
#pragma omp parallel num_threads(ntmax)
    {
        int nt = omp_get_num_threads(), t = omp_get_thread_num();
        size_t lo = bound[t], hi = bound[t + 1];
        if (nt != ntmax) { /* fewer threads than asked for: split by index */
            lo = nquery * (size_t)t / (size_t)nt;
            hi = nquery * (size_t)(t + 1) / (size_t)nt;
        }
        struct mps_nbr_scratch *sc = &l->scratch[t];
        size_t used = 0;
        int lfail = 0;
        for (size_t i = lo; i < hi; i++) {
            size_t m = 0;
            if (!query || query[i]) {
                struct cell_window w = cell_window(g, i);
                size_t room = candidates(g, &w);
                if (grow((void **)&sc->jb, &sc->cap, used + room + 1, sizeof *sc->jb) ||
                    grow((void **)&sc->jt, &sc->capt, room + 1, sizeof *sc->jt) ||
                    (want_r2 &&
                     (grow((void **)&sc->rb, &sc->cap2, used + room + 1, sizeof *sc->rb) ||
                      grow((void **)&sc->rt, &sc->capt2, room + 1, sizeof *sc->rt)))) {
                    lfail = 1;
                    break;
                }
                m = want_r2 ? visit(g, x, i, &w, r2max, sc->jb + used, sc->rb + used, sc->jt,
                                    sc->rt, 1, wide)
                            : visit(g, x, i, &w, r2max, sc->jb + used, NULL, sc->jt, NULL, 0, wide);
            }
            l->start[i + 1] = m;
            used += m;
        }
        publish_rows(l, lo, sc, used, lfail, &fail);
    }
    free(bound);
    return fail ? mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory%s",
                              fail == 2 ? " for the pairs" : "")
                : MPS_OK;
}

/* First row of thread t's block when nt threads share the candidates of
 * src evenly (a fluid's tank rows are empty, so an even split of the rows
 * would leave one thread idle). */
static size_t even_split(const struct mps_nbr_list *src, int t, int nt)
{
    const size_t n = src->n, want = src->start[n] / (size_t)nt * (size_t)t;
    if (t == 0)
        return 0;
    if (t == nt)
        return n;
    size_t lo = 0, hi = n; /* first row whose candidates start at or after want */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (src->start[mid] < want)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* One pass over the candidates: each thread writes the kept pairs of its
 * block of rows into its own buffer, then copies them to their place once
 * the row offsets are known (rather than counting in one pass and writing
 * in a second, which reads every candidate and its position twice). */
#ifdef MPS_HAVE_WIDE
/* The loop of mps_nbr_list_filter over one row's candidates j[0 .. len),
 * eight at a time (mps_simd_wide): positions gathered, r2 as
 * mps_pair_delta computes it (same bits), r2 stored to src_r2 if given, the
 * kept j (and r2, if dst_r2) packed at jout (and r2out); returns their
 * number. */
__attribute__((target("avx512f"))) static size_t filter_row_avx512(
    const int *j, size_t len, const double (*x)[MPS_DIM], size_t i, double r2max,
    double *src_r2, int *jout, double *r2out)
{
    const double *xd = &x[0][0];
    const __m512d vxi = _mm512_set1_pd(x[i][0]), vyi = _mm512_set1_pd(x[i][1]),
                  vr2 = _mm512_set1_pd(r2max);
    size_t m = 0;
    for (size_t k = 0; k < len; k += 8) {
        const __mmask8 in = mps_lanes8(len - k);
        const __m512i jv = _mm512_maskz_loadu_epi32(in, j + k);
        const __m256i j2 = _mm256_slli_epi32(_mm512_castsi512_si256(jv), 1); /* x[j][0] at 2j */
        const __m512d dx = _mm512_sub_pd(
                          _mm512_mask_i32gather_pd(_mm512_setzero_pd(), in, j2, xd, 8), vxi),
                      dy = _mm512_sub_pd(
                          _mm512_mask_i32gather_pd(_mm512_setzero_pd(), in, j2, xd + 1, 8), vyi);
        const __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
        if (src_r2)
            _mm512_mask_storeu_pd(src_r2 + k, in, r2);
        const __mmask8 keep = _mm512_cmp_pd_mask(r2, vr2, _CMP_LT_OQ) & in;
        const int nk = __builtin_popcount(keep);
        const __mmask16 first = mps_lanes8((size_t)nk);
        _mm512_mask_storeu_epi32(jout + m, first, _mm512_maskz_compress_epi32((__mmask16)keep, jv));
        if (r2out)
            _mm512_mask_storeu_pd(r2out + m, (__mmask8)first, _mm512_maskz_compress_pd(keep, r2));
        m += (size_t)nk;
    }
    return m;
}
#endif

enum mps_status mps_nbr_list_filter(struct mps_nbr_list *dst, struct mps_nbr_list *src,
                                    const double (*x)[MPS_DIM], double radius,
                                    struct mps_err *err)
{
    const size_t n = src->n;
    const double r2max = radius * radius;
    const int ntmax = omp_get_max_threads();
    if (grow((void **)&dst->start, &dst->cap_n, n + 1, sizeof(size_t)) ||
        reserve_scratch(dst, ntmax))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    dst->n = n;
    dst->radius = radius;
    dst->start[0] = 0;
    const int src_r2 = !src->no_r2, dst_r2 = !dst->no_r2, wide = mps_simd_wide();
    int fail = 0;
#pragma omp parallel num_threads(ntmax)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t lo = even_split(src, t, nt), hi = even_split(src, t + 1, nt);
        const size_t room = src->start[hi] - src->start[lo] + 1;
        struct mps_nbr_scratch *sc = &dst->scratch[t];
        int lfail = grow((void **)&sc->jb, &sc->cap, room, sizeof *sc->jb) ||
                    (dst_r2 && grow((void **)&sc->rb, &sc->cap2, room, sizeof *sc->rb));
        size_t used = 0;
        if (!lfail)
            for (size_t i = lo; i < hi; i++) {
                mps_nbr_prefetch_row(src, i + MPS_NBR_PREFETCH_ROWS);
#ifdef MPS_HAVE_WIDE
                if (wide) {
                    const size_t k0 = src->start[i], m =
                        filter_row_avx512(src->j + k0, src->start[i + 1] - k0, x, i, r2max,
                                          src_r2 ? src->r2 + k0 : NULL, sc->jb + used,
                                          dst_r2 ? sc->rb + used : NULL);
                    dst->start[i + 1] = m;
                    used += m;
                    continue;
                }
#endif
                /* every candidate is written, kept by advancing the count
                 * (which pass follows no order a predictor could learn) */
                size_t m = used;
                double d[MPS_DIM];
                for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
                    const double r2 = mps_pair_delta(x, i, (size_t)src->j[k], d);
                    if (src_r2)
                        src->r2[k] = r2;
                    sc->jb[m] = src->j[k];
                    if (dst_r2)
                        sc->rb[m] = r2;
                    m += r2 < r2max;
                }
                dst->start[i + 1] = m - used;
                used = m;
            }
        publish_rows(dst, lo, sc, used, lfail, &fail);
    }
    return fail ? mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory%s",
                              fail == 2 ? " for the pairs" : "")
                : MPS_OK;
}

enum mps_status mps_nbr_list_reverse(struct mps_nbr_list *dst, const struct mps_nbr_list *src,
                                     size_t from_lo, size_t from_hi, size_t to_lo, size_t to_hi,
                                     struct mps_err *err)
{
    const size_t n = src->n, m = to_hi > to_lo ? to_hi - to_lo : 0;
    const int dst_r2 = !dst->no_r2;
    if (dst_r2 && src->no_r2)
        return mps_err_set(err, MPS_EINPUT,
                           "neighbour list reverse: the source keeps no r2 for the destination");
    if (grow((void **)&dst->start, &dst->cap_n, n + 1, sizeof(size_t)))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    dst->n = n;
    dst->radius = src->radius;
    /* Each thread transposes a contiguous block of source rows: it counts
     * its pairs per destination row, then fills them at an offset after
     * those of the threads before it, so every row stays sorted by i. */
    const int ntmax = omp_get_max_threads();
    size_t *cnt = calloc((size_t)ntmax * m + 1, sizeof *cnt);
    if (!cnt)
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory");
    int fail = 0;
#pragma omp parallel num_threads(ntmax)
    {
        int t = omp_get_thread_num(), nt = omp_get_num_threads();
        size_t lo = from_lo + (from_hi - from_lo) * (size_t)t / (size_t)nt;
        size_t hi = from_lo + (from_hi - from_lo) * (size_t)(t + 1) / (size_t)nt;
        size_t *c = cnt + (size_t)t * m;
        for (size_t i = lo; i < hi; i++)
            for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
                size_t j = (size_t)src->j[k];
                if (j >= to_lo && j < to_hi)
                    c[j - to_lo]++;
            }
#pragma omp barrier
#pragma omp single
        {
            /* row offsets, and each thread's count turned into its offset */
            dst->start[0] = 0;
            for (size_t j = 0; j < n; j++) {
                size_t at = dst->start[j];
                if (j >= to_lo && j < to_hi)
                    for (int q = 0; q < nt; q++) {
                        size_t cq = cnt[(size_t)q * m + (j - to_lo)];
                        cnt[(size_t)q * m + (j - to_lo)] = at;
                        at += cq;
                    }
                dst->start[j + 1] = at;
            }
            if (grow_pairs(dst, dst->start[n]))
                fail = 1;
        }
        if (!fail)
            for (size_t i = lo; i < hi; i++)
                for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
                    size_t j = (size_t)src->j[k];
                    if (j >= to_lo && j < to_hi) {
                        size_t at = c[j - to_lo]++;
                        dst->j[at] = (int)i;
                        if (dst_r2)
                            dst->r2[at] = src->r2[k];
                    }
                }
    }
    free(cnt);
    if (fail)
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory for %zu pairs",
                           dst->start[n]);
    return MPS_OK;
}

void mps_nbr_list_free(struct mps_nbr_list *l)
{
    free(l->start);
    free(l->j);
    free(l->r2);
    for (int t = 0; t < l->nscratch; t++) {
        free(l->scratch[t].jb);
        free(l->scratch[t].rb);
        free(l->scratch[t].jt);
        free(l->scratch[t].rt);
    }
    free(l->scratch);
    memset(l, 0, sizeof *l);
}

enum mps_status mps_nbr_list_copy(struct mps_nbr_list *dst, const struct mps_nbr_list *src,
                                  struct mps_err *err)
{
    const size_t n = src->n, npairs = src->start ? src->start[n] : 0;
    dst->no_r2 = src->no_r2 || !src->r2;
    if (!dst->no_r2 && !dst->r2)
        dst->cap_pairs = 0; /* j may have room, r2 has none yet */
    if (grow((void **)&dst->start, &dst->cap_n, n + 1, sizeof(size_t)) || grow_pairs(dst, npairs))
        return mps_err_set(err, MPS_ENOMEM, "neighbour list: out of memory copying %zu pairs",
                           npairs);
    dst->n = n;
    dst->radius = src->radius;
    if (src->start)
        memcpy(dst->start, src->start, (n + 1) * sizeof *dst->start);
    else
        dst->start[0] = 0;
    if (npairs) {
        memcpy(dst->j, src->j, npairs * sizeof *dst->j);
        if (!dst->no_r2)
            memcpy(dst->r2, src->r2, npairs * sizeof *dst->r2);
    }
    return MPS_OK;
}

enum mps_status mps_nbr_list_put(const struct mps_nbr_list *l, const char *name,
                                 struct mps_ckpt *c, struct mps_err *err)
{
    char key[96];
    const size_t n = l->n, npairs = l->start ? l->start[n] : 0;
    double head[2] = {(double)n, l->radius}; /* n < 2^53 */
    int r2 = !l->no_r2 && l->r2;
    enum mps_status st;
    snprintf(key, sizeof key, "%s.list", name);
    if ((st = mps_ckpt_put(c, key, head, sizeof head, err)))
        return st;
    snprintf(key, sizeof key, "%s.start", name);
    if (l->start && (st = mps_ckpt_put(c, key, l->start, (n + 1) * sizeof *l->start, err)))
        return st;
    if (!l->start && (st = mps_ckpt_put(c, key, NULL, 0, err)))
        return st;
    snprintf(key, sizeof key, "%s.j", name);
    if ((st = mps_ckpt_put(c, key, l->j, npairs * sizeof *l->j, err)))
        return st;
    snprintf(key, sizeof key, "%s.r2", name);
    return mps_ckpt_put(c, key, r2 ? l->r2 : NULL, r2 ? npairs * sizeof *l->r2 : 0, err);
}

enum mps_status mps_nbr_list_get(struct mps_nbr_list *l, const char *name, struct mps_ckpt *c,
                                 struct mps_err *err)
{
    char key[96];
    double head[2];
    const void *start, *j, *r2;
    size_t bs, bj, br;
    enum mps_status st;
    snprintf(key, sizeof key, "%s.list", name);
    if ((st = mps_ckpt_get(c, key, head, sizeof head, err)))
        return st;
    snprintf(key, sizeof key, "%s.start", name);
    if ((st = mps_ckpt_get_any(c, key, &start, &bs, err)))
        return st;
    snprintf(key, sizeof key, "%s.j", name);
    if ((st = mps_ckpt_get_any(c, key, &j, &bj, err)))
        return st;
    snprintf(key, sizeof key, "%s.r2", name);
    if ((st = mps_ckpt_get_any(c, key, &r2, &br, err)))
        return st;
    /* the image's arrays as a list, copied by the one copy there is */
    size_t n = (size_t)head[0];
    struct mps_nbr_list view = {.n = n, .start = bs ? (size_t *)start : NULL, .j = (int *)j,
                                .r2 = br ? (double *)r2 : NULL, .no_r2 = !br,
                                .radius = head[1]};
    size_t npairs = bs ? view.start[n] : 0;
    if ((bs && bs != (n + 1) * sizeof(size_t)) || bj != npairs * sizeof(int) ||
        (br && br != npairs * sizeof(double)))
        return mps_err_set(err, MPS_EINPUT, "checkpoint: neighbour list '%s' is inconsistent",
                           name);
    return mps_nbr_list_copy(l, &view, err);
}

enum mps_status mps_nbr_grid_cell_order(struct mps_nbr_grid *g, size_t m, size_t *perm,
                                        struct mps_err *err)
{
    size_t *cell = malloc((m > 0 ? m : 1) * sizeof *cell);
    if (!cell)
        return mps_err_set(err, MPS_ENOMEM, "neighbour grid: out of memory renumbering");
    /* the grid as if built after the renumbering: the same cells and
     * slots, the particle in the k-th renumbered slot numbered k */
    for (size_t c = 0, k = 0; c < g->n; c++)
        if (g->sorted[c] < m) {
            perm[k] = g->sorted[c];
            cell[k] = g->cell_of[perm[k]];
            g->sorted[c] = k++;
        }
    memcpy(g->cell_of, cell, m * sizeof *cell);
    free(cell);
    return MPS_OK;
}
