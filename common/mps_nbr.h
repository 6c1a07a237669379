/* O(N) neighbour search: a uniform cell list (counting sort of particles by
 * cell) and, from it, a compact neighbour list (CSR) of all pairs closer than
 * a radius. Cells are at least the radius wide, so a query visits the 3^d
 * surrounding cells. The list stores j and, unless told not to (no_r2),
 * |r_ij|^2 for users that need the distances at the positions of the build
 * (a solid's reference bonds); a fluid, whose particles move between builds,
 * recomputes them and keeps j only. */
#ifndef MPS_NBR_H
#define MPS_NBR_H

#include <stddef.h>

#include "mps_ckpt.h"
#include "mps_dim.h"
#include "mps_mem.h"
#include "mps_err.h"

struct mps_nbr_grid {
    double lo[MPS_DIM];   /* lower corner of the bounding box */
    double cell;          /* cell width (>= the search radius) */
    int dims[MPS_DIM];    /* cells per axis */
    size_t ncells;
    size_t *cell_start;   /* ncells + 1 offsets into sorted */
    size_t *sorted;       /* particle indices, grouped by cell */
    size_t *cell_of;      /* cell index of each particle */
    double (*xs)[MPS_DIM]; /* positions in the order of sorted[]: a query
                            * reads its candidates contiguously */
    size_t n, cap_n, cap_cells, cap_xs;
};

struct mps_nbr_list {
    size_t n;             /* particles */
    size_t *start;        /* n + 1 offsets */
    int *j;               /* neighbour index */
    double *r2;           /* squared distance (NULL with no_r2) */
    /* Set before the first build to keep j only: a list whose users
     * recompute distances at moved positions (a fluid's) then writes a
     * third of the bytes. */
    int no_r2;
    size_t cap_n, cap_pairs;
    double radius;
    /* per-thread buffers of the build, kept so a rebuild allocates nothing */
    struct mps_nbr_scratch *scratch;
    int nscratch;
};

/* Rows ahead that loops walking a list in row order ask the cache for. */
#define MPS_NBR_PREFETCH_ROWS 4

/* Asks the cache for the neighbour indices of row i of l (if i < l->n).
 * Loops that walk the rows in order call it MPS_NBR_PREFETCH_ROWS ahead (the
 * viscous Laplacian at 80k particles waited on its list for 44% of its
 * samples; with it, 5.9 to 4.0 ms per step). */
static inline void mps_nbr_prefetch_row(const struct mps_nbr_list *l, size_t i)
{
    if (i < l->n)
        mps_prefetch_span(l->j + l->start[i], (l->start[i + 1] - l->start[i]) * sizeof *l->j);
}

/* Bins n particles into cells of width cell. Positions must be finite: a NaN
 * or infinite coordinate is reported as MPS_EDIVERGED naming the particle. */
enum mps_status mps_nbr_grid_build(struct mps_nbr_grid *g, size_t n, const double (*x)[MPS_DIM],
                                   double cell, struct mps_err *err);
void mps_nbr_grid_free(struct mps_nbr_grid *g);

/* All j != i with |x_i - x_j| < radius (radius <= grid cell), for the first
 * nquery particles (queries over all n particles of the grid). The list of
 * each i is sorted by j (deterministic, cache-friendly). OpenMP-parallel. */
enum mps_status mps_nbr_list_build(struct mps_nbr_list *l, const struct mps_nbr_grid *g,
                                   const double (*x)[MPS_DIM], size_t nquery, double radius,
                                   struct mps_err *err);
/* As mps_nbr_list_build, but only particles with query[i] set (all if query
 * is NULL) get their neighbours; the others get an empty row. A fluid keeps
 * the fixed tank out of the queries: its walls need far fewer pairs than a
 * full search around each wall particle would give (mps_nbr_list_reverse). */
enum mps_status mps_nbr_list_build_masked(struct mps_nbr_list *l, const struct mps_nbr_grid *g,
                                          const double (*x)[MPS_DIM], size_t nquery,
                                          const unsigned char *query, double radius,
                                          struct mps_err *err);
/* The transpose of part of src: row j of dst (to_lo <= j < to_hi) lists the
 * i in [from_lo, from_hi) whose row of src holds j, sorted by i, with src's
 * r2 (unless dst->no_r2; a src without r2 needs a dst without); all other
 * rows of dst are empty. dst has src->n rows. */
enum mps_status mps_nbr_list_reverse(struct mps_nbr_list *dst, const struct mps_nbr_list *src,
                                     size_t from_lo, size_t from_hi, size_t to_lo, size_t to_hi,
                                     struct mps_err *err);
void mps_nbr_list_free(struct mps_nbr_list *l);

/* dst becomes a copy of src's rows (start, j, and r2 if src keeps it): a
 * solver's checkpoint of a list it would otherwise rebuild differently. */
enum mps_status mps_nbr_list_copy(struct mps_nbr_list *dst, const struct mps_nbr_list *src,
                                  struct mps_err *err);

/* The list as blocks of a state image (mps_ckpt.h; name prefixes the block
 * names), and back into l (grown as needed): a solver's checkpoint of a list
 * it would otherwise rebuild differently. */
enum mps_status mps_nbr_list_put(const struct mps_nbr_list *l, const char *name,
                                 struct mps_ckpt *c, struct mps_err *err);
enum mps_status mps_nbr_list_get(struct mps_nbr_list *l, const char *name, struct mps_ckpt *c,
                                 struct mps_err *err);

/* The pairs of src that are closer than radius at positions x (which may have
 * moved since src was built: r2 is recomputed), kept in src's order. Used to
 * derive a short-radius list from a long-radius list with a skin. If src
 * keeps r2 it is overwritten with the squared distances at x (the second
 * pass reads them instead of gathering x[j] again). */
enum mps_status mps_nbr_list_filter(struct mps_nbr_list *dst, struct mps_nbr_list *src,
                                    const double (*x)[MPS_DIM], double radius,
                                    struct mps_err *err);

/* Numbers the first m particles of the grid in cell order: perm[k] (m
 * entries) = the old index of the particle numbered k, for
 * mps_particles_permute, and the grid is updated to the new numbers, as if
 * built after the renumbering. */
enum mps_status mps_nbr_grid_cell_order(struct mps_nbr_grid *g, size_t m, size_t *perm,
                                        struct mps_err *err);

#endif
