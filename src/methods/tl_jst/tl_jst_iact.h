/* Pair interactions of tl-jst (seed 000 eq. 41-42, seed 003 eq. 11). */
#ifndef SPH_TL_JST_IACT_H
#define SPH_TL_JST_IACT_H

#include "sph/tensor.h"

/* Velocity gradient contribution V_b / rho0 (p_b - p_a) (x) grad_b(X_a)
 * (seed 000 eq. 33a) */
static inline void tl_jst_iact_velocity_gradient(double G[9], double Vb,
                                                 double inv_rho0,
                                                 const double pa[3],
                                                 const double pb[3],
                                                 const double g[3]) {
  double s = Vb * inv_rho0;
  for (int i = 0; i < 3; ++i) {
    double dv = s * (pb[i] - pa[i]);
    G[3 * i] += dv * g[0];
    G[3 * i + 1] += dv * g[1];
    G[3 * i + 2] += dv * g[2];
  }
}

/* Globally conservative internal force term of eq. 42:
 * T_a += V_b (P_b grad_a(X_b) - P_a grad_b(X_a)) */
static inline void tl_jst_iact_force(double T[3], double Vb, const double Pa[9],
                                     const double Pb[9], const double g_ab[3],
                                     const double g_ba[3]) {
  double u[3], w[3];
  sph_mat3_vec(Pb, g_ba, u);
  sph_mat3_vec(Pa, g_ab, w);
  for (int i = 0; i < 3; ++i)
    T[i] += Vb * (u[i] - w[i]);
}

/* Symmetric force of seed 003 eq. 11: dp_a += V_b (P_a + P_b) grad_b(X_a),
 * accumulated as T_a -= ... so that dp = -T */
static inline void tl_jst_iact_force_symmetric(double T[3], double Vb,
                                               const double Pa[9],
                                               const double Pb[9],
                                               const double g_ab[3]) {
  double S[9];
  for (int k = 0; k < 9; ++k)
    S[k] = Pa[k] + Pb[k];
  double u[3];
  sph_mat3_vec(S, g_ab, u);
  for (int i = 0; i < 3; ++i)
    T[i] -= Vb * u[i];
}

#endif
