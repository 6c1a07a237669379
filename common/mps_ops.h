/* MPS differential operators (Eq. 8-15) over a neighbour list.
 * Distances are recomputed from x (the list may have been built at slightly
 * different positions, with a skin), and pairs beyond re are skipped.
 * `use` masks which particles take part as neighbours j (NULL: all); results
 * are computed for the particles i < nquery with query[i] != 0 (NULL: all)
 * and left untouched for the others. All loops are OpenMP-parallel over i. */
#ifndef MPS_OPS_H
#define MPS_OPS_H

#include <stddef.h>

#include "mps_dim.h"
#include "mps_nbr.h"

struct mps_ops_in {
    const struct mps_nbr_list *nl;   /* neighbours of i < nl->n */
    const double (*x)[MPS_DIM];
    double re;                       /* effective radius of this operator, m */
    const unsigned char *use;        /* neighbour mask, or NULL */
    const unsigned char *query;      /* evaluation mask, or NULL */
    const unsigned char *pair_use;   /* per entry of nl: 0 leaves the pair out (the
                                      * gradients only), or NULL */
};

/* Eq. 8: n_i = sum_j w(r_ij); count_i = number of j within re (count may be NULL). */
void mps_ops_number_density(const struct mps_ops_in *in, double *n, int *count);
/* mps_ops_number_density, and in the same pass nq_i: the sum of
 * mps_weight_quadratic over the neighbours and the particle itself
 * (fluid.density_weight = quadratic). */
void mps_ops_number_density_quadratic(const struct mps_ops_in *in, double *n, int *count,
                                      double *nq);

/* Eq. 12 for a vector field: lap_i = 2d/(lambda n0) sum_j (f_j - f_i) w(r_ij). */
void mps_ops_laplacian_vec(const struct mps_ops_in *in, double n0, double lambda,
                           const double (*f)[MPS_DIM], double (*lap)[MPS_DIM]);

/* Eq. 12 for a scalar field. */
void mps_ops_laplacian(const struct mps_ops_in *in, double n0, double lambda, const double *f,
                       double *lap);

/* Eq. 9: grad_i = d/n0 sum_j (f_j - fref_i) r_ij / |r_ij|^2 w(r_ij), with
 * fref_i = f_i, or with use_min the minimum of f over i and its neighbours
 * (Koshizuka's stabilised form: only repulsive pair terms). A pair closer
 * than r_floor (m; 0: none) is read at r_floor in its own direction
 * (mps_divergence_floor_factor), in both gradients: the pairs outside keep
 * their arithmetic to the bit. */
void mps_ops_gradient(const struct mps_ops_in *in, double n0, const double *f, int use_min,
                      double r_floor, double (*grad)[MPS_DIM]);

/* Eq. 14-15: the gradient with the correction matrix A_i, exact for linear f
 * wherever the neighbourhood spans every direction. Where A_i is singular or
 * ill-conditioned (det of A_i^-1 below cond_floor times its full-lattice value,
 * typically at a free surface), falls back to Eq. 9 for that particle and
 * sets fallback[i] = 1 (fallback may be NULL). */
void mps_ops_gradient_corrected(const struct mps_ops_in *in, double n0, const double *f,
                                int use_min, double cond_floor, double r_floor,
                                double (*grad)[MPS_DIM], unsigned char *fallback);

/* Eq. 10: div_i = d/n0 sum_j (f_j - f_i).r_ij / |r_ij|^2 w(r_ij), a pair
 * closer than r_floor (m; 0: none) read at r_floor
 * (mps_divergence_floor_factor). */
void mps_ops_divergence(const struct mps_ops_in *in, double n0, const double (*f)[MPS_DIM],
                        double r_floor, double *div);

#endif
