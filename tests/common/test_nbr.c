/* Neighbour search against brute force O(N^2), and the lattice constants of
 * the MPS weight against hand sums. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../test_util.h"
#include "mps_kernel.h"
#include "mps_simd.h"
#include "mps_nbr.h"
#include "mps_particles.h"

/* Compares the CSR list of the first nquery particles with a brute-force
 * search computing r2 the same way (so the values are bit-identical). */
static void compare(const char *what, size_t n, const double (*x)[MPS_DIM], size_t nquery,
                    double cell, double radius)
{
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list l = {0};
    struct mps_err err = {0};
    enum mps_status st = mps_nbr_grid_build(&g, n, x, cell, &err);
    CHECK(st == MPS_OK);
    if (st == MPS_OK)
        st = mps_nbr_list_build(&l, &g, x, nquery, radius, &err);
    CHECK(st == MPS_OK);
    if (st != MPS_OK) {
        fprintf(stderr, "%s: %s\n", what, err.msg);
        goto done;
    }
    CHECK(l.n == nquery);
    CHECK(l.start[0] == 0);
    double r2max = radius * radius;
    size_t bad = 0, total = 0;
    int *want = malloc(n * sizeof *want + 1);
    double *want_r2 = malloc(n * sizeof *want_r2 + 1);
    for (size_t i = 0; i < nquery; i++) {
        size_t m = 0;
        for (size_t j = 0; j < n; j++) {
            if (j == i)
                continue;
            double dx = x[j][0] - x[i][0], dy = x[j][1] - x[i][1];
            double r2 = dx * dx + dy * dy;
            if (r2 < r2max) {
                want[m] = (int)j;
                want_r2[m++] = r2;
            }
        }
        total += m;
        size_t got = l.start[i + 1] - l.start[i];
        if (got != m) {
            if (bad++ < 5)
                fprintf(stderr, "%s: particle %zu has %zu neighbours, brute force %zu\n", what,
                        i, got, m);
            continue;
        }
        for (size_t k = 0; k < m; k++)
            if (l.j[l.start[i] + k] != want[k] || l.r2[l.start[i] + k] != want_r2[k]) {
                if (bad++ < 5)
                    fprintf(stderr, "%s: particle %zu entry %zu: j %d r2 %g, want j %d r2 %g\n",
                            what, i, k, l.j[l.start[i] + k], l.r2[l.start[i] + k], want[k],
                            want_r2[k]);
                break;
            }
    }
    CHECK(bad == 0);
    CHECK(l.start[nquery] == total);
    if (bad)
        fprintf(stderr, "%s: %zu particles differ\n", what, bad);
    free(want);
    free(want_r2);
done:
    mps_nbr_list_free(&l);
    mps_nbr_grid_free(&g);
}

static double urand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static void test_random(void)
{
    const size_t n = 2000;
    const double l0 = 0.01;
    double (*x)[MPS_DIM] = malloc(n * sizeof *x);
    unsigned long long seed = 12345;
    /* about one particle per l0^2, like a fluid at rest, over a 50 x 40 box */
    for (size_t i = 0; i < n; i++) {
        x[i][0] = -0.2 + 50 * l0 * urand(&seed);
        x[i][1] = 0.3 + 40 * l0 * urand(&seed);
    }
    const double (*cx)[MPS_DIM] = (const double(*)[MPS_DIM])x;
    /* the AVX-512 candidate loop (where the CPU has it) and the portable
     * one: both must give the brute-force list, bit for bit */
    for (int wide = 1; wide >= 0; wide--) {
        mps_simd_set_wide(wide);
        compare("random re=2.1", n, cx, n, 2.1 * l0, 2.1 * l0);
        compare("random re=4.0", n, cx, n, 4.0 * l0, 4.0 * l0);
        compare("random re=2.1 in 4.0 cells", n, cx, n, 4.0 * l0, 2.1 * l0);
        compare("random first 500", n, cx, 500, 2.1 * l0, 2.1 * l0);
    }
    mps_simd_set_wide(1);
    /* a clustered cloud: many particles per cell */
    for (size_t i = 0; i < n; i++) {
        x[i][0] = 5 * l0 * urand(&seed);
        x[i][1] = 5 * l0 * urand(&seed);
    }
    compare("dense re=2.1", n, cx, n, 2.1 * l0, 2.1 * l0);
    free(x);
}

/* Numbering the first m particles in cell order (as the fluid is before each
 * list build): perm is a permutation, the renumbered particles follow the
 * grid's slots, and the updated grid and its list are those of a grid built
 * from scratch at the renumbered positions. */
static void test_cell_order(void)
{
    const size_t n = 1500, m = 900;
    const double l0 = 0.01, re = 5.0 * l0;
    double (*x)[MPS_DIM] = malloc(n * sizeof *x), (*y)[MPS_DIM] = malloc(n * sizeof *y);
    size_t *perm = malloc(m * sizeof *perm);
    unsigned char *seen = calloc(m, 1);
    unsigned long long seed = 4242;
    for (size_t i = 0; i < n; i++) {
        x[i][0] = 40 * l0 * urand(&seed);
        x[i][1] = 30 * l0 * urand(&seed);
    }
    struct mps_nbr_grid g = {0}, g2 = {0};
    struct mps_nbr_list l = {0}, l2 = {0};
    struct mps_err err = {0};
    CHECK(mps_nbr_grid_build(&g, n, (const double(*)[MPS_DIM])x, re, &err) == MPS_OK);
    CHECK(mps_nbr_grid_cell_order(&g, m, perm, &err) == MPS_OK);
    int ok = 1;
    for (size_t k = 0; k < m; k++) {
        ok &= perm[k] < m && !seen[perm[k]];
        if (perm[k] < m)
            seen[perm[k]] = 1;
    }
    CHECK(ok);
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < MPS_DIM; d++)
            y[i][d] = i < m ? x[perm[i]][d] : x[i][d];
    size_t last = 0, descents = 0;
    for (size_t c = 0, first = 1; c < g.n; c++)
        if (g.sorted[c] < m) {
            descents += !first && g.sorted[c] < last;
            last = g.sorted[c];
            first = 0;
        }
    CHECK(descents == 0);
    CHECK(mps_nbr_grid_build(&g2, n, (const double(*)[MPS_DIM])y, re, &err) == MPS_OK);
    CHECK(!memcmp(g.sorted, g2.sorted, n * sizeof *g.sorted));
    CHECK(!memcmp(g.cell_of, g2.cell_of, n * sizeof *g.cell_of));
    CHECK(mps_nbr_list_build(&l, &g, (const double(*)[MPS_DIM])y, n, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&l2, &g2, (const double(*)[MPS_DIM])y, n, re, &err) == MPS_OK);
    CHECK(l.start[n] == l2.start[n] && !memcmp(l.start, l2.start, (n + 1) * sizeof *l.start) &&
          !memcmp(l.j, l2.j, l.start[n] * sizeof *l.j));
    mps_nbr_list_free(&l);
    mps_nbr_list_free(&l2);
    mps_nbr_grid_free(&g);
    mps_nbr_grid_free(&g2);
    free(x);
    free(y);
    free(perm);
    free(seen);
}

/* mps_particles_permute moves every field, whatever its element size (1, 4,
 * 8, 16 bytes and, through the general copy, 24), for the first m
 * particles only; asking for more than there are is an error. */
static void test_particles_permute(void)
{
    struct mps_particles ps;
    unsigned char *u8 = NULL;
    int *i32 = NULL;
    double *f1 = NULL, (*f2)[2] = NULL, (*f3)[3] = NULL;
    mps_particles_init(&ps);
    mps_particles_add_field(&ps, "u8", 1, MPS_U8, (void **)&u8, "", 0);
    mps_particles_add_field(&ps, "i32", 1, MPS_I32, (void **)&i32, "", 0);
    mps_particles_add_field(&ps, "f1", 1, MPS_F64, (void **)&f1, "", 0);
    mps_particles_add_field(&ps, "f2", 2, MPS_F64, (void **)&f2, "", 0);
    mps_particles_add_field(&ps, "f3", 3, MPS_F64, (void **)&f3, "", 0);
    struct mps_err err = {0};
    const size_t n = 5000, m = 4500; /* above the size at which fields go in parallel */
    CHECK(mps_particles_resize(&ps, n, &err) == MPS_OK);
    for (size_t i = 0; i < n; i++) {
        u8[i] = (unsigned char)(i % 251);
        i32[i] = (int)i;
        f1[i] = (double)i;
        f2[i][0] = f2[i][1] = f3[i][0] = f3[i][2] = (double)i;
        f3[i][1] = -(double)i;
    }
    size_t *perm = malloc(m * sizeof *perm);
    for (size_t k = 0; k < m; k++)
        perm[k] = (k * 7919) % m; /* 7919 is prime and does not divide 4500 */
    CHECK(mps_particles_permute(&ps, perm, m, &err) == MPS_OK);
    int ok = 1;
    for (size_t i = 0; i < n; i++) {
        size_t o = i < m ? perm[i] : i;
        ok &= u8[i] == o % 251 && i32[i] == (int)o && f1[i] == (double)o && f2[i][0] == (double)o &&
              f2[i][1] == (double)o && f3[i][0] == (double)o && f3[i][1] == -(double)o &&
              f3[i][2] == (double)o;
    }
    CHECK(ok);
    CHECK(mps_particles_permute(&ps, perm, n + 1, &err) == MPS_EINPUT);
    free(perm);
    mps_particles_free(&ps);
}

/* A masked build equals the full one on the queried rows and leaves the
 * others empty; the reverse of the rows [0, nf) restricted to the columns
 * [nf, n) is their transpose (a fluid and its tank). */
static void test_masked_reverse(void)
{
    const size_t n = 1500, nf = 900;
    const double l0 = 0.01, re = 5.0 * l0;
    double (*x)[MPS_DIM] = malloc(n * sizeof *x);
    unsigned char *q = malloc(n);
    unsigned long long seed = 777;
    for (size_t i = 0; i < n; i++) {
        x[i][0] = 40 * l0 * urand(&seed);
        x[i][1] = 40 * l0 * urand(&seed);
        q[i] = i < nf || i % 7 == 0; /* the fluid and a few of the rest */
    }
    const double (*cx)[MPS_DIM] = (const double(*)[MPS_DIM])x;
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list full = {0}, part = {0}, rev = {0};
    struct mps_err err = {0};
    CHECK(mps_nbr_grid_build(&g, n, cx, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&full, &g, cx, n, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build_masked(&part, &g, cx, n, q, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_reverse(&rev, &full, 0, nf, nf, n, &err) == MPS_OK);
    CHECK(part.n == n && rev.n == n);
    size_t bad = 0, tank_pairs = 0;
    for (size_t i = 0; i < n; i++) {
        size_t m = part.start[i + 1] - part.start[i];
        if (!q[i]) {
            bad += m != 0;
        } else {
            bad += m != full.start[i + 1] - full.start[i];
            for (size_t k = 0; k < m && k < full.start[i + 1] - full.start[i]; k++)
                bad += part.j[part.start[i] + k] != full.j[full.start[i] + k] ||
                       part.r2[part.start[i] + k] != full.r2[full.start[i] + k];
        }
        /* rev row i: the i' < nf whose full row holds i, ascending */
        size_t k = rev.start[i];
        for (size_t a = 0; a < nf && i >= nf; a++)
            for (size_t b = full.start[a]; b < full.start[a + 1]; b++)
                if ((size_t)full.j[b] == i) {
                    bad += k >= rev.start[i + 1] || (size_t)rev.j[k] != a || rev.r2[k] != full.r2[b];
                    k++;
                }
        bad += k != rev.start[i + 1];
        tank_pairs += i >= nf ? rev.start[i + 1] - rev.start[i] : 0;
    }
    CHECK(bad == 0);
    CHECK(tank_pairs > 1000); /* the test sees pairs, not only empty rows */
    mps_nbr_list_free(&full);
    mps_nbr_list_free(&part);
    mps_nbr_list_free(&rev);
    mps_nbr_grid_free(&g);
    free(q);
    free(x);
}

/* Lattice with particles exactly on cell borders: the grid starts half a
 * cell below the lowest particle, so with cell = 2 l0 every odd lattice line
 * and with cell = 4 l0 every even one lies on a border. */
static void test_lattice(double l0, double x0)
{
    const int nx = 40, ny = 30;
    size_t n = (size_t)nx * ny;
    double (*x)[MPS_DIM] = malloc(n * sizeof *x);
    for (int b = 0; b < ny; b++)
        for (int a = 0; a < nx; a++) {
            x[b * nx + a][0] = x0 + a * l0;
            x[b * nx + a][1] = x0 + b * l0;
        }
    const double (*cx)[MPS_DIM] = (const double(*)[MPS_DIM])x;
    char what[64];
    const double radii[] = {2.1, 4.0, 2.0, 1.0};
    for (int k = 0; k < 4; k++) {
        snprintf(what, sizeof what, "lattice l0=%g re=%g", l0, radii[k]);
        compare(what, n, cx, n, radii[k] * l0, radii[k] * l0);
    }

    /* n0 of an interior particle from the list equals the lattice constant */
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list l = {0};
    struct mps_err err = {0};
    double re = 2.1 * l0;
    CHECK(mps_nbr_grid_build(&g, n, cx, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&l, &g, cx, n, re, &err) == MPS_OK);
    size_t i = (size_t)(ny / 2) * nx + nx / 2;
    double n0 = 0.0;
    for (size_t k = l.start[i]; k < l.start[i + 1]; k++)
        n0 += mps_weight(sqrt(l.r2[k]), re);
    struct mps_lattice_consts c = mps_lattice_consts(l0, re);
    CHECK(l.start[i + 1] - l.start[i] == (size_t)c.count);
    CHECK_NEAR(n0, c.n0, 1e-12 * c.n0);
    mps_nbr_list_free(&l);
    mps_nbr_grid_free(&g);
    free(x);
}

static void test_errors(void)
{
    double x[10][MPS_DIM];
    for (int i = 0; i < 10; i++)
        x[i][0] = x[i][1] = i;
    x[5][1] = NAN;
    struct mps_nbr_grid g = {0};
    struct mps_err err = {0};
    CHECK(mps_nbr_grid_build(&g, 10, (const double(*)[MPS_DIM])x, 1.0, &err) == MPS_EDIVERGED);
    CHECK(strstr(err.msg, "particle 5") != NULL);
    x[5][1] = INFINITY;
    CHECK(mps_nbr_grid_build(&g, 10, (const double(*)[MPS_DIM])x, 1.0, &err) == MPS_EDIVERGED);
    x[5][1] = 5.0;
    CHECK(mps_nbr_grid_build(&g, 10, (const double(*)[MPS_DIM])x, 1.0, &err) == MPS_OK);
    struct mps_nbr_list l = {0};
    CHECK(mps_nbr_list_build(&l, &g, (const double(*)[MPS_DIM])x, 10, 2.0, &err) == MPS_EINPUT);
    /* no particles at all */
    CHECK(mps_nbr_grid_build(&g, 0, NULL, 1.0, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&l, &g, NULL, 0, 1.0, &err) == MPS_OK);
    CHECK(l.n == 0 && l.start[0] == 0);
    mps_nbr_list_free(&l);
    mps_nbr_grid_free(&g);
}

static void test_kernel(void)
{
    const double l0 = 0.02;
    /* re = 2.1 l0: 4 at l0, 4 at sqrt2 l0, 4 at 2 l0 (w = re/r - 1); the 8 at
     * sqrt5 l0 = 2.236 l0 lie outside re, so N0 = 12. */
    struct mps_lattice_consts c = mps_lattice_consts(l0, 2.1 * l0);
    CHECK(c.count == 12);
    double n0 = 4 * (2.1 / 1.0 - 1) + 4 * (2.1 / sqrt(2.0) - 1) + 4 * (2.1 / 2.0 - 1);
    CHECK_NEAR(c.n0, n0, 1e-12 * n0);
    double lam = l0 * l0 *
                 (4 * 1 * (2.1 / 1.0 - 1) + 4 * 2 * (2.1 / sqrt(2.0) - 1) +
                  4 * 4 * (2.1 / 2.0 - 1)) / n0;
    CHECK_NEAR(c.lambda, lam, 1e-12 * lam);

    /* re = 4.0 l0: lambda = sum r^2 w / sum w over the lattice, summed here */
    double re = 4.0 * l0, sw = 0.0, sr2w = 0.0;
    int count = 0;
    for (int a = -6; a <= 6; a++)
        for (int b = -6; b <= 6; b++) {
            double r = l0 * hypot(a, b);
            if ((a || b) && r < re) {
                double w = re / r - 1.0;
                sw += w;
                sr2w += r * r * w;
                count++;
            }
        }
    c = mps_lattice_consts(l0, re);
    CHECK(c.count == count);
    CHECK(count == 44); /* 0 < a^2 + b^2 < 16: 7 + 2*7 + 2*7 + 2*5 - 1 */
    CHECK_NEAR(c.n0, sw, 1e-12 * sw);
    CHECK_NEAR(c.lambda, sr2w / sw, 1e-12 * sr2w / sw);

    CHECK(mps_weight(0.0, re) == 0.0);
    CHECK(mps_weight(re, re) == 0.0);
    CHECK(mps_weight(1.5 * re, re) == 0.0);
    CHECK_NEAR(mps_weight(0.5 * re, re), 1.0, 1e-15);

    /* The branch-free form the neighbour loops use gives the same bits from
     * r^2, including 0 at r = 0 and at and beyond re. */
    CHECK(mps_weight_r2(0.0, re) == 0.0);
    CHECK(mps_weight_r2(re * re, re) == 0.0);
    CHECK(mps_weight_r2(2.25 * re * re, re) == 0.0);
    int same = 1;
    for (int k = 1; k <= 2000; k++) {
        double r = 1.2 * re * k / 2000.0;
        same &= mps_weight_r2(r * r, re) == mps_weight(sqrt(r * r), re);
    }
    CHECK(same);

    /* The packed SSE2 form gives the same bits as the scalar one times the
     * scale, for an odd count (the scalar tail runs too), with r = 0,
     * r = re and r beyond re among them. */
    enum { NW = 2001 };
    static double w[NW], r2[NW];
    const double scale = 3.7;
    for (int k = 0; k < NW; k++) {
        double r = 1.2 * re * k / (NW - 1);
        r2[k] = w[k] = r * r;
    }
    r2[NW / 2] = w[NW / 2] = re * re;
    mps_weights_r2_sse2(w, NW, re, scale);
    same = 1;
    for (int k = 0; k < NW; k++)
        same &= w[k] == scale * mps_weight_r2(r2[k], re);
    CHECK(same);
    CHECK(w[0] == 0.0 && w[NW / 2] == 0.0 && w[NW - 1] == 0.0 && w[1] > 0.0);

    /* The AVX-512 form (1/r from a 14-bit estimate and two Newton steps) is
     * within 4 units in the last place of re/r: w = re/r - 1 is then off by
     * at most 4 eps re/r, far below the weights' own truncation error. One
     * Newton step fewer would leave 2^-27 relative, which this catches. Zero
     * where the scalar form is zero (r = 0 and r >= re, up to the same
     * rounding at r = re). */
    memcpy(w, r2, sizeof w);
    if (mps_weights_r2_wide(w, NW, re, scale)) {
        double worst = 0.0;
        int zeros = 1;
        for (int k = 0; k < NW; k++) {
            double exact = scale * mps_weight_r2(r2[k], re);
            if (r2[k] == 0.0 || r2[k] > re * re)
                zeros &= w[k] == 0.0;
            else {
                double err = fabs(w[k] - exact) / (scale * re / sqrt(r2[k]) * DBL_EPSILON);
                worst = err > worst ? err : worst;
            }
        }
        printf("  AVX-512 weights: worst %.2f eps of re/r\n", worst);
        CHECK(zeros);
        CHECK(worst <= 4.0);
        CHECK(w[1] > 0.0);
    } else
        printf("  AVX-512 weights: not on this CPU (or MPS_SIMD=sse2), SSE2 path only\n");
}

/* Lists that keep only j (no_r2, as the fluid's): the same pairs in the same
 * order as lists with r2, through the build, the filter at moved positions
 * and the reverse; a reverse that would need r2 from such a list is an
 * error. */
/* Entries of the filtered list ff that differ from the pairs of src within
 * radius at positions x (same order, r2 the same bits), plus entries of
 * src whose r2 the filter did not refresh to x. */
static size_t filter_errors(const struct mps_nbr_list *src, const struct mps_nbr_list *ff,
                            const double (*x)[MPS_DIM], double radius)
{
    size_t bad = 0;
    for (size_t i = 0; i < src->n; i++) {
        size_t q = ff->start[i];
        for (size_t k = src->start[i]; k < src->start[i + 1]; k++) {
            double d[MPS_DIM], r2 = mps_pair_delta(x, i, (size_t)src->j[k], d);
            bad += src->r2[k] != r2;
            if (r2 < radius * radius) {
                bad += q >= ff->start[i + 1] || ff->j[q] != src->j[k] || ff->r2[q] != r2;
                q++;
            }
        }
        bad += q != ff->start[i + 1];
    }
    return bad;
}

static void test_no_r2(void)
{
    const size_t n = 1500, nf = 900;
    const double l0 = 0.01, re = 5.0 * l0, rs = 2.1 * l0;
    double (*x)[MPS_DIM] = malloc(n * sizeof *x);
    unsigned long long seed = 4242;
    for (size_t i = 0; i < n; i++) {
        x[i][0] = 40 * l0 * urand(&seed);
        x[i][1] = 40 * l0 * urand(&seed);
    }
    const double (*cx)[MPS_DIM] = (const double(*)[MPS_DIM])x;
    struct mps_nbr_grid g = {0};
    struct mps_nbr_list full = {0}, bare = {0}, ff = {0}, bf = {0}, fr = {0}, br = {0};
    bare.no_r2 = bf.no_r2 = br.no_r2 = 1;
    struct mps_err err = {0};
    CHECK(mps_nbr_grid_build(&g, n, cx, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&full, &g, cx, n, re, &err) == MPS_OK);
    CHECK(mps_nbr_list_build(&bare, &g, cx, n, re, &err) == MPS_OK);
    CHECK(bare.r2 == NULL);
    /* move every particle by up to 0.4 l0, as a step within the skin does */
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < MPS_DIM; d++)
            x[i][d] += 0.4 * l0 * (2.0 * urand(&seed) - 1.0);
    CHECK(mps_nbr_list_filter(&ff, &full, cx, rs, &err) == MPS_OK);
    CHECK(mps_nbr_list_filter(&bf, &bare, cx, rs, &err) == MPS_OK);
    CHECK(bf.r2 == NULL);
    CHECK(mps_nbr_list_reverse(&fr, &full, 0, nf, nf, n, &err) == MPS_OK);
    CHECK(mps_nbr_list_reverse(&br, &bare, 0, nf, nf, n, &err) == MPS_OK);
    CHECK(br.r2 == NULL);
    const struct mps_nbr_list *a[3] = {&full, &ff, &fr}, *b[3] = {&bare, &bf, &br};
    size_t bad = 0, pairs = 0;
    for (int w = 0; w < 3; w++) {
        for (size_t i = 0; i <= n; i++)
            bad += a[w]->start[i] != b[w]->start[i];
        for (size_t k = 0; k < a[w]->start[n] && k < b[w]->start[n]; k++)
            bad += a[w]->j[k] != b[w]->j[k];
        pairs += a[w]->start[n];
    }
    CHECK(bad == 0);
    CHECK(ff.start[n] > 0 && ff.start[n] < full.start[n]);
    printf("  no_r2: %zu pairs in build, filter and reverse, %zu differ\n", pairs, bad);
    /* the filter against the pairs it filters, at the moved positions, on
     * the AVX-512 path (where the CPU has it) and the portable one */
    for (int wide = 1; wide >= 0; wide--) {
        mps_simd_set_wide(wide);
        struct mps_nbr_list fw = {0};
        CHECK(mps_nbr_list_filter(&fw, &full, cx, rs, &err) == MPS_OK);
        size_t wrong = filter_errors(&full, &fw, cx, rs);
        CHECK(wrong == 0);
        if (wrong)
            printf("  filter (%s path): %zu entries wrong\n", wide ? "wide" : "portable", wrong);
        mps_nbr_list_free(&fw);
    }
    mps_simd_set_wide(1);
    /* r2 wanted from a list that has none */
    struct mps_nbr_list want = {0};
    CHECK(mps_nbr_list_reverse(&want, &bare, 0, nf, nf, n, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "r2") != NULL);
    struct mps_nbr_list *all[] = {&full, &bare, &ff, &bf, &fr, &br, &want};
    for (int w = 0; w < 7; w++)
        mps_nbr_list_free(all[w]);
    mps_nbr_grid_free(&g);
    free(x);
}

/* `test_nbr avx512` (ctest test_nbr_avx512) runs the parts that compare the
 * AVX-512 path with the portable one, and reports SKIPPED (77) where there is
 * no AVX-512 path (the CPU lacks it, or MPS_SIMD=sse2): without it those
 * parts test the portable path only, which the plain run covers. */
/* The shifting's lattice response (fluid.shifting_weight): d/d eps of
 * sum_j g(r) x_j, g = -w'(r) / r, summed here from the derivative
 * g(r) + g'(r) x^2 / r of each term, against the solver's difference. */
static void test_gradient_response(void)
{
    const double l0 = 0.003, re = 2.1 * l0;
    double mps = 0.0, smooth = 0.0;
    for (int a = -3; a <= 3; a++)
        for (int b = -3; b <= 3; b++) {
            double x = l0 * a, r = l0 * hypot(a, b);
            if (!(a || b) || r >= re)
                continue;
            /* w = re/r - 1: g = re/r^3, g' = -3 re/r^4 */
            mps += re / (r * r * r) - 3.0 * re * x * x / pow(r, 5);
            /* w = (1 - r/re)^2: g = 2/(re r) - 2/re^2, g' = -2/(re r^2) */
            smooth += 2.0 / (re * r) - 2.0 / (re * re) - 2.0 * x * x / (re * r * r * r);
        }
    double rm = mps_lattice_gradient_response(l0, re, 0);
    double rs = mps_lattice_gradient_response(l0, re, 1);
    CHECK_NEAR(rm, fabs(mps), 1e-6 * fabs(mps));
    CHECK_NEAR(rs, fabs(smooth), 1e-6 * fabs(smooth));
    /* per unit of l0^-2 they do not depend on the spacing; the ratio the
     * shifting scales the smooth weight by is about 5 at re = 2.1 l0 */
    CHECK_NEAR(rm / rs, mps_lattice_gradient_response(1.0, 2.1, 0) /
                            mps_lattice_gradient_response(1.0, 2.1, 1), 1e-6);
    CHECK(rm / rs > 4.9 && rm / rs < 5.1);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "avx512") == 0) {
        if (!mps_simd_wide()) {
            printf("SKIPPED: no AVX-512 path here (CPU without avx512f, or MPS_SIMD=sse2)\n");
            return TEST_SKIPPED;
        }
        test_random();
        test_no_r2();
        test_kernel();
        return test_summary("test_nbr avx512");
    }
    test_random();
    test_masked_reverse();
    test_cell_order();
    test_particles_permute();
    test_no_r2();
    test_lattice(1.0, 0.0);
    test_lattice(0.01, -0.35);
    test_errors();
    test_kernel();
    test_gradient_response();
    return test_summary("test_nbr");
}
