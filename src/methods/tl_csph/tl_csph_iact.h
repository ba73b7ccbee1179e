/* Pair interactions of tl-csph: both are the shared ones of
 * methods/common/pair_iact.h, summed by sph_ref_pair_sums: the deformation
 * gradient from the current positions, F_a = sum_b V_b (x_b - x_a) (x)
 * grad_b(X_a) (seed 001 eq. 9 in the difference form of eq. 8, seed 000 eq.
 * 34), the gradient sum of x corrected once per particle, and the Galerkin
 * force (eq. 11). */
#ifndef SPH_TL_CSPH_IACT_H
#define SPH_TL_CSPH_IACT_H

#include "methods/common/pair_iact.h"

#endif
