/* Smoothing kernels: cubic B-spline, quintic spline, Wendland C2 and C4.
 *
 * W(r, h) = sigma_d / h^d * f(q), q = r / h, with the 1D/2D/3D normalisation
 * of each kernel so that its integral over R^d is 1. Support radius is
 * kappa * h: 2h (cubic, Wendland C2/C4) and 3h (quintic). The gradient is
 * taken with respect to the evaluation point x_a of W(x_a - x_b) (seed 000
 * eq. 21, seed 004 eq. 3), i.e. grad W = W'(r) (x_a - x_b) / r. */
#ifndef SPH_KERNEL_H
#define SPH_KERNEL_H

#include "sph/status.h"

#define SPH_KERNEL_LIST(X)                                                     \
  X(SPH_KERNEL_CUBIC, "cubic")                                                 \
  X(SPH_KERNEL_QUINTIC, "quintic")                                             \
  X(SPH_KERNEL_WENDLAND_C2, "wendland-c2")                                     \
  X(SPH_KERNEL_WENDLAND_C4, "wendland-c4")

typedef enum sph_kernel_type {
#define SPH_KERNEL_ENUM(e, name) e,
  SPH_KERNEL_LIST(SPH_KERNEL_ENUM)
#undef SPH_KERNEL_ENUM
      SPH_KERNEL_COUNT
} sph_kernel_type;

typedef struct sph_kernel {
  sph_kernel_type type;
  int dim;        /* 1, 2 or 3 */
  double h;       /* smoothing length */
  double kappa;   /* support radius / h */
  double support; /* kappa * h */
  double norm;    /* sigma_d / h^d */
} sph_kernel;

/* Fills `k`; fails with SPH_ERR_ARG for a bad dimension or h <= 0. */
sph_status sph_kernel_create(sph_kernel *k, sph_kernel_type type, int dim,
                             double h, sph_error *err);

/* Kernel type from its scene name ("cubic", ...); -1 if unknown. */
int sph_kernel_type_from_name(const char *name);
const char *sph_kernel_type_name(sph_kernel_type type);

/* W(r) */
double sph_kernel_eval(const sph_kernel *k, double r);
/* dW/dr */
double sph_kernel_dwdr(const sph_kernel *k, double r);
/* d2W/dr2 */
double sph_kernel_d2wdr2(const sph_kernel *k, double r);
/* grad_a W(x_a - x_b); rab = x_a - x_b, r = |rab| (0 gives 0) */
void sph_kernel_gradient(const sph_kernel *k, const double rab[3], double r,
                         double grad[3]);
/* Laplacian of W in k->dim dimensions: W'' + (d - 1) W' / r (finite at 0) */
double sph_kernel_laplacian(const sph_kernel *k, double r);

#endif
