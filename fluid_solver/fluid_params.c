#include "fluid_params.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mps_budget.h"

#define NOHI (MPS_KEY_NO_HI)
#define POS (MPS_KEY_LO_OPEN | MPS_KEY_NO_HI)

const struct mps_key_spec fluid_case_keys[] = {
    /* bounded above (no liquid is denser than 2.3e4 kg/m^3) because 1e300
     * overflowed the PPE's right-hand side to a non-finite residual */
    {"fluid.rho", MPS_KEY_DOUBLE, "1000", 0, 1e5, MPS_KEY_LO_OPEN, NULL, "kg/m^3",
     "water density"},
    {"fluid.nu", MPS_KEY_DOUBLE, "1e-6", 0, 0, NOHI, NULL, "m^2/s", "kinematic viscosity"},
    {"fluid.courant", MPS_KEY_DOUBLE, "0.2", 0, 1, MPS_KEY_LO_OPEN, NULL, "",
     "Courant number C of Eq. 52"},
    {"fluid.droplet_neighbours", MPS_KEY_INT, "0", 0, 12, 0, NULL, "",
     "particles with fewer neighbours within re_n than this (droplets: P = 0, ballistic) "
     "do not set the Courant step (Eq. 52); they are held to move at most dp per step "
     "instead (0: every particle sets it, the paper)"},
    {"fluid.dt_max", MPS_KEY_DOUBLE, "1e-3", 0, 0, POS, NULL, "s", "cap on the fluid step"},
    {"fluid.dt_min", MPS_KEY_DOUBLE, "1e-7", 0, 0, POS, NULL, "s",
     "smallest step the CFL condition may ask for before the run is declared diverged; "
     "end_time and the output intervals may not be shorter"},
    {"fluid.kappa", MPS_KEY_DOUBLE, "0.01", 0, 1, MPS_KEY_LO_OPEN, NULL, "",
     "relaxation of the PPE source term (Eq. 23)"},
    {"fluid.kappa_dt", MPS_KEY_DOUBLE, "0", 0, 0, NOHI, NULL, "s",
     "Eq. 23's kappa per step of at least this length: a step dt shorter than kappa_dt "
     "corrects kappa dt / kappa_dt of the density error, a fixed rate kappa / kappa_dt, so "
     "the source and its pressure do not jump when the step changes (as kappa rho / dt^2 "
     "does); a longer step corrects kappa, as printed. 0 (default): always as printed; "
     "5e-4 halves the dam break's flicker but the 3 mm plate's water expands over the walls "
     "(docs/pressure.md)"},
    {"fluid.kappa_step_decay", MPS_KEY_DOUBLE, "0.95", 0, 1, MPS_KEY_HI_OPEN, NULL, "",
     "the step that scales Eq. 23's correction (kappa rho / (dt dtk)) falls by at most this "
     "factor per step: after the CFL step drops at an impact the correction strengthens "
     "over several steps instead of quadrupling its pressure at once (dtk = max(dt, "
     "decay x the previous step's dtk)); 0: dtk = dt, as printed; 0.95 (default): about "
     "14 steps to follow a halved step (the default since 2026-12-04, docs/pressure.md)"},
    {"fluid.kappa_step_decay_expansion", MPS_KEY_DOUBLE, "0.99", 0, 1, MPS_KEY_HI_OPEN, NULL, "",
     "the same decay for the rows whose particle number density is below n0 (expanded "
     "water, where Eq. 23 pulls the pressure down): their reference step falls by at most "
     "this factor per step and never below the compression rows' (fluid.kappa_step_decay). "
     "A CFL step that falls 3.5 times in 5 ms otherwise lets Eq. 23's tension in expanded "
     "deep water grow as 1/(dt dtk) until the clamp sets most of the pool to P = 0 for a "
     "step; 0: the compression rows' step, as before 2026-12-06; 0.99 (default): about 70 "
     "steps to follow a halved step (docs/pressure.md, \"Expanded water follows the step "
     "more slowly\")"},
    {"fluid.density_dead_band", MPS_KEY_DOUBLE, "0.0005", 0, 0.05, 0, NULL, "n0",
     "Eq. 23's density error is corrected only beyond this fraction of n0, by its excess "
     "(a soft threshold): an error below it is the lattice's own noise, and correcting it "
     "at the paper's rate pumps still water into motion after 2-3 s (1 ms steps) or within "
     "a second (0.2 ms); the water's area may drift by up to about 0.7 of the band "
     "(docs/pressure.md, \"Still water, 10 s\"). 0: Eq. 23 as printed"},
    {"fluid.ppe_source", MPS_KEY_ENUM, "mixed", 0, 0, 0, "density|mixed", "",
     "PPE source: density deviation only (Eq. 23), or mixed with the divergence of the "
     "predicted velocity (Tanaka & Masunaga 2010), see docs/fluid.md"},
    {"fluid.divergence_stencil", MPS_KEY_ENUM, "near_bodies", 0, 0, 0,
     "gradient|laplacian|near_bodies", "",
     "neighbours of Eq. 10's divergence in the mixed source: the gradient's (re_n, the "
     "paper's radius for Eq. 10), the Laplacian's (re_lap, the stencil the PPE projects "
     "with: it measures about half as much of the divergence the projection leaves, and "
     "most of the pressure flicker goes; use it with fluid.density_weight = quadratic, "
     "docs/pressure.md, \"The divergence on the Laplacian's stencil\"), or the Laplacian's "
     "in the rows that reach a solid body within re_lap and the gradient's elsewhere "
     "(near_bodies: the plate's force as smooth as with the Laplacian's everywhere, still "
     "water and runs without bodies as with the gradient's; docs/pressure.md, \"The "
     "divergence near bodies\")"},
    {"fluid.divergence_walls", MPS_KEY_ENUM, "slip", 0, 0, 0, "slip|fixed", "",
     "the tank's wall and dummy particles in Eq. 10 of the mixed source (re_n): at their "
     "velocity (fixed) or slipping, only the approach normal to the wall counted (slip: a "
     "flow along a wall otherwise reads as a divergence that follows the wall's lattice, "
     "docs/pressure.md, \"Walls that slip in Eq. 10\")"},
    {"fluid.divergence_floor", MPS_KEY_DOUBLE, "0.5", 0, 1, MPS_KEY_HI_OPEN, NULL, "dp",
     "a pair closer than this enters Eq. 10 of the mixed source as at this distance, in "
     "the direction and at the speed it has: Eq. 7's weight grows without bound as a pair "
     "closes, and a pair a long step had brought to 0.32 dp asked for 290 kPa and threw a "
     "particle out at 27 m/s (docs/pressure.md, \"Pairs closer than half a spacing\"). "
     "0: Eq. 10 as printed"},
    {"fluid.gradient_floor", MPS_KEY_DOUBLE, "0.5", 0, 1, MPS_KEY_HI_OPEN, NULL, "dp",
     "a pair closer than this enters the pressure gradient (Eq. 9, and Eq. 14-15's "
     "matrix) as at this distance, in its own direction: Eq. 7's weight grows without "
     "bound as a pair closes, and a water particle 0.018 dp from a plate's surface "
     "particle left at 10 m/s in one step (docs/hard_cases.md, section 4). 0: Eq. 9 as "
     "printed"},
    {"fluid.initial_pressure", MPS_KEY_ENUM, "hydrostatic", 0, 0, 0, "hydrostatic|zero", "",
     "pressure at t = 0: hydrostatic below the top of the water above each particle, or zero"},
    {"fluid.density_weight", MPS_KEY_ENUM, "mps", 0, 0, 0, "mps|quadratic", "",
     "weight of the number density in Eq. 23's density error: Eq. 7's (mps, the paper's) or "
     "(1 - r/re)^2 with the particle itself (quadratic), which disorder raises a third as "
     "much, so that still water neither pairs up nor expands (docs/pressure.md); the free "
     "surface check keeps Eq. 7's"},
    /* 1e-3 1/Pa is a sound speed of 1 m/s in water, slower than the flows
     * here: past it the compressibility is the flow, not a correction to it
     * (and 1e300 overflowed the PPE's diagonal) */
    {"fluid.alpha", MPS_KEY_DOUBLE, "1e-7", 0, 1e-3, 0, NULL, "1/Pa",
     "compressibility 1/(rho c^2) of the weakly compressible PPE (Eq. 21-23)"},
    /* 10 dp is far past the paper's 2.1 and 4.0, and a weight spanning a
     * whole thin body; 1e300 overflowed the weights' sums to NaN positions */
    {"fluid.re_n", MPS_KEY_DOUBLE, "2.1", 1, 10, MPS_KEY_LO_OPEN, NULL, "dp",
     "effective radius for number density and gradient"},
    {"fluid.re_lap", MPS_KEY_DOUBLE, "4.0", 1, 10, MPS_KEY_LO_OPEN, NULL, "dp",
     "effective radius for the Laplacian"},
    /* at least 0.5 (the paper: 0.97, 0.85): below it a particle missing half
     * its neighbours counts as inside, and with no free-surface row at all
     * (1e-300) the PPE failed as not positive definite */
    {"fluid.beta1", MPS_KEY_DOUBLE, "0.97", 0.5, 1, 0, NULL, "",
     "free surface if n < beta1 n0 ..."},
    {"fluid.beta2", MPS_KEY_DOUBLE, "0.85", 0.5, 1, 0, NULL, "",
     "... and neighbour count < beta2 N0"},
    {"fluid.surface_scan", MPS_KEY_DOUBLE, "1.15", 0, 1.4, 0, NULL, "dp",
     "a free-surface candidate stays one only if no neighbour lies within this distance "
     "of the point dp outside it (0: the paper's double check alone)"},
    {"fluid.surface_scan_density", MPS_KEY_DOUBLE, "0.9", 0, 1, 0, NULL, "n0",
     "candidates sparser than this fraction of n0 with no wall or solid particle within re_n "
     "(spray, aerated water) skip the scan and stay on the free surface at P = 0, as the "
     "paper's double check says; 0: every candidate is scanned (docs/pressure.md)"},
    {"fluid.gradient", MPS_KEY_ENUM, "corrected", 0, 0, 0, "corrected|plain", "",
     "pressure gradient: Eq. 14-15 (corrected) or Eq. 9 (plain)"},
    {"fluid.wall_bc", MPS_KEY_ENUM, "solid_ppe", 0, 0, 0, "solid_ppe|neumann|ppe", "",
     "wall pressure: Neumann tank walls (hydrostatic extrapolation from the fluid) and a "
     "coupled solid's surface in the PPE (solid_ppe), Neumann for the solid too (neumann), "
     "or the first wall layer and the solid surface in the PPE (ppe, the paper's 4.3); "
     "see docs/fluid.md"},
    {"fluid.solid_load", MPS_KEY_ENUM, "face", 0, 0, 0, "face|eq50", "",
     "load on a coupled solid's surface particle: its pressure times the face it stands "
     "for (dp), along the normal from the fluid (face), or the paper's Eq. 50-51 (eq50); "
     "see docs/pressure.md"},
    {"fluid.body_shadow", MPS_KEY_BOOL, "false", 0, 0, 0, NULL, "",
     "leave out of the PPE Laplacian and the pressure gradient the pairs whose line crosses "
     "a coupled solid (the water on the two faces of a plate thinner than re_lap); false: "
     "every pair, as in the paper. With it a light plate needs coupling.scheme: implicit "
     "(docs/pressure.md, \"Thin bodies\")"},
    {"fluid.surface_laplacian", MPS_KEY_ENUM, "closed", 0, 0, 0, "closed|truncated", "",
     "PPE Laplacian of the particles under the free surface (Neumann walls only): "
     "neighbours missing beyond the surface extrapolated to P = 0 there (closed), or left "
     "out as in the paper (truncated)"},
    {"fluid.gradient_min", MPS_KEY_BOOL, "false", 0, 0, 0, NULL, "",
     "subtract the neighbourhood minimum pressure (repulsive pair terms only)"},
    {"fluid.clamp_negative", MPS_KEY_BOOL, "true", 0, 0, 0, NULL, "",
     "set negative PPE pressures to zero"},
    {"fluid.tension_solves", MPS_KEY_INT, "8", 0, 50, 0, NULL, "",
     "water holds no tension: up to this many more PPE solves per step with the fluid rows "
     "under tension held at P = 0, released or taken back until the set settles (a "
     "complementarity problem: P >= 0, and where P = 0 the water may only expand); what is "
     "still negative after them is clamped. 8 (default) settles nearly every step; 0: "
     "clamp after the one solve, the paper's 4.3, faster where water splashes "
     "(docs/pressure.md, \"Water that holds no tension\"). Needs fluid.clamp_negative; "
     "with fluid.clamp_negative=false the default is 0"},
    {"fluid.tension_sweeps", MPS_KEY_INT, "10", 0, 100, 0, NULL, "",
     "where the rows under tension start (with fluid.tension_solves): this many projected "
     "Gauss-Seidel sweeps (P = max(0, ...)) over the rows within three neighbour rings of "
     "the first solve's negative ones, from its clamped pressure; the rows they leave at "
     "P = 0 are the first held set. The same answer, in fewer solves; 0: hold the first "
     "solve's negative rows (docs/pressure.md, \"Where the held rows start\")"},
    {"fluid.tension_start", MPS_KEY_ENUM, "last_step", 0, 0, 0, "last_step|first_solve", "",
     "where the rows under tension start (with fluid.tension_solves): the rows whose "
     "particles the last step held at P = 0, swept (fluid.tension_sweeps) from the last "
     "step's pressure, and solved with them held from the first solve (last_step); or a "
     "first solve with none held, whose negative rows start the sweeps (first_solve, the "
     "default before 2026-12-07). A step whose particles the last held none of starts as "
     "first_solve does. The same answer, in fewer solves (docs/fluid_speed.md)"},
    {"fluid.collision_distance", MPS_KEY_DOUBLE, "0.9", 0, 1, MPS_KEY_HI_OPEN, NULL, "dp",
     "fluid particles closer than this are pushed apart (0: off)"},
    {"fluid.collision_restitution", MPS_KEY_DOUBLE, "0.2", 0, 1, 0, NULL, "",
     "restitution of that collision"},
    {"fluid.side_walls.breadth", MPS_KEY_DOUBLE, "0", 0, 0, NOHI, NULL, "m",
     "the tank's breadth between its two side walls, for a 2D run of a narrow tank: the "
     "walls' oscillating (Stokes) boundary layers retard the flow by sqrt(2 nu omega) / "
     "breadth times its velocity in the tank (the in-phase part of their shear, averaged "
     "over the breadth; omega = 2 pi / fluid.side_walls.period). 0 (default): no side "
     "walls, the paper's 2D flow (docs/sloshing.md, \"Side walls\")"},
    {"fluid.side_walls.period", MPS_KEY_DOUBLE, "0", 0, 0, NOHI, NULL, "s",
     "the period of the oscillation the side walls' boundary layers are taken at; 0 "
     "(default): the tank's motion.period (a sinusoidal motion)"},
    {"fluid.side_walls.inertia", MPS_KEY_BOOL, "true", 0, 0, 0, NULL, "",
     "with fluid.side_walls.breadth: also the reactive half of the layers' shear, an "
     "inertia of delta / breadth (delta = sqrt(2 nu / omega)) on the flow and its pressure "
     "correction, which lowers the sloshing frequency by about the damping ratio; false: "
     "the drag alone"},
    {"fluid.jitter.amplitude", MPS_KEY_DOUBLE, "0", 0, 0.1, 0, NULL, "dp",
     "displace each fluid particle's starting position by a uniform random amount of at "
     "most this in x and in y: one realisation of an ensemble, for a flow whose details "
     "after an impact are chaotic (the peak of an impact pressure: docs/pressure.md, "
     "\"Impact pressure\"); 0 (default): the lattice"},
    {"fluid.jitter.seed", MPS_KEY_INT, "1", 0, 0, NOHI, NULL, "",
     "the realisation: the same seed gives the same positions, whatever the thread count"},
    {"fluid.shifting", MPS_KEY_DOUBLE, "2.0", 0, 0, NOHI, NULL, "",
     "particle shifting coefficient A of dr = -A dp |v| dt grad n / n0 (0: off)"},
    {"fluid.shifting_max", MPS_KEY_DOUBLE, "0.1", 0, 1, MPS_KEY_LO_OPEN, NULL, "dp",
     "largest shift per step"},
    {"fluid.shifting_weight", MPS_KEY_ENUM, "mps", 0, 0, 0, "mps|smooth", "",
     "the weight whose gradient the shifting follows: Eq. 3's (mps), singular at r = 0, or "
     "(1 - r/re)^2 (smooth), scaled to the same response on the lattice; see docs/pressure.md"},
    {"fluid.ppe_solver", MPS_KEY_ENUM, "auto", 0, 0, 0,
     "auto|pcg_jacobi|pcg_ic0|pcg_sic0|pcg_defl|cholmod|cholmod_reuse", "",
     "linear solver for the PPE"},
    {"fluid.ppe_rtol", MPS_KEY_DOUBLE, "1e-6", 0, 0.1, MPS_KEY_LO_OPEN, NULL, "",
     "relative residual of iterative PPE solves"},
    {"fluid.ppe_max_iter", MPS_KEY_INT, "2000", 1, 0, NOHI, NULL, "", "iteration cap"},
    {"fluid.ppe_drop", MPS_KEY_DOUBLE, "0.015", 0, 1, MPS_KEY_HI_OPEN, NULL, "",
     "pcg_sic0: couplings with a_ij^2 < drop^2 a_ii a_jj are left out of the incomplete "
     "Cholesky factor (added to the diagonal); 0 keeps all (docs/ppe_solvers.md)"},
    {"fluid.ppe_coarse_cell", MPS_KEY_DOUBLE, "4", 1, 100, 0, NULL, "dp",
     "pcg_defl: side of the square cells whose PPE rows form one aggregate of the coarse "
     "space (docs/ppe_solvers.md)"},
    {"fluid.step_log", MPS_KEY_BOOL, "false", 0, 0, 0, NULL, "",
     "write PREFIX_steps.csv: one row per step (dt, PPE iterations and rows, rows at P = 0, "
     "collision pairs, neighbour-list builds), for diagnosing a run"},
    /* not REQUIRED in the schema: a solid-only case has no tank; the fluid
     * checks for it in fluid_params_read */
    {"fluid.tank.width", MPS_KEY_DOUBLE, NULL, 0, 0, POS, NULL, "m",
     "inner width of the tank (left wall inner face at x = 0)"},
    {"fluid.tank.height", MPS_KEY_DOUBLE, NULL, 0, 0, POS, NULL, "m",
     "inner height of the side walls (floor at y = 0)"},
    {"fluid.tank.lid", MPS_KEY_BOOL, "false", 0, 0, 0, NULL, "", "close the tank at the top"},
    {"fluid.tank.wall_layers", MPS_KEY_INT, "3", 3, 8, 0, NULL, "",
     "wall layer + dummy layers (paper: 3)"},
    {"fluid.blocks.*.x0", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_NO_LO | NOHI | MPS_KEY_REQUIRED,
     NULL, "m", "water block left"},
    {"fluid.blocks.*.y0", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_NO_LO | NOHI | MPS_KEY_REQUIRED,
     NULL, "m", "water block bottom"},
    {"fluid.blocks.*.x1", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_NO_LO | NOHI | MPS_KEY_REQUIRED,
     NULL, "m", "water block right"},
    {"fluid.blocks.*.y1", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_NO_LO | NOHI | MPS_KEY_REQUIRED,
     NULL, "m", "water block top"},
    {"fluid.probes.*.name", MPS_KEY_STRING, NULL, 0, 0, MPS_KEY_REQUIRED, NULL, "",
     "column name in probes.csv"},
    {"fluid.probes.*.kind", MPS_KEY_ENUM, NULL, 0, 0, MPS_KEY_REQUIRED,
     "front|height|pressure|bottom_pressure|max_speed|escaped|wall_force|wall_moment|tank_angle",
     "", "what the probe measures (docs/sensors.md; tank_angle: docs/sloshing.md)"},
    {"fluid.probes.*.x", MPS_KEY_DOUBLE, "0", 0, 0, MPS_KEY_NO_LO | NOHI, NULL, "m",
     "probe x (height: column position; pressure: point)"},
    {"fluid.probes.*.y", MPS_KEY_DOUBLE, "0", 0, 0, MPS_KEY_NO_LO | NOHI, NULL, "m",
     "probe y (pressure: point; wall_moment: the point the moment is taken about)"},
    {"fluid.probes.*.diameter", MPS_KEY_DOUBLE, NULL, 0, 0, POS, NULL, "m",
     "pressure: diameter of the sensor's face, over which it averages like a transducer "
     "(default 4 dp, the smallest that averages a few particles; give it in metres for runs "
     "at several dp). On a wall it reads the fluid next to the face, not the wall particles "
     "(their pressure is an average over 3 dp whatever the sensor's size): docs/sensors.md"},
    {"fluid.probes.*.on", MPS_KEY_ENUM, "auto", 0, 0, 0, "auto|wall|solid|water", "",
     "pressure: a sensor on the tank wall face through (x, y), on a solid's surface (the "
     "surface particle nearest (x, y) at the first reading, followed as the body moves), or "
     "a point in the water; auto: wall if (x, y) is within dp/2 of a wall face, else solid if "
     "a solid surface particle is within dp, else water"},
    {"fluid.probes.*.wall", MPS_KEY_ENUM, NULL, 0, 0, 0, "left|right|floor|lid", "",
     "wall_force, wall_moment: the tank wall (inner faces x = 0, x = width, y = 0, y = height)"},
    {NULL, 0, NULL, 0, 0, 0, NULL, NULL, NULL},
};

static enum fluid_probe_kind probe_kind(const char *s)
{
    static const char *const names[] = {"front",      "height",      "pressure",
                                        "bottom_pressure", "max_speed", "escaped",
                                        "wall_force", "wall_moment", "tank_angle"};
    for (int k = 0; k < 9; k++)
        if (strcmp(s, names[k]) == 0)
            return (enum fluid_probe_kind)k;
    return FLUID_PROBE_FRONT; /* unreachable: mps_case validated the enum */
}

const char *const fluid_wall_names[FLUID_NWALLS] = {"left", "right", "floor", "lid"};

static enum fluid_wall wall_index(const char *s)
{
    for (int w = 0; w < FLUID_NWALLS; w++)
        if (strcmp(s, fluid_wall_names[w]) == 0)
            return (enum fluid_wall)w;
    return FLUID_WALL_LEFT; /* unreachable: mps_case validated the enum */
}

/* A pressure sensor on a wall: the wall whose face passes within dp/2 of
 * (x, y) (the nearest if two do, at a corner), or -1. */
static int wall_at(const struct fluid_params *p, double x, double y)
{
    const double d[FLUID_NWALLS] = {fabs(x), fabs(x - p->tank_w), fabs(y),
                                    p->tank_lid ? fabs(y - p->tank_h) : INFINITY};
    int best = -1;
    for (int w = 0; w < FLUID_NWALLS; w++)
        if (d[w] <= 0.5 * p->dp && (best < 0 || d[w] < d[best]))
            best = w;
    return best;
}

/* The per-kind keys of probe k: a sensor's diameter, placement and wall, a
 * wall load's wall. Errors name the key. */
static enum mps_status read_probe_keys(struct fluid_params *p, const struct mps_case *c, int k,
                                       struct mps_err *err)
{
    struct fluid_probe_def *d = &p->probes[k];
    char key[64];
    const int pressure = d->kind == FLUID_PROBE_PRESSURE;
    const int wall_load = d->kind == FLUID_PROBE_WALL_FORCE || d->kind == FLUID_PROBE_WALL_MOMENT;
    const int has_d = mps_case_has(c, "fluid.probes.%d.diameter", k);
    const int has_wall = mps_case_has(c, "fluid.probes.%d.wall", k);
    if ((has_d && !pressure) || (has_wall && !wall_load)) {
        snprintf(key, sizeof key, "fluid.probes.%d.%s", k, has_d && !pressure ? "diameter" : "wall");
        return mps_case_fail(c, err, key, "not a key of a %s probe (%s)",
                             mps_case_string(c, "fluid.probes.%d.kind", k),
                             has_d && !pressure ? "diameter is for kind pressure"
                                                : "wall is for wall_force and wall_moment");
    }
    if (wall_load) {
        snprintf(key, sizeof key, "fluid.probes.%d.kind", k);
        if (!has_wall)
            return mps_case_fail(c, err, key, "%s needs fluid.probes.%d.wall "
                                 "(left|right|floor|lid)",
                                 mps_case_string(c, "%s", key), k);
        d->wall = wall_index(mps_case_string(c, "fluid.probes.%d.wall", k));
        snprintf(key, sizeof key, "fluid.probes.%d.wall", k);
        if (d->wall == FLUID_WALL_LID && !p->tank_lid)
            return mps_case_fail(c, err, key, "the tank has no lid (fluid.tank.lid: false)");
        return MPS_OK;
    }
    if (!pressure)
        return MPS_OK;
    d->diameter = has_d ? mps_case_double(c, "fluid.probes.%d.diameter", k) : 4.0 * p->dp;
    const char *on = mps_case_string(c, "fluid.probes.%d.on", k);
    d->on = strcmp(on, "wall") == 0    ? FLUID_ON_WALL
            : strcmp(on, "solid") == 0 ? FLUID_ON_SOLID
            : strcmp(on, "water") == 0 ? FLUID_ON_WATER
                                       : FLUID_ON_AUTO;
    const double tol = 0.5 * p->dp, top = p->tank_lid ? p->tank_h + tol : INFINITY;
    if (d->x < -tol || d->x > p->tank_w + tol || d->y < -tol || d->y > top) {
        snprintf(key, sizeof key, "fluid.probes.%d.%s", k,
                 d->x < -tol || d->x > p->tank_w + tol ? "x" : "y");
        return mps_case_fail(c, err, key, "the sensor (%g, %g) lies outside the tank [0, %g] x "
                             "[0, %g]", d->x, d->y, p->tank_w, p->tank_h);
    }
    int w = wall_at(p, d->x, d->y);
    snprintf(key, sizeof key, "fluid.probes.%d.on", k);
    if (d->on == FLUID_ON_WALL && w < 0)
        return mps_case_fail(c, err, key, "the point (%g, %g) is on no tank wall face (x = 0, "
                             "x = %g, y = 0%s, within dp/2)", d->x, d->y, p->tank_w,
                             p->tank_lid ? ", y = height" : "");
    if (d->on == FLUID_ON_AUTO && w >= 0)
        d->on = FLUID_ON_WALL;
    if (d->on != FLUID_ON_WALL)
        return MPS_OK;
    d->wall = (enum fluid_wall)w;
    /* the face must hold the whole sensor: a transducer ends at the corner */
    const int side = w == FLUID_WALL_LEFT || w == FLUID_WALL_RIGHT;
    const double s = side ? d->y : d->x, len = side ? p->tank_h : p->tank_w;
    const double r = 0.5 * d->diameter;
    if (s - r < -1e-9 * len || s + r > len * (1.0 + 1e-9)) {
        snprintf(key, sizeof key, "fluid.probes.%d.diameter", k);
        return mps_case_fail(c, err, key, "the sensor's face [%g, %g] (%s = %g +- %g m) runs past "
                             "the end of the %s wall [0, %g]: move it or make it smaller%s",
                             s - r, s + r, side ? "y" : "x", s, r, fluid_wall_names[w], len,
                             has_d ? "" : " (the default diameter is 4 dp)");
    }
    return MPS_OK;
}

enum mps_status fluid_params_read(struct fluid_params *p, const struct mps_case *c,
                                  struct mps_err *err)
{
    memset(p, 0, sizeof *p);
    p->dp = mps_case_double(c, "dp");
    p->end_time = mps_case_double(c, "end_time");
    p->g[0] = mps_case_double(c, "gravity.x");
    p->g[1] = mps_case_double(c, "gravity.y");
    p->rho = mps_case_double(c, "fluid.rho");
    p->nu = mps_case_double(c, "fluid.nu");
    p->courant = mps_case_double(c, "fluid.courant");
    p->droplet_neighbours = (int)mps_case_int(c, "fluid.droplet_neighbours");
    p->dt_max = mps_case_double(c, "fluid.dt_max");
    p->dt_min = mps_case_double(c, "fluid.dt_min");
    p->kappa = mps_case_double(c, "fluid.kappa");
    p->kappa_dt = mps_case_double(c, "fluid.kappa_dt");
    p->kappa_step_decay = mps_case_double(c, "fluid.kappa_step_decay");
    p->kappa_step_decay_expansion = mps_case_double(c, "fluid.kappa_step_decay_expansion");
    p->density_dead_band = mps_case_double(c, "fluid.density_dead_band");
    p->density_quadratic = strcmp(mps_case_string(c, "fluid.density_weight"), "quadratic") == 0;
    p->alpha = mps_case_double(c, "fluid.alpha");
    p->mixed_source = strcmp(mps_case_string(c, "fluid.ppe_source"), "mixed") == 0;
    p->divergence_wide = strcmp(mps_case_string(c, "fluid.divergence_stencil"), "laplacian") == 0;
    p->divergence_near_bodies =
        strcmp(mps_case_string(c, "fluid.divergence_stencil"), "near_bodies") == 0;
    p->divergence_slip = strcmp(mps_case_string(c, "fluid.divergence_walls"), "slip") == 0;
    p->divergence_floor = mps_case_double(c, "fluid.divergence_floor");
    p->gradient_floor = mps_case_double(c, "fluid.gradient_floor");
    p->initial_hydrostatic =
        strcmp(mps_case_string(c, "fluid.initial_pressure"), "hydrostatic") == 0;
    p->re_n = mps_case_double(c, "fluid.re_n");
    p->re_lap = mps_case_double(c, "fluid.re_lap");
    p->beta1 = mps_case_double(c, "fluid.beta1");
    p->beta2 = mps_case_double(c, "fluid.beta2");
    p->surface_scan = mps_case_double(c, "fluid.surface_scan");
    p->surface_scan_density = mps_case_double(c, "fluid.surface_scan_density");
    p->gradient = strcmp(mps_case_string(c, "fluid.gradient"), "plain") == 0
                      ? FLUID_GRAD_PLAIN
                      : FLUID_GRAD_CORRECTED;
    const char *wbc = mps_case_string(c, "fluid.wall_bc");
    p->wall_bc = strcmp(wbc, "ppe") == 0         ? FLUID_WALL_PPE
                 : strcmp(wbc, "solid_ppe") == 0 ? FLUID_WALL_SOLID_PPE
                                                 : FLUID_WALL_NEUMANN;
    p->solid_load = strcmp(mps_case_string(c, "fluid.solid_load"), "eq50") == 0
                        ? FLUID_LOAD_EQ50
                        : FLUID_LOAD_FACE;
    p->body_shadow = mps_case_bool(c, "fluid.body_shadow");
    p->surface_closure = strcmp(mps_case_string(c, "fluid.surface_laplacian"), "closed") == 0 &&
                         p->wall_bc != FLUID_WALL_PPE;
    p->gradient_min = mps_case_bool(c, "fluid.gradient_min");
    p->clamp_negative = mps_case_bool(c, "fluid.clamp_negative");
    p->tension_solves = (int)mps_case_int(c, "fluid.tension_solves");
    /* without the clamp the default's re-solves have nothing to replace */
    if (!p->clamp_negative && strcmp(mps_case_where(c, "fluid.tension_solves"), "default") == 0)
        p->tension_solves = 0;
    if (!p->clamp_negative && p->tension_solves > 0)
        return mps_err_set(err, MPS_EINPUT,
                           "%s: fluid.tension_solves: %d more solves release the rows the clamp "
                           "would set to zero, but fluid.clamp_negative is false: set one of "
                           "them to 0/true",
                           mps_case_origin(c), p->tension_solves);
    p->tension_sweeps = (int)mps_case_int(c, "fluid.tension_sweeps");
    p->tension_start_last = strcmp(mps_case_string(c, "fluid.tension_start"), "last_step") == 0;
    p->collision_dist = mps_case_double(c, "fluid.collision_distance");
    p->collision_restitution = mps_case_double(c, "fluid.collision_restitution");
    p->side_wall_breadth = mps_case_double(c, "fluid.side_walls.breadth");
    p->side_wall_period = mps_case_double(c, "fluid.side_walls.period");
    p->side_wall_inertia = mps_case_bool(c, "fluid.side_walls.inertia");
    /* the Stokes layer's frequency: a sinusoidal roll gives it (its
     * period, eq55 included, is resolved with the motion: fluid_create) */
    if (p->side_wall_breadth > 0.0 && !(p->side_wall_period > 0.0) &&
        strcmp(mps_case_string(c, "motion.kind"), "sinusoid") != 0)
        return mps_case_fail(c, err, "fluid.side_walls.breadth",
                             "needs fluid.side_walls.period (s) when the tank does not roll "
                             "sinusoidally (motion.kind = %s): the side walls' boundary layers "
                             "are taken at one period of oscillation",
                             mps_case_string(c, "motion.kind"));
    if (p->side_wall_breadth > 0.0 && !(p->nu > 0.0))
        return mps_case_fail(c, err, "fluid.side_walls.breadth",
                             "needs a viscous fluid (fluid.nu > 0): the side walls' drag is "
                             "viscous");
    p->shift_coef = mps_case_double(c, "fluid.shifting");
    p->shift_max = mps_case_double(c, "fluid.shifting_max");
    p->shift_smooth = strcmp(mps_case_string(c, "fluid.shifting_weight"), "smooth") == 0;
    p->jitter = mps_case_double(c, "fluid.jitter.amplitude");
    p->jitter_seed = (unsigned long)mps_case_int(c, "fluid.jitter.seed");
    p->ppe_solver = mps_case_string(c, "fluid.ppe_solver");
    p->step_log = mps_case_bool(c, "fluid.step_log");
    p->ppe_rtol = mps_case_double(c, "fluid.ppe_rtol");
    p->ppe_max_iter = (int)mps_case_int(c, "fluid.ppe_max_iter");
    p->ppe_drop = mps_case_double(c, "fluid.ppe_drop");
    p->ppe_coarse_cell = mps_case_double(c, "fluid.ppe_coarse_cell");
    if (!mps_case_has(c, "fluid.tank.width") || !mps_case_has(c, "fluid.tank.height"))
        return mps_err_set(err, MPS_EINPUT, "%s: missing required key '%s' (the fluid needs a tank)",
                           mps_case_origin(c),
                           mps_case_has(c, "fluid.tank.width") ? "fluid.tank.height"
                                                                 : "fluid.tank.width");
    p->tank_w = mps_case_double(c, "fluid.tank.width");
    p->tank_h = mps_case_double(c, "fluid.tank.height");
    p->tank_lid = mps_case_bool(c, "fluid.tank.lid");
    p->wall_layers = (int)mps_case_int(c, "fluid.tank.wall_layers");
    p->output_interval = mps_case_double(c, "output.interval");
    p->probe_interval = mps_case_double(c, "output.probe_interval");
    p->checkpoint_interval = mps_case_double(c, "output.checkpoint_interval");

    if (p->re_lap < p->re_n)
        return mps_case_fail(c, err, "fluid.re_lap", "must be >= fluid.re_n = %g", p->re_n);
    if (p->dt_max < p->dt_min)
        return mps_case_fail(c, err, "fluid.dt_max", "must be >= fluid.dt_min = %g", p->dt_min);
    if (p->tank_w < 4 * p->dp || p->tank_h < 4 * p->dp)
        return mps_case_fail(c, err, "dp", "too coarse for a tank of %g x %g m", p->tank_w,
                             p->tank_h);

    p->nblocks = mps_case_count(c, "fluid.blocks");
    if (p->nblocks > FLUID_MAX_BLOCKS)
        return mps_case_fail(c, err, "fluid.blocks", "%d blocks: at most %d", p->nblocks,
                             FLUID_MAX_BLOCKS);
    double top = 0.0;
    for (int b = 0; b < p->nblocks; b++) {
        static const char *const names[4] = {"x0", "y0", "x1", "y1"};
        char key[64];
        snprintf(key, sizeof key, "fluid.blocks.%d.x0", b);
        if (!mps_case_has(c, "%s", key)) /* an item given by --set past the end */
            return mps_err_set(err, MPS_EINPUT, "%s: fluid.blocks.%d: missing (a gap in the "
                               "list of blocks)", mps_case_origin(c), b);
        for (int k = 0; k < 4; k++)
            p->block[b][k] = mps_case_double(c, "fluid.blocks.%d.%s", b, names[k]);
        snprintf(key, sizeof key, "fluid.blocks.%d.x1", b);
        if (p->block[b][2] <= p->block[b][0])
            return mps_case_fail(c, err, key, "must be > x0 = %g", p->block[b][0]);
        snprintf(key, sizeof key, "fluid.blocks.%d.y1", b);
        if (p->block[b][3] <= p->block[b][1])
            return mps_case_fail(c, err, key, "must be > y0 = %g", p->block[b][1]);
        /* The block must lie inside the tank (a tolerance of dp/1000 absorbs
         * decimal round-off in the case file). */
        const double tol = 1e-3 * p->dp, lim[4] = {0.0, 0.0, p->tank_w, p->tank_h};
        for (int k = 0; k < 4; k++) {
            int outside = k < 2 ? p->block[b][k] < lim[k] - tol : p->block[b][k] > lim[k] + tol;
            if (k == 3 && !p->tank_lid)
                outside = 0; /* an open tank may hold water above its walls */
            if (outside) {
                snprintf(key, sizeof key, "fluid.blocks.%d.%s", b, names[k]);
                return mps_case_fail(c, err, key,
                                     "the water block lies outside the tank [0, %g] x [0, %g]",
                                     p->tank_w, p->tank_h);
            }
        }
        if (p->block[b][3] > top)
            top = p->block[b][3];
        /* overlapping blocks would put two particles on one lattice site */
        const double *q = p->block[b];
        for (int a = 0; a < b; a++) {
            const double *o = p->block[a];
            if (fmin(q[2], o[2]) - fmax(q[0], o[0]) > tol &&
                fmin(q[3], o[3]) - fmax(q[1], o[1]) > tol) {
                snprintf(key, sizeof key, "fluid.blocks.%d.x0", b);
                return mps_case_fail(c, err, key,
                                     "the water block overlaps fluid.blocks.%d ([%g, %g] x "
                                     "[%g, %g]): split them so each place holds water once",
                                     a, o[0], o[2], o[1], o[3]);
            }
        }
    }

    /* Before anything is allocated: water blocks and wall layers round the
     * tank (an upper bound: blocks may overlap). */
    double water = 0.0;
    for (int b = 0; b < p->nblocks; b++)
        water += (p->block[b][2] - p->block[b][0]) * (p->block[b][3] - p->block[b][1]);
    double nparticles = water / (p->dp * p->dp) +
                        (p->wall_layers + 1.0) * 2.0 * (p->tank_w + p->tank_h) / p->dp;
    enum mps_status st = mps_budget_check(c, "dp", "fluid", nparticles, MPS_BUDGET_FLUID_BYTES, err);
    if (st)
        return st;

    /* The CFL cap must be satisfiable: a column of height H reaches about
     * sqrt(2 g H) on collapse, so the CFL step is C dp / sqrt(2 g H). */
    double gmag = sqrt(p->g[0] * p->g[0] + p->g[1] * p->g[1]);
    double vexp = sqrt(2.0 * gmag * top);
    if (vexp > 0.0 && p->courant * p->dp / vexp < p->dt_min)
        return mps_case_fail(c, err, "fluid.dt_min",
                             "the CFL condition (Eq. 52) needs dt <= C dp / v = %.3g s for the "
                             "expected speed sqrt(2 g H) = %.3g m/s, below dt_min",
                             p->courant * p->dp / vexp, vexp);
    /* So must the viscous limit, which fluid_cfl_dt applies at every step:
     * otherwise the first step fails with a message about speeds. */
    if (fluid_viscous_dt(p) < p->dt_min)
        return mps_case_fail(c, err, "fluid.nu",
                             "the explicit viscosity (Eq. 16) needs dt <= 0.2 dp^2 / nu = %.3g s, "
                             "below fluid.dt_min = %.3g s",
                             fluid_viscous_dt(p), p->dt_min);
    /* a step cut to land on one of these times would be shorter than
     * dt_min, which the fluid takes for a flow too fast for Eq. 52 */
    const char *const times[] = {"end_time", "output.interval", "output.probe_interval"};
    const double tv[] = {p->end_time, p->output_interval, p->probe_interval};
    for (int k = 0; k < 3; k++)
        if (tv[k] > 0.0 && tv[k] < p->dt_min)
            return mps_case_fail(c, err, times[k],
                                 "shorter than fluid.dt_min = %g s, the shortest step the fluid "
                                 "takes",
                                 p->dt_min);

    p->nprobes = mps_case_count(c, "fluid.probes");
    if (p->nprobes > FLUID_MAX_PROBES)
        return mps_case_fail(c, err, "fluid.probes", "%d probes: at most %d", p->nprobes,
                             FLUID_MAX_PROBES);
    for (int k = 0; k < p->nprobes; k++) {
        if (!mps_case_has(c, "fluid.probes.%d.name", k))
            return mps_err_set(err, MPS_EINPUT, "%s: fluid.probes.%d: missing (a gap in the "
                               "list of probes)", mps_case_origin(c), k);
        p->probes[k].name = mps_case_string(c, "fluid.probes.%d.name", k);
        p->probes[k].kind = probe_kind(mps_case_string(c, "fluid.probes.%d.kind", k));
        p->probes[k].x = mps_case_double(c, "fluid.probes.%d.x", k);
        p->probes[k].y = mps_case_double(c, "fluid.probes.%d.y", k);
        if ((st = read_probe_keys(p, c, k, err)))
            return st;
    }
    return MPS_OK;
}

double fluid_viscous_dt(const struct fluid_params *p)
{
    return p->nu > 0.0 ? 0.2 * p->dp * p->dp / p->nu : INFINITY;
}
