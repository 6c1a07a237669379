#include "scene_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "mps_kernel.h"

/* A rectangle of the layout, as the case gives it: PREFIX.x0, y0, x1, y1. */
struct rect {
    double x0, y0, x1, y1;
};

/* 1 and *v if key holds a finite number; 0 if absent or not one (the owner's
 * to report). */
static int raw_number(const struct mps_case *c, const char *key, double *v)
{
    const char *s = mps_case_text(c, "%s", key);
    if (!s || !*s)
        return 0;
    char *end;
    *v = strtod(s, &end);
    return *end == '\0' && isfinite(*v);
}

/* 1 and *r if the four corners of the rectangle at prefix are numbers and
 * x0 < x1, y0 < y1; 0 otherwise. */
static int raw_rect(const struct mps_case *c, const char *prefix, struct rect *r)
{
    char key[160];
    double *v[4] = {&r->x0, &r->y0, &r->x1, &r->y1};
    static const char *const corner[4] = {"x0", "y0", "x1", "y1"};
    for (int k = 0; k < 4; k++) {
        snprintf(key, sizeof key, "%s.%s", prefix, corner[k]);
        if (!raw_number(c, key, v[k]))
            return 0;
    }
    return r->x0 < r->x1 && r->y0 < r->y1;
}

/* 1 if a clamp of the body named name covers [x0, x1] x [y0, y1]. */
static int clamped(const struct mps_case *c, const char *name, double x0, double y0, double x1,
                   double y1, double tol)
{
    int n = mps_case_count(c, "solid.clamps");
    for (int k = 0; k < n; k++) {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "solid.clamps.%d", k);
        const char *body = mps_case_text(c, "%s.body", prefix);
        struct rect q;
        if (body && strcmp(body, name) == 0 && raw_rect(c, prefix, &q) && q.x0 <= x0 + tol &&
            q.y0 <= y0 + tol && q.x1 >= x1 - tol && q.y1 >= y1 - tol)
            return 1;
    }
    return 0;
}

/* fluid.tank.lid as a YAML boolean; absent: no lid (the fluid's default). */
static int raw_lid(const struct mps_case *c)
{
    const char *s = mps_case_text(c, "fluid.tank.lid");
    static const char *const yes[] = {"true", "yes", "on", "1"}; /* as mps_case reads */
    for (int k = 0; s && k < 4; k++)
        if (strcasecmp(s, yes[k]) == 0)
            return 1;
    return 0;
}

enum mps_status scene_check_fsi(const struct mps_case *c, struct mps_err *err)
{
    double W, H;
    if (!raw_number(c, "fluid.tank.width", &W) || !raw_number(c, "fluid.tank.height", &H))
        return MPS_OK; /* the fluid names what is wrong with its tank */
    /* dp/1000 absorbs decimal round-off in the file, as for water blocks */
    const double tol = 1e-3 * mps_case_double(c, "dp");
    const int lid = raw_lid(c);
    const int nbodies = mps_case_count(c, "solid.bodies");
    const int nblocks = mps_case_count(c, "fluid.blocks");
    char key[96], prefix[64];
    for (int b = 0; b < nbodies; b++) {
        struct rect d;
        snprintf(prefix, sizeof prefix, "solid.bodies.%d", b);
        const char *name = mps_case_text(c, "%s.name", prefix);
        if (!name || !raw_rect(c, prefix, &d))
            continue; /* the solid names what is wrong with this body */
        /* an open tank may hold a body that stands above its walls; a part
         * sunk into a wall is allowed when it is clamped (it replaces the
         * wall there: cases/hard_plate_at_rest), a free part is not */
        const char *side =
            d.x0 < -tol && !clamped(c, name, d.x0, d.y0, 0.0, d.y1, tol)   ? "x0"
            : d.y0 < -tol && !clamped(c, name, d.x0, d.y0, d.x1, 0.0, tol) ? "y0"
            : d.x1 > W + tol && !clamped(c, name, W, d.y0, d.x1, d.y1, tol) ? "x1"
            : lid && d.y1 > H + tol && !clamped(c, name, d.x0, H, d.x1, d.y1, tol)
                ? "y1"
                : NULL;
        if (side) {
            snprintf(key, sizeof key, "%s.%s", prefix, side);
            return mps_case_fail(c, err, key,
                                 "body '%s' lies outside the tank [0, %g] x [0, %g] (a part "
                                 "sunk into a wall must be inside one clamp)",
                                 name, W, H);
        }
        for (int k = 0; k < nblocks; k++) {
            struct rect w;
            char block[64];
            snprintf(block, sizeof block, "fluid.blocks.%d", k);
            if (raw_rect(c, block, &w) && fmin(d.x1, w.x1) - fmax(d.x0, w.x0) > tol &&
                fmin(d.y1, w.y1) - fmax(d.y0, w.y0) > tol) {
                snprintf(key, sizeof key, "%s.x0", prefix);
                return mps_case_fail(c, err, key, "body '%s' overlaps the water block "
                                     "fluid.blocks.%d ([%g, %g] x [%g, %g])",
                                     name, k, w.x0, w.x1, w.y0, w.y1);
            }
        }
    }
    return MPS_OK;
}

/* The gap, in spacings, between a water block ending at a body's face and
 * the body's first particles, along one axis: block [b0, b1] below, body
 * [d0, d1] above (or the mirror image). 1 is the lattice; 0 if the two do
 * not meet there. */
static double face_gap(double b0, double b1, double d0, double d1, double dp, double tol)
{
    if (fabs(b1 - d0) <= tol) /* the water, then the body */
        return (d0 + 0.5 * dp - (b0 + ((double)mps_lattice_count(b0, b1, dp) - 0.5) * dp)) / dp;
    if (fabs(d1 - b0) <= tol) /* the body, then the water */
        return (b0 + 0.5 * dp - (d0 + ((double)mps_lattice_count(d0, d1, dp) - 0.5) * dp)) / dp;
    return 0.0;
}

int scene_check_lattice(const struct mps_case *c, int with_fluid, FILE *out)
{
    const double dp = mps_case_double(c, "dp");
    const double tol = 1e-3 * dp;
    const char *path = mps_case_origin(c);
    const int nbodies = mps_case_count(c, "solid.bodies");
    const int nblocks = with_fluid ? mps_case_count(c, "fluid.blocks") : 0;
    static const char *const what[2] = {"width", "height"};
    int nwarn = 0;
    for (int b = 0; b < nbodies; b++) {
        struct rect d;
        char prefix[64];
        snprintf(prefix, sizeof prefix, "solid.bodies.%d", b);
        const char *name = mps_case_text(c, "%s.name", prefix);
        if (!name || !raw_rect(c, prefix, &d))
            continue; /* the solid names what is wrong with this body */
        const double lo[2] = {d.x0, d.y0}, hi[2] = {d.x1, d.y1};
        for (int a = 0; a < 2; a++) {
            const double len = hi[a] - lo[a], s = len / dp;
            const long n = mps_lattice_count(lo[a], hi[a], dp);
            if (s - (double)n <= 1e-3)
                continue;
            fprintf(out,
                    "coupler: warning: %s: %s.%s1: body '%s' is %g m in %s, %.3f spacings of "
                    "dp = %g m: it is built %ld spacings (%g m, %.1f%% less), as its particles "
                    "fill whole spacings only; a dp that divides %g m builds it as declared\n",
                    path, prefix, a ? "y" : "x", name, len, what[a], s, dp, n, (double)n * dp,
                    100.0 * (1.0 - (double)n / s), len);
            nwarn++;
        }
        for (int k = 0; k < nblocks; k++) {
            struct rect w;
            char block[64];
            snprintf(block, sizeof block, "fluid.blocks.%d", k);
            if (!raw_rect(c, block, &w))
                continue;
            /* faces that meet over some length: across x (the rows overlap
             * in y) or across y */
            const double gx = fmin(d.y1, w.y1) - fmax(d.y0, w.y0) > tol
                                  ? face_gap(w.x0, w.x1, d.x0, d.x1, dp, tol) : 0.0;
            const double gy = fmin(d.x1, w.x1) - fmax(d.x0, w.x0) > tol
                                  ? face_gap(w.y0, w.y1, d.y0, d.y1, dp, tol) : 0.0;
            for (int a = 0; a < 2; a++) {
                const double g = a ? gy : gx;
                if (g == 0.0 || fabs(g - 1.0) <= 0.01)
                    continue;
                fprintf(out,
                        "coupler: warning: %s: %s: its water stands %.2f spacings from body "
                        "'%s' across %s instead of 1 (dp = %g m does not divide the block or "
                        "the body): the pressure beside the body starts wrong, and the first "
                        "steps close the gap; a dp that divides both avoids it\n",
                        path, block, g, name, a ? "y" : "x", dp);
                nwarn++;
            }
        }
    }
    return nwarn;
}
