/* Pair interactions of ul-csph: the shared ones of methods/common/pair_iact.h
 * taken in the reference configuration x^r (ref->X after an update), summed by
 * sph_ref_pair_sums: the incremental gradient f_a = sum_b (x_b - x_a) (x)
 * g_b(x^r_a) (seed 001 eq. 12-13 in the difference form of eq. 8) and the
 * Galerkin force of eq. 14 in the conservative pair form of seed 000
 * eq. 29c, with the stress P F^r^T / J^r per reference volume; the per
 * particle steps (F = f F^r, that stress) are ul_iact_* below, with the
 * Hessian-difference stabilisation of sec. 3.4 (eq. 17-21) and its
 * adjoint in the force. */
#ifndef SPH_UL_CSPH_IACT_H
#define SPH_UL_CSPH_IACT_H

#include "methods/common/pair_iact.h"

/* F = f F^r (seed 001 sec. 3.1) */
static inline void ul_iact_total_defgrad(const double f[9], const double Fr[9],
                                         double F[9]) {
  sph_mat3_mul(f, Fr, F);
}

/* S = P F^r^T / J^r: eq. 14's P^n [F^r]^T per reference volume
 * (V^0 = V^r / J^r) */
static inline void ul_iact_reference_stress(const double P[9],
                                            const double Fr[9], double Jr,
                                            double S[9]) {
  double Frt[9];
  sph_mat3_transpose(Fr, Frt);
  sph_mat3_mul(P, Frt, S);
  for (int k = 0; k < 9; ++k)
    S[k] /= Jr;
}

/* Q^T with Q = (S - c Y) L, paired with the corrected gradient L of x^r */
static inline void ul_iact_force_matrix(const double S[9], const double Y[9],
                                        double c, const double L[9],
                                        double Qt[9]) {
  double A[9], Q[9];
  for (int k = 0; k < 9; ++k)
    A[k] = S[k] - c * Y[k];
  sph_mat3_mul(A, L, Q);
  sph_mat3_transpose(Q, Qt);
}

/* H_k(x_i) h, the kernel Hessian of eq. 18 applied to h, with
 * r = x_i - x_k, d = |r| > 0, W' and W'' at d:
 * grad grad W = W'' r^ r^T + (W' / d) (I - r^ r^T) */
static inline void ul_iact_hessian_h(const double r[3], double d, double dw,
                                     double d2w, const double h[3],
                                     double out[3]) {
  double e[3] = {r[0] / d, r[1] / d, r[2] / d};
  double eh = e[0] * h[0] + e[1] * h[1] + e[2] * h[2], q = dw / d;
  for (int c = 0; c < 3; ++c)
    out[c] = d2w * eh * e[c] + q * (h[c] - eh * e[c]);
}

/* The stabilisation of f (eq. 17 and 21 on x): over the slots k of a,
 * eta [sum_k V_k (x_k - x_a) (x) H~_k(x_a) h - sum_k (f0_k - f0_a) g_k(x_a).h]
 * in the difference form (both sums vanish on constants); hv = H~_k(x_a) h
 * and gh = g_k(x_a).h of the slot */
static inline void ul_iact_stab_defgrad(double acc[9], double Vk,
                                        const double xa[3], const double xk[3],
                                        const double hv[3], double gh,
                                        const double f0a[9],
                                        const double f0k[9]) {
  for (int i = 0; i < 3; ++i) {
    double dx = Vk * (xk[i] - xa[i]);
    for (int j = 0; j < 3; ++j)
      acc[3 * i + j] += dx * hv[j] - gh * (f0k[3 * i + j] - f0a[3 * i + j]);
  }
}

/* Y_m += gh_jm V_j S_j: the adjoint of the f0 difference term */
static inline void ul_iact_stab_adjoint(double Y[9], double ghjm, double Vj,
                                        const double Sj[9]) {
  double c = ghjm * Vj;
  for (int k = 0; k < 9; ++k)
    Y[k] += c * Sj[k];
}

/* out += V_j S_j hv_ji: the adjoint of the Hessian term */
static inline void ul_iact_stab_hessian_force(double out[3], double Vj,
                                              const double Sj[9],
                                              const double hvji[3]) {
  for (int i = 0; i < 3; ++i)
    out[i] += Vj * (Sj[3 * i] * hvji[0] + Sj[3 * i + 1] * hvji[1] +
                    Sj[3 * i + 2] * hvji[2]);
}

#endif
