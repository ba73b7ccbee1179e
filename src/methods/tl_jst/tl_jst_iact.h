/* Pair interactions specific to tl-jst: the symmetric force of seed 003
 * eq. 11 (also eq. 30 of seed 000 with the uncorrected gradient) and the
 * kernel-gradient force of seed 000 eq. 31; the shared ones are in
 * methods/common/pair_iact.h. */
#ifndef SPH_TL_JST_IACT_H
#define SPH_TL_JST_IACT_H

#include "core/hd.h"
#include "core/tensor.h"

/* Symmetric force of seed 003 eq. 11: dp_a += (P_a + P_b) V_b grad_b(X_a),
 * accumulated as T_a -= ... so that dp = -T; g_ab = V_b grad_b(X_a) */
SPH_HD static inline void tl_jst_iact_force_symmetric(double T[3],
                                                      const double Pa[9],
                                                      const double Pb[9],
                                                      const double g_ab[3]) {
  double S[9];
  for (int k = 0; k < 9; ++k)
    S[k] = Pa[k] + Pb[k];
  double u[3];
  sph_mat3_vec(S, g_ab, u);
  for (int i = 0; i < 3; ++i)
    T[i] -= u[i];
}

/* Kernel-gradient force of seed 000 eq. 31: T_a += V_b P_b gradW~_a(X_b)
 * (b = a included) */
SPH_HD static inline void tl_jst_iact_force_kernel(double T[3], double Vb,
                                                   const double Pb[9],
                                                   const double g_ba[3]) {
  double u[3];
  sph_mat3_vec(Pb, g_ba, u);
  for (int i = 0; i < 3; ++i)
    T[i] += Vb * u[i];
}

#endif
