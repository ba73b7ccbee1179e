/* Pair interactions shared by the total-Lagrangian methods. */
#ifndef SPH_TL_IACT_H
#define SPH_TL_IACT_H

#include "sph/tensor.h"

/* Gradient contribution V_b (f_b - f_a) (x) grad_b(X_a) of a vector field
 * (seed 000 eq. 21; with f = p / rho0 eq. 33a, with f = x eq. 34) */
static inline void tl_iact_gradient(double G[9], double Vb, const double fa[3],
                                    const double fb[3], const double g[3]) {
  for (int i = 0; i < 3; ++i) {
    double d = Vb * (fb[i] - fa[i]);
    G[3 * i] += d * g[0];
    G[3 * i + 1] += d * g[1];
    G[3 * i + 2] += d * g[2];
  }
}

/* Globally conservative internal force of seed 000 eq. 29c / 42 (the
 * Galerkin force of seed 001 eq. 11 with the corrected gradient):
 * T_a += V_b (P_b grad_a(X_b) - P_a grad_b(X_a)) */
static inline void tl_iact_force(double T[3], double Vb, const double Pa[9],
                                 const double Pb[9], const double g_ab[3],
                                 const double g_ba[3]) {
  double u[3], w[3];
  sph_mat3_vec(Pb, g_ba, u);
  sph_mat3_vec(Pa, g_ab, w);
  for (int i = 0; i < 3; ++i)
    T[i] += Vb * (u[i] - w[i]);
}

#endif
