/* Initial particle layout: the tank (a wall layer and dummy layers on the
 * left, right and bottom, optionally a lid) and the water blocks, on square
 * lattices of spacing dp with centres dp/2 from every face. */
#ifndef FLUID_SCENE_H
#define FLUID_SCENE_H

#include <stddef.h>

#include "fluid_params.h"
#include "mps_dim.h"

struct fluid_scene_pt {
    double x[MPS_DIM];
    int type;   /* enum fluid_ptype */
};

/* Fills *pts (malloc'd, caller frees) with the fluid particles first, then the
 * walls; returns the count of each through nfluid and nwall. Returns -1 on
 * allocation failure. */
int fluid_scene_build(const struct fluid_params *p, struct fluid_scene_pt **pts, size_t *nfluid,
                      size_t *nwall);

#endif
