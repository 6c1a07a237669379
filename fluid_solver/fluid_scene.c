#include "fluid_scene.h"

#include <math.h>
#include <stdlib.h>

#include "fluid.h"
#include "mps_kernel.h"

struct pts_buf {
    struct fluid_scene_pt *a;
    size_t n, cap;
};

static int push(struct pts_buf *b, double x, double y, int type)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        void *q = realloc(b->a, cap * sizeof *b->a);
        if (!q)
            return -1;
        b->a = q;
        b->cap = cap;
    }
    b->a[b->n++] = (struct fluid_scene_pt){{x, y}, type};
    return 0;
}

/* splitmix64 of (seed, particle, axis): a uniform number in [-1, 1) that
 * depends on nothing else, so a realisation is the same whatever the order or
 * thread count that builds it. */
static double jitter_unit(unsigned long seed, size_t k, int axis)
{
    unsigned long long z = (unsigned long long)seed * 0x9E3779B97F4A7C15ULL +
                           (2ULL * k + (unsigned long long)axis + 1ULL) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-52 - 1.0;
}

/* Wall points along an inner face of length len: the lattice (i + 1/2) dp,
 * i < n = mps_lattice_count(0, len, dp), which ends r = len - n dp short of the
 * far wall, whose first column stands at len + dp/2. Left so, the last gap
 * is r + dp wide, and when len is not a whole number of spacings particles
 * creep through that corner: the 3 mm dam-break plate (0.584 m is 194.67
 * spacings) used the tank guard 3-59 times in 1-2 s, the 4 and 8 mm runs
 * (146 and 73 spacings) never. So r >= dp/2 gets one more point in the
 * middle of the gap (spacings (dp + r)/2, 0.75-1 dp); a smaller r moves the
 * last point on by r/2 (spacings at most 1.25 dp). A whole number of
 * spacings gives the plain lattice, point for point. Returns the count;
 * wall_point gives point k of it. */
static long wall_count(double len, double dp)
{
    long n = mps_lattice_count(0.0, len, dp);
    return n + (len - n * dp >= 0.5 * dp);
}

static double wall_point(long k, double len, double dp)
{
    long n = mps_lattice_count(0.0, len, dp);
    double r = len - n * dp;
    if (r < 1e-6 * dp || k < n - 1)
        return (k + 0.5) * dp;
    if (k == n)
        return 0.5 * (n * dp + len);
    return (k + 0.5) * dp + (r < 0.5 * dp ? 0.5 * r : 0.0);
}

int fluid_scene_build(const struct fluid_params *p, struct fluid_scene_pt **pts, size_t *nfluid,
                      size_t *nwall)
{
    struct pts_buf b = {0};
    const double dp = p->dp, W = p->tank_w, H = p->tank_h;
    const int L = p->wall_layers;

    for (int k = 0; k < p->nblocks; k++) {
        const double *bl = p->block[k];
        long ni = mps_lattice_count(bl[0], bl[2], dp), nj = mps_lattice_count(bl[1], bl[3], dp);
        for (long j = 0; j < nj; j++)
            for (long i = 0; i < ni; i++)
                if (push(&b, bl[0] + (i + 0.5) * dp, bl[1] + (j + 0.5) * dp, FLUID_P))
                    goto fail;
    }
    size_t nf = b.n;
    for (size_t k = 0; p->jitter > 0.0 && k < nf; k++)
        for (int d = 0; d < MPS_DIM; d++)
            b.a[k].x[d] += p->jitter * dp * jitter_unit(p->jitter_seed, k, d);

    /* Side walls run from the bottom of the dummy layers to the top of the
     * wall (or of the lid's layers); the floor (and lid) span the inner width,
     * closed at the far corner by wall_point. The side walls of an open tank
     * keep the plain lattice up to their top, where no corner is closed. */
    long nx = wall_count(W, dp);
    long ny = p->tank_lid ? wall_count(H, dp) : mps_lattice_count(0.0, H, dp);
    for (int layer = 0; layer < L; layer++) {
        int type = layer == 0 ? WALL_P : DUMMY_P;
        double off = (layer + 0.5) * dp;
        /* corner points belong to the layer of their larger distance */
        for (long j = 0; j < L + ny; j++) {
            double y = j < L ? -L * dp + (j + 0.5) * dp
                             : p->tank_lid ? wall_point(j - L, H, dp) : (j - L + 0.5) * dp;
            int t = (y < 0 && (int)floor(-y / dp) > layer) ? DUMMY_P : type;
            if (push(&b, -off, y, t) || push(&b, W + off, y, t))
                goto fail;
        }
        for (int k = 0; p->tank_lid && k < L; k++) {
            double y = H + (k + 0.5) * dp;
            int t = k > layer ? DUMMY_P : type;
            if (push(&b, -off, y, t) || push(&b, W + off, y, t))
                goto fail;
        }
        for (long i = 0; i < nx; i++) {
            double x = wall_point(i, W, dp);
            if (push(&b, x, -off, type))
                goto fail;
            if (p->tank_lid && push(&b, x, H + off, type))
                goto fail;
        }
    }
    *pts = b.a;
    *nfluid = nf;
    *nwall = b.n - nf;
    return 0;
fail:
    free(b.a);
    return -1;
}
