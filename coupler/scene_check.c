#include "scene_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

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
