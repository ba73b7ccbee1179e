/* The error norms of seed 004 sec. 5.1 eq. 44-45 as the paper evaluates
 * them: the displacement field is the kernel interpolant of the particles'
 * displacements with the first-order corrected kernel (eq. 6-8, App. A.1-A.3),
 *   u_h(X) = sum_j V_j W~_j(X) u_j,  W~_j(X) = alpha (1 + beta . (X - X_j))
 *   W(X - X_j),
 * and grad u_h its exact gradient (App. A.4-A.6), both at Gauss points: the
 * box [lo, hi] cut into `tiles` tiles a side, `points` Gauss-Legendre points
 * a side in each tile (the paper: 10 x 10 tiles, 5 x 5 points), so
 *   ||u - u_h|| = (int |u - u_h|^2 dOmega)^(1/2)            (eq. 44)
 *   |u - u_h|   = (int |grad u - grad u_h|^2 dOmega)^(1/2)  (eq. 45),
 * absolute, as the paper defines them. The particle table and the cell bins
 * are allocated once (set-up); binning and the sums allocate nothing. */
#ifndef SPH_REFERENCE_GAUSS_H
#define SPH_REFERENCE_GAUSS_H

#include <stddef.h>

#include "core/kernel.h"
#include "sph/status.h"

/* a particle's row in the table: reference position, volume, displacement */
enum { SPH_GAUSS_X = 0, SPH_GAUSS_V = 3, SPH_GAUSS_U = 4, SPH_GAUSS_ROW = 7 };

typedef struct sph_gauss_norm sph_gauss_norm;

/* the exact displacement and its gradient G_ij = d u_i / d X_j at X */
typedef void sph_gauss_exact(const void *ctx, const double X[3], double u[3],
                             double G[9]);

/* n-point Gauss-Legendre nodes and weights on [-1, 1], n = 1 ... 5;
 * returns 0 for another n */
int sph_gauss_legendre(int n, double x[], double w[]);

/* A norm over the box [lo, hi] (the first k->dim coordinates) for n
 * particles of support k->support. */
sph_status sph_gauss_norm_create(sph_gauss_norm **out, const sph_kernel *k,
                                 const double lo[3], const double hi[3],
                                 int tiles, int points, size_t n,
                                 sph_error *err);
void sph_gauss_norm_destroy(sph_gauss_norm *g);

/* the particle table to fill (n rows of SPH_GAUSS_ROW), then bin */
double *sph_gauss_norm_table(sph_gauss_norm *g);
void sph_gauss_norm_bin(sph_gauss_norm *g);

/* u_h and grad u_h at X; SPH_ERR_RANGE where the kernel's moment matrix is
 * singular (too few particles in the support) */
sph_status sph_gauss_norm_interpolate(const sph_gauss_norm *g,
                                      const double X[3], double u[3],
                                      double G[9], sph_error *err);

/* e[0] = eq. 44, e[1] = eq. 45 against the exact field */
sph_status sph_gauss_norm_errors(const sph_gauss_norm *g,
                                 sph_gauss_exact *exact, const void *ctx,
                                 double e[2], sph_error *err);

#endif
