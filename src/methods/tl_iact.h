/* Pair interactions shared by the total-Lagrangian methods, written with
 * the uncorrected pair gradient w_ab r_ab, r_ab = X_a - X_b and
 * w_ab = V_b W'(|r_ab|) / |r_ab| (one number per slot), so that the
 * corrected gradients of seed 000 eq. 21 are V_b grad_b(X_a) = L_a w_ab r_ab
 * and V_b grad_a(X_b) = -L_b w_ab r_ab: the correction matrices L are applied
 * once per particle, never per pair. */
#ifndef SPH_TL_IACT_H
#define SPH_TL_IACT_H

#include "sph/tensor.h"

/* r_ab = X_a - X_b */
static inline void tl_iact_pair_vector(const double *X, size_t a, size_t b,
                                       double r[3]) {
  for (int c = 0; c < 3; ++c)
    r[c] = X[3 * a + c] - X[3 * b + c];
}

/* Gradient of a vector field before the correction (seed 000 eq. 21; with
 * f = p eq. 33a, with f = x eq. 34): G += w_ab (f_b - f_a) (x) r_ab; the
 * corrected gradient is G L_a^T (tl_iact_gradient_correct). */
static inline void tl_iact_gradient(double G[9], double w, const double fa[3],
                                    const double fb[3], const double r[3]) {
  for (int i = 0; i < 3; ++i) {
    double d = w * (fb[i] - fa[i]);
    G[3 * i] += d * r[0];
    G[3 * i + 1] += d * r[1];
    G[3 * i + 2] += d * r[2];
  }
}

/* G <- G L^T */
static inline void tl_iact_gradient_correct(double G[9], const double L[9]) {
  double out[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[3 * i + j] = G[3 * i] * L[3 * j] + G[3 * i + 1] * L[3 * j + 1] +
                       G[3 * i + 2] * L[3 * j + 2];
  for (int k = 0; k < 9; ++k)
    G[k] = out[k];
}

/* Globally conservative internal force of seed 000 eq. 29c / 42 (the
 * Galerkin force of seed 001 eq. 11 with the corrected gradient),
 * -T_a = sum_b V_b (P_a grad_b(X_a) - P_b grad_a(X_b))
 *      = Q_a s_a + sum_b w_ab Q_b r_ab with Q = P L and s_a = sum_b w_ab r_ab:
 * this adds the pair's share w_ab Q_b r_ab to dp_a. */
static inline void tl_iact_force(double dp[3], double w, const double Qb[9],
                                 const double r[3]) {
  for (int i = 0; i < 3; ++i)
    dp[i] +=
        w * (Qb[3 * i] * r[0] + Qb[3 * i + 1] * r[1] + Qb[3 * i + 2] * r[2]);
}

#endif
