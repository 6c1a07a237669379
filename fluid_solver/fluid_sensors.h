/* Pressure sensors and tank-wall loads (docs/sensors.md), and their means in
 * time: probes of kind pressure, wall_force and wall_moment read like a
 * physical transducer, the mean over its face and over the steps since the
 * previous probe row (dt-weighted). The fluid adds every step's value
 * (fluid_sensors_accumulate, at the end of fluid_step), the program that
 * writes the row reads the means and restarts them: standalone at each probe
 * time, under the coupler when an ADVANCE asks for PROBES.
 *
 * Face pressure of a tank wall, at a point s along it: the fluid particles
 * next to the face (centre within 1.5 dp of it), each one's pressure carried
 * hydrostatically to the face point, P_i + rho g.(x_face(s) - x_i), weighted
 * by a hat of half-width dp along the wall and by its distance from the face
 * (full weight up to dp/2, none at 1.5 dp: the first row of fluid), divided
 * by max(sum of weights, 1/2): where fewer particles touch the face than half
 * a row (a dry wall, the edge of the water) the missing ones count as P = 0.
 * The Neumann wall particles' own pressure is not used: it is an average of
 * the fluid within re_n + dp (fluid_ppe_boundary_pressure), 3 dp either side,
 * which would make every sensor at least 6 dp wide. */
#ifndef FLUID_SENSORS_H
#define FLUID_SENSORS_H

#include "fluid_params.h"
#include "mps_err.h"
#include "mps_json.h"

struct fluid;
struct fluid_sensors;

/* State for the probes of p (none needed if no probe is averaged: *out NULL). */
enum mps_status fluid_sensors_create(struct fluid_sensors **out, const struct fluid_params *p,
                                     struct mps_err *err);
void fluid_sensors_destroy(struct fluid_sensors **s);

/* 1 for the kinds whose probes.csv value is a mean since the previous row. */
int fluid_probe_averaged(enum fluid_probe_kind kind);

/* After a step of dt: adds dt times the current value of each averaged probe. */
void fluid_sensors_accumulate(const struct fluid *f, double dt);

/* Averaged probe k: its mean since the last restart, or its value now when no
 * step was accumulated since (the row at t = 0). NaN for a sensor on a solid
 * when there is no solid. */
double fluid_sensors_value(const struct fluid *f, int k);

/* A probe row was written: the means start again. */
void fluid_sensors_restart(const struct fluid *f);

/* Where each pressure sensor sits, as resolved ("sensors" in summary.json). */
void fluid_sensors_summary(const struct fluid *f, struct mps_json *j);

#endif
