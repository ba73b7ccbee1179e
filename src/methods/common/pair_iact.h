/* Pair interactions shared by the total-Lagrangian methods, written with
 * the uncorrected pair gradient w_ab r_ab, r_ab = X_a - X_b and
 * w_ab = V_b W'(|r_ab|) / |r_ab| (one number per slot), so that the
 * corrected gradients of seed 000 eq. 21 are V_b grad_b(X_a) = L_a w_ab r_ab
 * and V_b grad_a(X_b) = -L_b w_ab r_ab: the correction matrices L are applied
 * once per particle, never per pair. */
#ifndef SPH_PAIR_IACT_H
#define SPH_PAIR_IACT_H

#include <string.h>

#include "core/hd.h"
#include "core/tensor.h"

#ifndef __CUDACC__

/* Two doubles in one register (GCC and Clang vector extension), so that a
 * sweep keeps its twelve sums in registers rather than on the stack. */
typedef double ref_v2 __attribute__((vector_size(16)));

static inline ref_v2 ref_v2_load(const double *p) {
  ref_v2 v;
  memcpy(&v, p, sizeof v);
  return v;
}

/* A particle's pair sums: the gradient rows (G_i0, G_i1), the last column
 * (G_02, G_12) and G_22, the force (f_0, f_1) and f_2, and a Laplacian
 * (l_0, l_1) and l_2. */
typedef struct ref_sums {
  ref_v2 g01[3];
  ref_v2 g2_01;
  double g22;
  ref_v2 f01;
  double f2;
  ref_v2 l01;
  double l2;
} ref_sums;

/* r_ab = X_a - X_b as (r_0, r_1) and r_2 */
static inline void ref_iact_pair_vector2(const double *Xa, const double *Xb,
                                         ref_v2 *r01, double *r2) {
  *r01 = ref_v2_load(Xa) - ref_v2_load(Xb);
  *r2 = Xa[2] - Xb[2];
}

/* ref_iact_gradient on the register sums (the same products and sums), from
 * the difference f_b - f_a as (df_0, df_1) and df_2 */
static inline void ref_iact_gradient2(ref_sums *s, double w, ref_v2 df01,
                                      double df2, ref_v2 r01, double r2) {
  ref_v2 d01 = w * df01;
  double d2 = w * df2;
  s->g01[0] += d01[0] * r01;
  s->g01[1] += d01[1] * r01;
  s->g01[2] += d2 * r01;
  s->g2_01 += d01 * r2;
  s->g22 += d2 * r2;
}

/* ref_iact_force on the register sums, with Q_b stored transposed */
static inline void ref_iact_force2(ref_sums *s, double w, const double Qtb[9],
                                   ref_v2 r01, double r2) {
  double r0 = w * r01[0], r1 = w * r01[1], wr2 = w * r2;
  s->f01 += r0 * ref_v2_load(Qtb) + r1 * ref_v2_load(Qtb + 3) +
            wr2 * ref_v2_load(Qtb + 6);
  s->f2 += r0 * Qtb[2] + r1 * Qtb[5] + wr2 * Qtb[8];
}

/* the Laplacian sum l += lap_ab (f_b - f_a) of a vector field, in the
 * order and arithmetic of the JST term's own sweep (terms/jst_dissipation.c)
 * so that its L[u] is the same to the bit */
static inline void ref_iact_laplacian2(ref_sums *s, double lap, ref_v2 df01,
                                       double df2) {
  s->l01 += lap * df01;
  s->l2 += lap * df2;
}

/* the sums as G[9] and f[3] */
static inline void ref_sums_store(const ref_sums *s, double G[9], double f[3]) {
  for (int i = 0; i < 3; ++i) {
    G[3 * i] = s->g01[i][0];
    G[3 * i + 1] = s->g01[i][1];
  }
  G[2] = s->g2_01[0];
  G[5] = s->g2_01[1];
  G[8] = s->g22;
  f[0] = s->f01[0];
  f[1] = s->f01[1];
  f[2] = s->f2;
}

#endif /* !__CUDACC__: the register sums are the CPU sweep's */

/* r_ab = X_a - X_b */
SPH_HD static inline void ref_iact_pair_vector(const double *X, size_t a,
                                               size_t b, double r[3]) {
  for (int c = 0; c < 3; ++c)
    r[c] = X[3 * a + c] - X[3 * b + c];
}

/* Gradient of a vector field before the correction (seed 000 eq. 21; with
 * f = p eq. 33a, with f = x eq. 34): G += w_ab (f_b - f_a) (x) r_ab; the
 * corrected gradient is G L_a^T (ref_iact_gradient_correct). */
SPH_HD static inline void ref_iact_gradient(double G[9], double w,
                                            const double fa[3],
                                            const double fb[3],
                                            const double r[3]) {
  for (int i = 0; i < 3; ++i) {
    double d = w * (fb[i] - fa[i]);
    G[3 * i] += d * r[0];
    G[3 * i + 1] += d * r[1];
    G[3 * i + 2] += d * r[2];
  }
}

/* ref_iact_force2 on plain sums (the device step, src/gpu): the same
 * products and sums per component, f += w_ab Q_b r_ab with Q_b stored
 * transposed */
SPH_HD static inline void
ref_iact_force(double f[3], double w, const double Qtb[9], const double r[3]) {
  double r0 = w * r[0], r1 = w * r[1], wr2 = w * r[2];
  for (int c = 0; c < 3; ++c)
    f[c] += r0 * Qtb[c] + r1 * Qtb[3 + c] + wr2 * Qtb[6 + c];
}

/* ref_iact_laplacian2 on plain sums: l += lap_ab (f_b - f_a) */
SPH_HD static inline void ref_iact_laplacian(double l[3], double lap,
                                             const double fa[3],
                                             const double fb[3]) {
  for (int c = 0; c < 3; ++c)
    l[c] += lap * (fb[c] - fa[c]);
}

/* G <- G L^T */
SPH_HD static inline void ref_iact_gradient_correct(double G[9],
                                                    const double L[9]) {
  double out[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[3 * i + j] = G[3 * i] * L[3 * j] + G[3 * i + 1] * L[3 * j + 1] +
                       G[3 * i + 2] * L[3 * j + 2];
  for (int k = 0; k < 9; ++k)
    G[k] = out[k];
}

/* Plane strain in 2D: the gradient of x has no z row or column but
 * F_zz = 1 (the points all lie in one plane, so the sums leave it 0). */
SPH_HD static inline void ref_iact_plane_strain(double F[9], int dim) {
  if (dim == 2) {
    F[2] = F[5] = F[6] = F[7] = 0.0;
    F[8] = 1.0;
  }
}

/* Globally conservative internal force of seed 000 eq. 29c / 42 (the
 * Galerkin force of seed 001 eq. 11 with the corrected gradient),
 * -T_a = sum_b V_b (P_a grad_b(X_a) - P_b grad_a(X_b))
 *      = Q_a s_a + sum_b w_ab Q_b r_ab with Q = P L and s_a = sum_b w_ab r_ab:
 * ref_iact_force2 adds the pair's share w_ab Q_b r_ab, this the Q_a s_a part
 * (Q stored transposed). */
SPH_HD static inline void
ref_iact_force_self(const double Qta[9], const double sa[3], double out[3]) {
  for (int i = 0; i < 3; ++i)
    out[i] = Qta[i] * sa[0] + Qta[3 + i] * sa[1] + Qta[6 + i] * sa[2];
}

#endif
