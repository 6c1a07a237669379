/* The interface cache shared by the solid models (solid_model_ops.interface):
 * the surface particles and the inner particles within `depth` of one, found
 * on the initial lattice x0, with their x and v refilled on every call. */
#ifndef SOLID_IFACE_H
#define SOLID_IFACE_H

#include <stddef.h>

#include "mps_dim.h"
#include "mps_err.h"
#include "solid_model.h"

struct solid_iface_cache {
    double depth;                   /* depth the cache was built for, < 0: none */
    size_t n;
    size_t *idx;                    /* particle indices */
    int *id;
    double (*x)[MPS_DIM], (*v)[MPS_DIM];
    unsigned char *surface, *fixed;
};

/* An empty cache (depth -1: the next build is due). */
void solid_iface_cache_init(struct solid_iface_cache *c);
/* Selects, among n particles, those with surface[i] and those within depth
 * (m) of one of them in x0; copies id and fixed. On failure the cache is left
 * empty (n 0, depth -1). */
enum mps_status solid_iface_cache_build(struct solid_iface_cache *c, size_t n,
                                        const double (*x0)[MPS_DIM],
                                        const unsigned char *surface, const int *id,
                                        const unsigned char *fixed, double depth,
                                        struct mps_err *err);
/* Copies the current x and v of the cached particles and points out at the
 * cache (valid until the next build or free). */
void solid_iface_cache_fill(struct solid_iface_cache *c, const double (*x)[MPS_DIM],
                            const double (*v)[MPS_DIM], struct solid_iface *out);
void solid_iface_cache_free(struct solid_iface_cache *c);

#endif
