/* Pair interactions of tl-bond (seed 004): the bond-corrected deformation
 * gradient (eq. 37-39 summed as F^c_a = F_a M_a + sum_b x_ab (x) q_ab), the
 * rates of the deformation gradient (eq. 24) and of the momentum with the
 * symmetrised corrected gradient (eq. 22), and the pair wave speed of the
 * time step (eq. 31-32). */
#ifndef SPH_TL_BOND_IACT_H
#define SPH_TL_BOND_IACT_H

#include <math.h>

#include "core/tensor.h"

/* Fc += (x_b - x_a) (x) q_ab */
static inline void tl_bond_iact_defgrad(double Fc[9], const double xa[3],
                                        const double xb[3], const double q[3]) {
  for (int i = 0; i < 3; ++i) {
    double d = xb[i] - xa[i];
    for (int j = 0; j < 3; ++j)
      Fc[3 * i + j] += d * q[j];
  }
}

/* dF += (v_b - v_a) (x) V_b grad W~_b(X_a) (eq. 24 with sum_b V_b grad W~_b
 * = 0); dp += P_a fa + P_b fb (eq. 22 or its conservative counterpart) */
static inline void tl_bond_iact_rates(double dF[9], double dp[3],
                                      const double va[3], const double vb[3],
                                      const double Pa[9], const double Pb[9],
                                      const double gv[3], const double fa[3],
                                      const double fb[3]) {
  for (int i = 0; i < 3; ++i) {
    double d = vb[i] - va[i];
    for (int j = 0; j < 3; ++j) {
      dF[3 * i + j] += d * gv[j];
      dp[i] += Pa[3 * i + j] * fa[j] + Pb[3 * i + j] * fb[j];
    }
  }
}

/* r_ij / c_p,ij of eq. 31-32 with c_p,ij = c_lin / ((lam_a + lam_b) / 2) */
static inline double tl_bond_iact_transit(const double xa[3],
                                          const double xb[3], double lam_a,
                                          double lam_b, double c_lin) {
  double r2 = 0.0;
  for (int c = 0; c < 3; ++c)
    r2 += (xb[c] - xa[c]) * (xb[c] - xa[c]);
  return sqrt(r2) * 0.5 * (lam_a + lam_b) / c_lin;
}

#endif
