/* Pair interactions of tl-csph: the deformation gradient from the current
 * positions, F_a = sum_b V_b (x_b - x_a) (x) grad_b(X_a) (seed 001 eq. 9 in
 * the difference form of eq. 8, seed 000 eq. 34), accumulated uncorrected
 * (w_ab r_ab) and corrected once per particle; the force is the shared
 * Galerkin force of methods/tl_iact.h. */
#ifndef SPH_TL_CSPH_IACT_H
#define SPH_TL_CSPH_IACT_H

#include "methods/tl_iact.h"

static inline void tl_csph_iact_deformation(tl_sums *s, double w,
                                            const double xa[3],
                                            const double xb[3], tl_v2 r01,
                                            double r2) {
  tl_iact_gradient2(s, w, xa, xb, r01, r2);
}

#endif
