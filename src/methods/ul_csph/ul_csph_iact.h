/* Pair interactions of ul-csph: the shared ones of methods/tl_iact.h taken
 * in the reference configuration x^r (ref->X after an update), summed by
 * tl_pair_sums: the incremental gradient f_a = sum_b (x_b - x_a) (x)
 * g_b(x^r_a) (seed 001 eq. 12-13 in the difference form of eq. 8) and the
 * Galerkin force of eq. 14 in the conservative pair form of seed 000
 * eq. 29c, with the stress P F^r^T / J^r per reference volume; the per
 * particle steps (F = f F^r, that stress) are ul_iact_* below. */
#ifndef SPH_UL_CSPH_IACT_H
#define SPH_UL_CSPH_IACT_H

#include "methods/tl_iact.h"

/* F = f F^r (seed 001 sec. 3.1) */
static inline void ul_iact_total_defgrad(const double f[9], const double Fr[9],
                                         double F[9]) {
  sph_mat3_mul(f, Fr, F);
}

/* Q^T with Q = P F^r^T L / J^r: eq. 14's P^n [F^r]^T per initial volume
 * V^0 = V^r / J^r, paired with the corrected gradient L of x^r */
static inline void ul_iact_force_matrix(const double P[9], const double Fr[9],
                                        double Jr, const double L[9],
                                        double Qt[9]) {
  double Frt[9], S[9], Q[9];
  sph_mat3_transpose(Fr, Frt);
  sph_mat3_mul(P, Frt, S);
  sph_mat3_mul(S, L, Q);
  for (int k = 0; k < 9; ++k)
    Q[k] /= Jr;
  sph_mat3_transpose(Q, Qt);
}

#endif
