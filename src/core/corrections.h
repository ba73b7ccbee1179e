/* Kernel corrections on a particle cloud (reference configuration for
 * total-Lagrangian methods), stored per directed pair in the CSR order of an
 * sph_neighbors list.
 *
 *  - gradient correction matrix L_a (seed 001 eq. 8, seed 000 eq. 21):
 *      L_a = ( sum_b V_b grad W_b(X_a) (x) (X_b - X_a) )^-1 , applied as
 *      corrected grad W_b(X_a) = L_a grad W_b(X_a); the sum is arranged so that
 *      sum_b V_b (f_b - f_a) (x) corrected grad W_b(X_a) = grad f exactly for
 *      linear f.
 *  - zeroth-order corrected kernel W~0 (seed 004 eq. 10) and its gradient
 *      (eq. 13-14), with the correction L of eq. 11-12 applied to it;
 *  - first-order corrected kernel W~1 (seed 004 eq. 6-8) and its exact
 *      gradient (seed 004 App. A, eq. A.1-A.6);
 *  - corrected Laplacian (seed 000 App. A, eq. A.2-A.5) with the quadratic
 *      condition generalised to d dimensions (sum V |r|^2 Lap W~ = 2d).
 *
 * Pair quantities with "_b(X_a)" are those of particle b seen from a, stored
 * at the slot of b in a's list. The self pair (b = a) is not in the list; its
 * kernel value W(0) enters the W~0/W~1 sums and is returned separately.
 *
 * In 2D (plane strain) the moment matrices are 2x2 blocks and L has
 * L_zz = 1, L_xz = L_zx = ... = 0; 1D likewise keeps only the xx entry.
 * A moment matrix whose reciprocal 1-norm condition number falls below
 * `rcond_min` (default 1e-10) is reported as SPH_ERR_SINGULAR naming the
 * particle id and its position, never inverted into NaN. */
#ifndef SPH_CORRECTIONS_H
#define SPH_CORRECTIONS_H

#include <stddef.h>
#include <stdint.h>

#include "core/kernel.h"
#include "core/neighbors.h"
#include "sph/status.h"

/* Which corrected gradient a method asks for. */
typedef enum sph_gradient_kind {
  SPH_GRAD_UNCORRECTED = 0, /* grad W (seed 000 eq. 22) */
  SPH_GRAD_CORRECTED,       /* L grad W (seed 000 eq. 21, seed 001 eq. 8) */
  SPH_GRAD_CORRECTED_W0,    /* L grad W~0 (seed 004 eq. 11-14) */
  SPH_GRAD_W1               /* grad W~1 (seed 004 App. A) */
} sph_gradient_kind;

/* Geometry the corrections are computed on. */
typedef struct sph_cloud {
  size_t n;
  int dim;
  const double *x;      /* 3*n positions */
  const double *volume; /* n volumes */
  const int64_t *id;    /* n ids for error messages (may be NULL) */
  const sph_neighbors *nl;
  const sph_kernel *kernel;
  double rcond_min; /* 0 selects the default 1e-10 */
  /* n flags or NULL: points whose lists may lack neighbours (a distributed
   * run's images no owned particle neighbours): the functions below give
   * them NaN values (never to be read) and no failure */
  const unsigned char *partial;
} sph_cloud;

/* Per-pair gradients grad[3*k] for every slot k of the CSR list; if not
 * NULL, grad_self[3*a] receives the gradient of the particle's own kernel
 * at itself (zero for UNCORRECTED and CORRECTED; nonzero for CORRECTED_W0
 * and W1, where sum_b V_b f_b grad W~1_b(x_a) over b including a reproduces
 * linear gradients), and L[9*a] the correction matrices used (identity for
 * UNCORRECTED and W1). `grad` may be NULL (not for W1) when only L is
 * wanted. */
sph_status sph_correction_gradient(const sph_cloud *c, sph_gradient_kind kind,
                                   double *grad, double *grad_self, double *L,
                                   sph_error *err);

/* Corrected kernel values: w[k] for slot k (W~_b(X_a)) and wself[a]
 * (W~_a(X_a)); order 0 gives W~0, order 1 gives W~1. */
sph_status sph_correction_kernel(const sph_cloud *c, int order, double *w,
                                 double *wself, sph_error *err);

/* Corrected Laplacian Lap W~_b(X_a) for every slot (seed 000 App. A). */
sph_status sph_correction_laplacian(const sph_cloud *c, double *lap,
                                    sph_error *err);

/* The coefficients a point's corrected gradient slots (kind SPH_GRAD_W1:
 * W~1; SPH_GRAD_CORRECTED_W0: L grad W~0, seed 004 eq. 10-14) and (when
 * `laplacian`) corrected Laplacian slots are evaluated from,
 * SPH_CORRECTION_COEFS per point, so that a slot (a -> b) is evaluated
 * again where a's neighbourhood is not whole (a ghost of a distributed run,
 * its coefficients from its owner): sph_correction_slot gives the same bits
 * as the sweeps above. */
#define SPH_CORRECTION_COEFS 20
sph_status sph_correction_coefficients(const sph_cloud *c,
                                       sph_gradient_kind kind, int laplacian,
                                       double *coef, sph_error *err);
/* The gradient of kind and Lap W~_b(X_a) of slot (a -> b) from coef, a's. */
void sph_correction_slot(const sph_cloud *c, sph_gradient_kind kind,
                         const double *coef, size_t a, size_t b, double grad[3],
                         double *lap);

#endif
