/* Pair interactions of ul-sph (seed 002): the low-dissipation Riemann
 * solver (eq. 13-16, limiter in the dimensionless form of docs/benchmarks.md
 * E.1), the Riemann continuity and pressure terms (eq. 11-12), the nested shear
 * force (eq. 17), Gray et al.'s artificial stress force, the rotation-
 * invariant Laplacian of the velocity (eq. 23) and the velocity gradient
 * (eq. 18, or eq. 30 with the correction matrix B of eq. 31).
 *
 * Geometry of a pair (i, j) as cached at the last configuration update:
 * e = (x_i - x_j) / r (the paper's e_ij), r, dW = W'(r) <= 0, so that
 * grad_i W_ij = dW e. The Riemann problem is posed along -e (from i to j):
 * U_L = -v_i.e, U_R = -v_j.e. */
#ifndef SPH_UL_SPH_IACT_H
#define SPH_UL_SPH_IACT_H

#include <math.h>

#include "core/tensor.h"

/* a . b over the first dim components (dim a constant where inlined) */
static inline double ul_sph_iact_dot(const double a[3], const double b[3],
                                     int dim) {
  double s = a[0] * b[0] + a[1] * b[1];
  return dim == 3 ? s + a[2] * b[2] : s;
}

/* Interface velocity jump and pressure of one pair. */
typedef struct ul_riemann {
  double du;    /* U_L - U*: half the dissipative velocity jump */
  double pstar; /* P* */
} ul_riemann;

/* eq. 13-14: the dissipative velocity jump U_L - U* alone (what the
 * continuity equation needs); `pressure_term` keeps (P_L - P_R) / (z_L +
 * z_R) in U* */
static inline double ul_sph_iact_riemann_du(const double e[3],
                                            const double vi[3],
                                            const double vj[3], double rho_i,
                                            double rho_j, double p_i,
                                            double p_j, double c_i, double c_j,
                                            int pressure_term, int dim) {
  double jump = ul_sph_iact_dot(vj, e, dim) - ul_sph_iact_dot(vi, e, dim);
  double zL = rho_i * c_i, zR = rho_j * c_j;
  return (zR * jump - (pressure_term ? p_i - p_j : 0.0)) * (1.0 / (zL + zR));
}

/* eq. 13-16: P*; `limited` applies the limiter beta of eq. 16 (dissipation
 * only while the pair approaches, growing with its Mach number), else
 * beta = 1 for every pair (the unlimited dissipative solver of the
 * authors' code) */
static inline double
ul_sph_iact_riemann_pstar(const double e[3], const double vi[3],
                          const double vj[3], double rho_i, double rho_j,
                          double p_i, double p_j, double c_i, double c_j,
                          int limited, int dim) {
  double jump = ul_sph_iact_dot(vj, e, dim) - ul_sph_iact_dot(vi, e, dim);
  double zL = rho_i * c_i, zR = rho_j * c_j;
  double beta = 1.0;
  if (limited) { /* clamped to [0, 1] without branches */
    beta = 6.0 * jump / (c_i + c_j);
    beta = 0.5 * (beta + fabs(beta)); /* max(beta, 0) exactly, no branch */
    beta = beta < 1.0 ? beta : 1.0;
  }
  return (zL * p_j + zR * p_i + beta * zL * zR * jump) * (1.0 / (zL + zR));
}

/* both parts (tests and the contact pairs) */
static inline ul_riemann
ul_sph_iact_riemann(const double e[3], const double vi[3], const double vj[3],
                    double rho_i, double rho_j, double p_i, double p_j,
                    double c_i, double c_j, int pressure_term, int limited) {
  ul_riemann s;
  s.du = ul_sph_iact_riemann_du(e, vi, vj, rho_i, rho_j, p_i, p_j, c_i, c_j,
                                pressure_term, 3);
  s.pstar = ul_sph_iact_riemann_pstar(e, vi, vj, rho_i, rho_j, p_i, p_j, c_i,
                                      c_j, limited, 3);
  return s;
}

/* eq. 11: d rho_i / dt += -2 rho_i V_j (U_L - U*) dW (times rho_i later) */
static inline double ul_sph_iact_continuity(double Vj, double du, double dW) {
  return -2.0 * Vj * du * dW;
}

/* eq. 12: dv_i / dt += -2 V_j P* / rho_i grad_i W (1 / rho_i later) */
static inline void ul_sph_iact_pressure(double a[3], double Vj, double pstar,
                                        double dW, const double e[3], int dim) {
  double s = -2.0 * Vj * pstar * dW;
  for (int c = 0; c < dim; ++c)
    a[c] += s * e[c];
}

/* eq. 17: dv_i / dt += V_j (sigma_i + sigma_j) grad_i W (1 / rho_i later) */
static inline void ul_sph_iact_shear_stress(double a[3], double Vj,
                                            const double si[9],
                                            const double sj[9], double dW,
                                            const double e[3]) {
  for (int r = 0; r < 3; ++r) {
    double s = 0.0;
    for (int c = 0; c < 3; ++c)
      s += (si[3 * r + c] + sj[3 * r + c]) * e[c];
    a[r] += Vj * dW * s;
  }
}

/* Gray et al. (2001): dv_i / dt += m_j f^n (R_i + R_j) grad_i W */
static inline void ul_sph_iact_artificial_stress(double a[3], double mj,
                                                 double fn, const double Ri[9],
                                                 const double Rj[9], double dW,
                                                 const double e[3]) {
  for (int r = 0; r < 3; ++r) {
    double s = 0.0;
    for (int c = 0; c < 3; ++c)
      s += (Ri[3 * r + c] + Rj[3 * r + c]) * e[c];
    a[r] += mj * fn * dW * s;
  }
}

/* eq. 23 without the 2 zeta: V_j (e . v_ij) / r dW e */
static inline void ul_sph_iact_laplacian(double lap[3], double Vj,
                                         const double vi[3], const double vj[3],
                                         double r, double dW, const double e[3],
                                         int dim) {
  double vij[3] = {vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2]};
  double s = Vj * ul_sph_iact_dot(e, vij, dim) / r * dW;
  for (int c = 0; c < dim; ++c)
    lap[c] += s * e[c];
}

/* eq. 31 before the inverse: M += V_j dW r e (x) e (= V_j r_ij (x) grad W) */
static inline void ul_sph_iact_moment(double M[9], double Vj, double r,
                                      double dW, const double e[3], int dim) {
  double s = Vj * r * dW;
  for (int a = 0; a < dim; ++a)
    for (int b = 0; b < dim; ++b)
      M[3 * a + b] += s * e[a] * e[b];
}

/* eq. 18 (eq. 30 before the correction B): L_i -= V_j (v_i - v_j) (x)
 * grad_i W; with B = M^-1 applied on the right, -L B is exact for a linear
 * field. `dim` 2 leaves the third row and column as they are (zeros). */
static inline void ul_sph_iact_velocity_gradient(double L[9], double Vj,
                                                 const double vi[3],
                                                 const double vj[3], double dW,
                                                 const double e[3], int dim) {
  double g[3] = {-(dW * e[0]), -(dW * e[1]), -(dW * e[2])};
  for (int a = 0; a < dim; ++a) {
    double d = Vj * (vi[a] - vj[a]);
    for (int b = 0; b < dim; ++b)
      L[3 * a + b] += d * g[b];
  }
}

#endif
