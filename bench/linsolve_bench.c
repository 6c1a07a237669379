/* PPE solver micro-benchmark: times each fluid_linsolve method on one matrix,
 * from a cold start (x = 0, new solver) and a warm one (same solver, second
 * matrix, x = the solution for a right-hand side perturbed by 1e-3 relative
 * noise, as the previous step's pressure would be). Each measurement is run
 * --repeat times and the fastest run is printed: the machine is shared, so
 * the minimum is the least noisy estimate of the cost.
 *
 *   linsolve_bench [options] A.mtx [b.mtx [A2.mtx [b2.mtx]]]
 *   linsolve_bench [options] --synthetic N
 *
 * A.mtx: Matrix Market "matrix coordinate real|integer symmetric|general",
 * either one triangle (mirrored) or both. b.mtx: Matrix Market array or
 * coordinate, or plain numbers one per line; default b = A * 1. A2/b2: the
 * next step's matrix (warm rows use it; same n expected), default A/b.
 * --synthetic N: jittered-lattice MPS matrix with about N rows (see
 * synth_build); the warm matrix has every particle moved a little, so its
 * pattern differs as after a real time step.
 * A method written NAME@THETA (pcg_sic0@0.02) runs with that drop threshold
 * (fluid_linsolve_set_drop), so several thresholds fit in one --methods. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <omp.h>

#include "fluid_linsolve.h"

struct mat {
    int n;
    int *rowptr, *col;
    double *val;
    struct fluid_csr csr;
};

static void mat_free(struct mat *m)
{
    free(m->rowptr);
    free(m->col);
    free(m->val);
    memset(m, 0, sizeof *m);
}

static void die(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));
static void die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "linsolve_bench: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    exit(1);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        die("out of memory (%zu bytes)", n);
    return p;
}

/* ---- triplets -> CSR (both triangles, sorted, duplicates summed) ---- */

struct trip {
    size_t nz, cap;
    int *i, *j;
    double *v;
};

static void trip_add(struct trip *t, int i, int j, double v)
{
    if (t->nz == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 1024;
        t->i = realloc(t->i, t->cap * sizeof *t->i);
        t->j = realloc(t->j, t->cap * sizeof *t->j);
        t->v = realloc(t->v, t->cap * sizeof *t->v);
        if (!t->i || !t->j || !t->v)
            die("out of memory reading %zu entries", t->cap);
    }
    t->i[t->nz] = i;
    t->j[t->nz] = j;
    t->v[t->nz] = v;
    t->nz++;
}

static void trip_free(struct trip *t)
{
    free(t->i);
    free(t->j);
    free(t->v);
    memset(t, 0, sizeof *t);
}

struct entry {
    int c;
    double v;
};

static int cmp_entry(const void *a, const void *b)
{
    int x = ((const struct entry *)a)->c, y = ((const struct entry *)b)->c;
    return (x > y) - (x < y);
}

/* mirror: add (j,i) for every off-diagonal (i,j). what: name for messages. */
static void csr_from_trip(struct mat *m, int n, const struct trip *t, int mirror,
                          const char *what)
{
    size_t total = t->nz * (mirror ? 2 : 1);
    int *cnt = calloc((size_t)n + 1, sizeof *cnt);
    struct entry *e = xmalloc(total * sizeof *e);
    if (!cnt)
        die("out of memory");
    for (size_t k = 0; k < t->nz; k++) {
        cnt[t->i[k] + 1]++;
        if (mirror && t->i[k] != t->j[k])
            cnt[t->j[k] + 1]++;
    }
    for (int i = 0; i < n; i++)
        cnt[i + 1] += cnt[i];
    int *pos = xmalloc((size_t)n * sizeof *pos);
    memcpy(pos, cnt, (size_t)n * sizeof *pos);
    for (size_t k = 0; k < t->nz; k++) {
        e[pos[t->i[k]]++] = (struct entry){t->j[k], t->v[k]};
        if (mirror && t->i[k] != t->j[k])
            e[pos[t->j[k]]++] = (struct entry){t->i[k], t->v[k]};
    }
    free(pos);
    m->n = n;
    m->rowptr = xmalloc(((size_t)n + 1) * sizeof *m->rowptr);
    m->col = xmalloc((size_t)cnt[n] * sizeof *m->col);
    m->val = xmalloc((size_t)cnt[n] * sizeof *m->val);
    size_t nz = 0;
    m->rowptr[0] = 0;
    for (int i = 0; i < n; i++) {
        struct entry *r = e + cnt[i];
        int len = cnt[i + 1] - cnt[i], diag = 0;
        qsort(r, (size_t)len, sizeof *r, cmp_entry);
        for (int k = 0; k < len; k++) {
            if (nz > (size_t)m->rowptr[i] && m->col[nz - 1] == r[k].c) {
                m->val[nz - 1] += r[k].v;   /* duplicate: summed, as Matrix Market says */
                continue;
            }
            m->col[nz] = r[k].c;
            m->val[nz++] = r[k].v;
            diag |= r[k].c == i;
        }
        if (!diag)
            die("%s: row %d has no diagonal entry (a PPE row always has one)", what, i + 1);
        if (nz > 2147483647u)
            die("%s: more than 2^31 nonzeros", what);
        m->rowptr[i + 1] = (int)nz;
    }
    free(cnt);
    free(e);
    m->csr = (struct fluid_csr){n, m->rowptr, m->col, m->val};
}

/* Largest |a_ij - a_ji| relative to the largest |a_ij|. */
static double asymmetry(const struct mat *m)
{
    double amax = 0.0, dmax = 0.0;
    for (int i = 0; i < m->n; i++)
        for (int k = m->rowptr[i]; k < m->rowptr[i + 1]; k++) {
            int j = m->col[k];
            amax = fmax(amax, fabs(m->val[k]));
            const int *lo = m->col + m->rowptr[j], *hi = m->col + m->rowptr[j + 1];
            double aji = 0.0;
            while (lo < hi) {   /* binary search for i in row j */
                const int *mid = lo + (hi - lo) / 2;
                if (*mid < i)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            if (lo < m->col + m->rowptr[j + 1] && *lo == i)
                aji = m->val[lo - m->col];
            dmax = fmax(dmax, fabs(m->val[k] - aji));
        }
    return amax > 0.0 ? dmax / amax : 0.0;
}

/* ---- Matrix Market ---- */

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        die("%s: %s", path, strerror(errno));
    size_t cap = 1 << 20, n = 0;
    char *buf = xmalloc(cap + 1);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            cap *= 2;
            buf = realloc(buf, cap + 1);
            if (!buf)
                die("%s: out of memory", path);
        }
    }
    if (ferror(f))
        die("%s: read error", path);
    fclose(f);
    buf[n] = '\0';
    *len = n;
    return buf;
}

/* A cursor over a text file that knows its line number. */
struct cur {
    const char *path;
    char *p;
    long line;
};

/* Skips blanks, newlines and comment lines (% or #); returns 0 at end of file. */
static int skip(struct cur *c)
{
    for (;;) {
        while (*c->p == ' ' || *c->p == '\t' || *c->p == '\r' || *c->p == '\n') {
            if (*c->p == '\n')
                c->line++;
            c->p++;
        }
        if (*c->p == '%' || *c->p == '#') {
            while (*c->p && *c->p != '\n')
                c->p++;
            continue;
        }
        return *c->p != '\0';
    }
}

static double num(struct cur *c, const char *what)
{
    if (!skip(c))
        die("%s: end of file while reading %s", c->path, what);
    char *end;
    errno = 0;
    double v = strtod(c->p, &end);
    if (end == c->p || (*end && !isspace((unsigned char)*end)))
        die("%s:%ld: cannot read %s from \"%.20s\"", c->path, c->line, what, c->p);
    c->p = end;
    return v;
}

static long inum(struct cur *c, const char *what, long lo, long hi)
{
    double v = num(c, what);
    if (v != floor(v) || v < (double)lo || v > (double)hi)
        die("%s:%ld: %s = %g: must be an integer in [%ld, %ld]", c->path, c->line, what, v, lo,
            hi);
    return (long)v;
}

struct mm_header {
    int present, coordinate, symmetric;
};

/* Reads "%%MatrixMarket matrix <format> <field> <symmetry>" if present. */
static struct mm_header mm_header(struct cur *c)
{
    struct mm_header h = {0, 1, 0};
    if (strncasecmp(c->p, "%%MatrixMarket", 14))
        return h;
    h.present = 1;
    char obj[32] = "", fmt[32] = "", field[32] = "", sym[32] = "";
    sscanf(c->p + 14, "%31s %31s %31s %31s", obj, fmt, field, sym);
    if (strcasecmp(obj, "matrix"))
        die("%s:1: Matrix Market object \"%s\": expected matrix", c->path, obj);
    if (!strcasecmp(fmt, "array"))
        h.coordinate = 0;
    else if (strcasecmp(fmt, "coordinate"))
        die("%s:1: format \"%s\": expected coordinate or array", c->path, fmt);
    if (strcasecmp(field, "real") && strcasecmp(field, "integer") && strcasecmp(field, "double"))
        die("%s:1: field \"%s\": expected real or integer (pattern and complex matrices "
            "have no PPE values)",
            c->path, field);
    if (!strcasecmp(sym, "symmetric") || !strcasecmp(sym, "hermitian"))
        h.symmetric = 1;
    else if (strcasecmp(sym, "general") && sym[0])
        die("%s:1: symmetry \"%s\": expected symmetric or general", c->path, sym);
    while (*c->p && *c->p != '\n')
        c->p++;
    return h;
}

static void read_matrix(struct mat *m, const char *path)
{
    size_t len;
    char *buf = slurp(path, &len);
    struct cur c = {path, buf, 1};
    struct mm_header h = mm_header(&c);
    if (!h.present || !h.coordinate)
        die("%s: expected a \"%%%%MatrixMarket matrix coordinate real symmetric\" file", path);
    long nr = inum(&c, "row count", 1, 2147483646L);
    long nc = inum(&c, "column count", 1, 2147483646L);
    long nnz = inum(&c, "entry count", 1, 1L << 40);
    if (nr != nc)
        die("%s: matrix is %ld x %ld: the PPE is square", path, nr, nc);
    struct trip t = {0};
    size_t upper = 0, lower = 0;
    for (long k = 0; k < nnz; k++) {
        if (!skip(&c))
            die("%s: file ends after %ld of the %ld entries its size line announces", path, k,
                nnz);
        int i = (int)inum(&c, "row index", 1, nr) - 1;
        int j = (int)inum(&c, "column index", 1, nr) - 1;
        double v = num(&c, "value");
        upper += j > i;
        lower += i > j;
        trip_add(&t, i, j, v);
    }
    if (skip(&c))
        fprintf(stderr, "%s:%ld: note: text after the %ld entries ignored\n", path, c.line, nnz);
    /* One triangle stored: mirror it. Both stored (some writers do that even
     * under "symmetric"): take the file as the full matrix. */
    int mirror = !(upper && lower);
    if (h.symmetric && !mirror)
        fprintf(stderr, "%s: note: header says symmetric but both triangles are stored: "
                        "read as full storage\n", path);
    if (!h.symmetric && mirror && (upper || lower))
        fprintf(stderr, "%s: note: general matrix with one triangle only: mirrored\n", path);
    csr_from_trip(m, (int)nr, &t, mirror, path);
    trip_free(&t);
    free(buf);
    double asym = asymmetry(m);
    if (asym > 1e-12)
        fprintf(stderr, "%s: warning: matrix is not symmetric (max |a_ij - a_ji| / max |a| = "
                        "%.2g); CG and Cholesky assume it is\n", path, asym);
}

static double *read_vector(const char *path, int n)
{
    size_t len;
    char *buf = slurp(path, &len);
    struct cur c = {path, buf, 1};
    struct mm_header h = mm_header(&c);
    double *b = calloc((size_t)n, sizeof *b);
    if (!b)
        die("out of memory");
    if (h.present && h.coordinate) {
        long nr = inum(&c, "row count", 1, 2147483646L);
        long nc = inum(&c, "column count", 1, 2147483646L);
        long nnz = inum(&c, "entry count", 0, 1L << 40);
        if (nr * nc != n || (nr != 1 && nc != 1))
            die("%s: vector is %ld x %ld: expected %d x 1", path, nr, nc, n);
        for (long k = 0; k < nnz; k++) {
            long i = inum(&c, "row index", 1, nr) - 1, j = inum(&c, "column index", 1, nc) - 1;
            b[i + j] += num(&c, "value");
        }
    } else {
        if (h.present) {
            long nr = inum(&c, "row count", 1, 2147483646L);
            long nc = inum(&c, "column count", 1, 2147483646L);
            if (nr * nc != n || (nr != 1 && nc != 1))
                die("%s: vector is %ld x %ld: expected %d x 1", path, nr, nc, n);
        }
        for (int i = 0; i < n; i++) {
            if (!skip(&c))
                die("%s: %d values for a matrix with %d rows", path, i, n);
            b[i] = num(&c, "right-hand side value");
        }
        if (skip(&c))
            die("%s:%ld: more than %d values for a matrix with %d rows", path, c.line, n, n);
    }
    free(buf);
    return b;
}

/* ---- synthetic PPE ---- */

static unsigned long long rng = 88172645463325252ull;
static double urand(void)   /* xorshift64, uniform in [0, 1) */
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

struct synth {
    int nx, ny;
    double (*x)[2];   /* particle positions, spacing 1 */
    int *perm;        /* lattice unknown -> row (identity unless shuffled) */
};

/* nx x ny particles on a unit lattice with uniform jitter 0.1, the top row a
 * free surface (Dirichlet p = 0: no unknown). Row a: a_aa = (1 + eps) sum_b
 * w_ab over every neighbour, a_ab = -w_ab between unknowns, w = re/r - 1 for
 * r < re = 4 (MPS weight, neighbours within 4 spacings). eps stands for the
 * weak-compressibility term. */
static void synth_init(struct synth *s, int nrows, int shuffle)
{
    s->nx = (int)ceil(sqrt((double)nrows));
    s->ny = nrows / s->nx + 1 + (nrows % s->nx != 0);
    int np = s->nx * s->ny, n = s->nx * (s->ny - 1);
    s->x = xmalloc((size_t)np * sizeof *s->x);
    for (int j = 0; j < s->ny; j++)
        for (int i = 0; i < s->nx; i++) {
            s->x[j * s->nx + i][0] = i + 0.1 * (2.0 * urand() - 1.0);
            s->x[j * s->nx + i][1] = j + 0.1 * (2.0 * urand() - 1.0);
        }
    s->perm = xmalloc((size_t)n * sizeof *s->perm);
    for (int i = 0; i < n; i++)
        s->perm[i] = i;
    for (int i = n - 1; shuffle && i > 0; i--) {   /* Fisher-Yates */
        int k = (int)(urand() * (i + 1)), tmp = s->perm[i];
        s->perm[i] = s->perm[k];
        s->perm[k] = tmp;
    }
}

/* Moves every particle by up to `step` in a random direction (one time step). */
static void synth_move(struct synth *s, double step)
{
    for (int k = 0; k < s->nx * s->ny; k++) {
        double a = 6.283185307179586 * urand();
        s->x[k][0] += step * cos(a);
        s->x[k][1] += step * sin(a);
    }
}

static void synth_build(const struct synth *s, struct mat *m, double eps)
{
    const double re = 4.0;
    const int w = 5;   /* lattice window: re + jitter + motion < 5 spacings */
    int nx = s->nx, ny = s->ny, n = nx * (ny - 1);
    struct trip t = {0};
    for (int a = 0; a < n; a++) {
        int ai = a % nx, aj = a / nx;
        double sum = 0.0;
        for (int bj = aj - w; bj <= aj + w; bj++)
            for (int bi = ai - w; bi <= ai + w; bi++) {
                int b = bj * nx + bi;
                if (bi < 0 || bi >= nx || bj < 0 || bj >= ny || b == a)
                    continue;
                double dx = s->x[b][0] - s->x[a][0], dy = s->x[b][1] - s->x[a][1];
                double r = sqrt(dx * dx + dy * dy);
                if (r >= re)
                    continue;
                double wab = re / r - 1.0;
                sum += wab;
                if (bj < ny - 1)
                    trip_add(&t, s->perm[a], s->perm[b], -wab);
            }
        trip_add(&t, s->perm[a], s->perm[a], (1.0 + eps) * sum);
    }
    csr_from_trip(m, n, &t, 0, "synthetic");
    trip_free(&t);
}

/* b = A p, p = hydrostatic depth plus 1% noise: a smooth pressure field, the
 * hard case for CG (low modes converge last). */
static double *synth_rhs(const struct synth *s, const struct mat *m)
{
    double *p = xmalloc((size_t)m->n * sizeof *p), *b = xmalloc((size_t)m->n * sizeof *b);
    for (int a = 0; a < m->n; a++)
        p[s->perm[a]] = (s->ny - 1 - s->x[a][1]) + 0.01 * urand();
    for (int i = 0; i < m->n; i++) {
        double acc = 0.0;
        for (int k = m->rowptr[i]; k < m->rowptr[i + 1]; k++)
            acc += m->val[k] * p[m->col[k]];
        b[i] = acc;
    }
    free(p);
    return b;
}

/* ---- measurement ---- */

static double relres(const struct mat *m, const double *b, const double *x)
{
    double rr = 0.0, bb = 0.0;
    for (int i = 0; i < m->n; i++) {
        double acc = 0.0;
        for (int k = m->rowptr[i]; k < m->rowptr[i + 1]; k++)
            acc += m->val[k] * x[m->col[k]];
        rr += (b[i] - acc) * (b[i] - acc);
        bb += b[i] * b[i];
    }
    return bb > 0.0 ? sqrt(rr / bb) : 0.0;
}

struct run {
    struct fluid_linsolve_stats st;
    double total, check;
};

static int solve_timed(struct fluid_linsolve *s, const struct mat *m, const double *b,
                       double *x, struct run *r)
{
    struct mps_err err = {0};
    double t0 = omp_get_wtime();
    enum mps_status rc = fluid_linsolve_solve(s, &m->csr, b, x, &r->st, &err);
    r->total = omp_get_wtime() - t0;
    if (rc) {
        fprintf(stderr, "linsolve_bench: %s\n", err.msg);
        return -1;
    }
    r->check = relres(m, b, x);
    return 0;
}

static void print_row(const char *method, const char *start, const struct mat *m,
                      const struct run *r)
{
    printf("| %-15s | %-4s | %6d | %5.1f | %8.2f | %8.2f | %8.2f | %5d | %8.2f | %8.1e |\n",
           method, start, m->n, (double)m->rowptr[m->n] / m->n, 1e3 * r->st.t_analyse,
           1e3 * r->st.t_factor, 1e3 * r->st.t_solve, r->st.iterations, 1e3 * r->total,
           r->check);
}

static void usage(void)
{
    fprintf(stderr,
            "usage: linsolve_bench [options] A.mtx [b.mtx [A2.mtx [b2.mtx]]]\n"
            "       linsolve_bench [options] --synthetic N\n"
            "options:\n"
            "  --methods LIST  comma-separated, from: %s\n"
            "                  (default pcg_jacobi,pcg_ic0,cholmod,cholmod_reuse);\n"
            "                  NAME@THETA sets the drop threshold (pcg_sic0@0.02)\n"
            "  --repeat K      runs per measurement, fastest kept (default 3)\n"
            "  --threads T     OpenMP threads, 0 = default (default 0)\n"
            "  --rtol R        relative residual for PCG (default 1e-6, as fluid.ppe_rtol)\n"
            "  --max-iter M    PCG iteration cap (default 20000)\n"
            "  --eps E         synthetic: weak-compressibility term / diagonal (default 1e-3;\n"
            "                  rho alpha / dt^2 over 1.5 / dp^2 is 1e-3..3e-2 with the\n"
            "                  default fluid.alpha and dt = 1e-3..2e-4 s)\n"
            "  --step D        synthetic: particle motion between the two matrices, in\n"
            "                  particle spacings (default 0.02)\n"
            "  --shuffle       synthetic: number the unknowns randomly (no locality)\n"
            "  --warm-noise E  relative noise on b for the warm start (default 1e-3;\n"
            "                  larger: a worse initial guess, more warm iterations)\n",
            fluid_linsolve_methods());
    exit(2);
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);   /* rows appear as they are measured */
    const char *methods = "pcg_jacobi,pcg_ic0,cholmod,cholmod_reuse";
    int repeat = 3, threads = 0, max_iter = 20000, synthetic = 0, shuffle = 0;
    double rtol = 1e-6, eps = 1e-3, step = 0.02, warm_noise = 1e-3;
    const char *files[4] = {NULL, NULL, NULL, NULL};
    int nfiles = 0;
    for (int a = 1; a < argc; a++) {
        const char *o = argv[a];
        int more = a + 1 < argc;
        if (!strcmp(o, "--methods") && more)
            methods = argv[++a];
        else if (!strcmp(o, "--repeat") && more)
            repeat = atoi(argv[++a]);
        else if (!strcmp(o, "--threads") && more)
            threads = atoi(argv[++a]);
        else if (!strcmp(o, "--rtol") && more)
            rtol = atof(argv[++a]);
        else if (!strcmp(o, "--max-iter") && more)
            max_iter = atoi(argv[++a]);
        else if (!strcmp(o, "--eps") && more)
            eps = atof(argv[++a]);
        else if (!strcmp(o, "--step") && more)
            step = atof(argv[++a]);
        else if (!strcmp(o, "--synthetic") && more)
            synthetic = atoi(argv[++a]);
        else if (!strcmp(o, "--warm-noise") && more)
            warm_noise = atof(argv[++a]);
        else if (!strcmp(o, "--shuffle"))
            shuffle = 1;
        else if (o[0] == '-' && o[1])
            usage();
        else if (nfiles < 4)
            files[nfiles++] = o;
        else
            usage();
    }
    if (repeat < 1 || (synthetic <= 0 && nfiles == 0) || (synthetic > 0 && nfiles > 0))
        usage();
    if (!(step >= 0.0 && step <= 0.3))   /* synth_build looks 5 spacings around a particle */
        die("--step %g: must be in [0, 0.3]", step);

    /* Two consecutive "steps": (A0, b0) cold, (A1, b1) warm. */
    struct mat A0 = {0}, A1 = {0};
    double *b0 = NULL, *b1 = NULL;
    if (synthetic > 0) {
        struct synth sy;
        synth_init(&sy, synthetic, shuffle);
        synth_build(&sy, &A0, eps);
        b0 = synth_rhs(&sy, &A0);
        synth_move(&sy, step);
        synth_build(&sy, &A1, eps);
        b1 = synth_rhs(&sy, &A1);
        printf("synthetic PPE: %d x %d lattice, jitter 0.1, re = 4, eps = %g, step %g%s\n",
               sy.nx, sy.ny, eps, step, shuffle ? ", shuffled numbering" : "");
        free(sy.x);
        free(sy.perm);
    } else {
        read_matrix(&A0, files[0]);
        if (files[1]) {
            b0 = read_vector(files[1], A0.n);
        } else {
            b0 = xmalloc((size_t)A0.n * sizeof *b0);
            for (int i = 0; i < A0.n; i++) {
                b0[i] = 0.0;
                for (int k = A0.rowptr[i]; k < A0.rowptr[i + 1]; k++)
                    b0[i] += A0.val[k];
            }
            printf("no right-hand side given: b = A * 1\n");
        }
        if (files[2]) {
            read_matrix(&A1, files[2]);
            if (!files[3])
                die("%s given without its right-hand side", files[2]);
            b1 = read_vector(files[3], A1.n);
        } else {
            A1 = A0;   /* shared arrays: A1 is not freed separately */
            b1 = b0;
            printf("note: one matrix only: warm rows reuse it, so cholmod_reuse keeps its "
                   "whole analysis (same pattern)\n");
        }
        printf("matrix %s: n = %d, nnz = %d\n", files[0], A0.n, A0.rowptr[A0.n]);
    }
    int nthr = threads > 0 ? threads : omp_get_max_threads();
    char load[64] = "?";
    FILE *lf = fopen("/proc/loadavg", "r");
    if (lf) {
        if (!fgets(load, sizeof load, lf))
            strcpy(load, "?");
        load[strcspn(load, "\n")] = '\0';
        fclose(lf);
    }
    printf("threads %d, rtol %g, warm noise %g, min of %d runs, load average before: %s\n",
           nthr, rtol, warm_noise, repeat, load);

    /* Warm start: the solution for b1 * (1 + warm_noise * noise). Solved with PCG to
     * a tight tolerance rather than with CHOLMOD: OpenBLAS threads left
     * spinning by a factorisation would slow the first timed PCG runs. */
    double *xwarm = xmalloc((size_t)A1.n * sizeof *xwarm);
    {
        double *bp = xmalloc((size_t)A1.n * sizeof *bp);
        for (int i = 0; i < A1.n; i++)
            bp[i] = b1[i] * (1.0 + warm_noise * (2.0 * urand() - 1.0));
        struct fluid_linsolve *s = NULL;
        struct mps_err err = {0};
        memset(xwarm, 0, (size_t)A1.n * sizeof *xwarm);
        if (fluid_linsolve_create(&s, "pcg_ic0", 1e-10, 5000, threads, &err))
            die("%s", err.msg);
        enum mps_status rc = fluid_linsolve_solve(s, &A1.csr, bp, xwarm, NULL, &err);
        if (rc == MPS_ESOLVE && strstr(err.msg, "did not converge"))   /* close enough */
            fprintf(stderr, "note: warm-start solution: %s\n", err.msg);
        else if (rc)
            die("warm-start solution: %s", err.msg);
        fluid_linsolve_destroy(&s);
        free(bp);
    }

    printf("\n| method          | start|      n | nnz/r | analyse  | factor   | solve    | "
           "iters | total    | residual |\n");
    printf("|-----------------|------|--------|-------|----------|----------|----------|-------"
           "|----------|----------|\n");
    double *x = xmalloc((size_t)(A0.n > A1.n ? A0.n : A1.n) * sizeof *x);
    char *list = strdup(methods);
    int failed = 0;
    for (char *save = NULL, *name = strtok_r(list, ",", &save); name;
         name = strtok_r(NULL, ",", &save)) {
        struct run best[2] = {0}, r;
        best[0].total = best[1].total = INFINITY;
        int ok = 1;
        char label[64];
        snprintf(label, sizeof label, "%s", name);
        char *at = strchr(name, '@');
        double theta = 0.0;
        if (at) {
            char *end;
            *at = '\0';
            theta = strtod(at + 1, &end);
            if (end == at + 1 || *end)
                die("method \"%s\": expected NAME@THETA with a number after @", label);
        }
        for (int k = 0; k < repeat && ok; k++) {
            struct fluid_linsolve *s = NULL;
            struct mps_err err = {0};
            if (fluid_linsolve_create(&s, name, rtol, max_iter, threads, &err) ||
                (at && fluid_linsolve_set_drop(s, theta, &err)))
                die("%s", err.msg);
            memset(x, 0, (size_t)A0.n * sizeof *x);
            ok = !solve_timed(s, &A0, b0, x, &r);
            if (ok && r.total < best[0].total)
                best[0] = r;
            memcpy(x, xwarm, (size_t)A1.n * sizeof *x);
            ok = ok && !solve_timed(s, &A1, b1, x, &r);
            if (ok && r.total < best[1].total)
                best[1] = r;
            fluid_linsolve_destroy(&s);
        }
        if (!ok) {
            failed = 1;
            continue;
        }
        print_row(label, "cold", &A0, &best[0]);
        print_row(label, "warm", &A1, &best[1]);
        fflush(stdout);
    }
    free(list);
    free(x);
    free(xwarm);
    if (A1.rowptr != A0.rowptr) {
        mat_free(&A1);
        free(b1);
    }
    mat_free(&A0);
    free(b0);
    return failed;
}
