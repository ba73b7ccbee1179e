/* Small vector and 3x3 tensor helpers.
 *
 * Vectors are double[3]; second-order tensors are double[9] stored row-major
 * (A[3*i + j] = A_ij, first index spatial, second material for two-point
 * tensors). 2D scenes are plane strain and use the same 3x3 storage with
 * F_zz = 1. The tensor cross product is the one of seed 000 (eq. 1c, 12):
 * (A x B)_iI = E_ijk E_IJK A_jJ B_kK, so the cofactor is H = 1/2 F x F. */
#ifndef SPH_TENSOR_H
#define SPH_TENSOR_H

#include <math.h>
#include <string.h>

#include "core/hd.h"

SPH_HD static inline double sph_vec3_dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

SPH_HD static inline double sph_vec3_norm(const double a[3]) {
  return sqrt(sph_vec3_dot(a, a));
}

SPH_HD static inline void sph_vec3_cross(const double a[3], const double b[3],
                                         double out[3]) {
  double c0 = a[1] * b[2] - a[2] * b[1];
  double c1 = a[2] * b[0] - a[0] * b[2];
  double c2 = a[0] * b[1] - a[1] * b[0];
  out[0] = c0;
  out[1] = c1;
  out[2] = c2;
}

SPH_HD static inline void sph_mat3_zero(double A[9]) {
  memset(A, 0, 9 * sizeof *A);
}

SPH_HD static inline void sph_mat3_identity(double A[9]) {
  sph_mat3_zero(A);
  A[0] = A[4] = A[8] = 1.0;
}

SPH_HD static inline double sph_mat3_trace(const double A[9]) {
  return A[0] + A[4] + A[8];
}

/* A : B = A_ij B_ij */
SPH_HD static inline double sph_mat3_ddot(const double A[9],
                                          const double B[9]) {
  double s = 0.0;
  for (int k = 0; k < 9; ++k)
    s += A[k] * B[k];
  return s;
}

SPH_HD static inline void sph_mat3_transpose(const double A[9], double T[9]) {
  double t[9] = {A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8]};
  memcpy(T, t, sizeof t);
}

/* C = A B (C may alias A or B) */
SPH_HD static inline void sph_mat3_mul(const double A[9], const double B[9],
                                       double C[9]) {
  double t[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      t[3 * i + j] =
          A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
  memcpy(C, t, sizeof t);
}

/* y = A x (y may alias x) */
SPH_HD static inline void sph_mat3_vec(const double A[9], const double x[3],
                                       double y[3]) {
  double t0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
  double t1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
  double t2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
  y[0] = t0;
  y[1] = t1;
  y[2] = t2;
}

/* A += a (x) b */
SPH_HD static inline void sph_mat3_add_outer(double A[9], const double a[3],
                                             const double b[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      A[3 * i + j] += a[i] * b[j];
}

SPH_HD static inline double sph_mat3_det(const double A[9]) {
  return A[0] * (A[4] * A[8] - A[5] * A[7]) -
         A[1] * (A[3] * A[8] - A[5] * A[6]) +
         A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* Cofactor H = det(A) A^-T, computed without dividing (valid for singular A).
 * Equals 1/2 A x A (seed 000). */
SPH_HD static inline void sph_mat3_cofactor(const double A[9], double H[9]) {
  double t[9];
  t[0] = A[4] * A[8] - A[5] * A[7];
  t[1] = A[5] * A[6] - A[3] * A[8];
  t[2] = A[3] * A[7] - A[4] * A[6];
  t[3] = A[2] * A[7] - A[1] * A[8];
  t[4] = A[0] * A[8] - A[2] * A[6];
  t[5] = A[1] * A[6] - A[0] * A[7];
  t[6] = A[1] * A[5] - A[2] * A[4];
  t[7] = A[2] * A[3] - A[0] * A[5];
  t[8] = A[0] * A[4] - A[1] * A[3];
  memcpy(H, t, sizeof t);
}

/* Ainv = A^-1; returns det(A). Ainv is untouched when det(A) == 0. */
SPH_HD static inline double sph_mat3_inverse(const double A[9],
                                             double Ainv[9]) {
  double H[9];
  sph_mat3_cofactor(A, H);
  double det = A[0] * H[0] + A[1] * H[1] + A[2] * H[2];
  if (det == 0.0)
    return 0.0;
  double inv = 1.0 / det;
  /* A^-1 = H^T / det */
  double t[9] = {H[0] * inv, H[3] * inv, H[6] * inv, H[1] * inv, H[4] * inv,
                 H[7] * inv, H[2] * inv, H[5] * inv, H[8] * inv};
  memcpy(Ainv, t, sizeof t);
  return det;
}

/* Tensor cross product of seed 000: C_iI = E_ijk E_IJK A_jJ B_kK. */
SPH_HD static inline void
sph_mat3_tensor_cross(const double A[9], const double B[9], double C[9]) {
  static const int nxt[3] = {1, 2, 0};
  static const int prv[3] = {2, 0, 1};
  double t[9];
  for (int i = 0; i < 3; ++i) {
    int j = nxt[i], k = prv[i];
    for (int I = 0; I < 3; ++I) {
      int J = nxt[I], K = prv[I];
      /* even permutations (j,k),(J,K) minus the swapped ones */
      t[3 * i + I] = A[3 * j + J] * B[3 * k + K] - A[3 * j + K] * B[3 * k + J] -
                     A[3 * k + J] * B[3 * j + K] + A[3 * k + K] * B[3 * j + J];
    }
  }
  memcpy(C, t, sizeof t);
}

/* 1-norm (largest column sum of absolute values) */
SPH_HD static inline double sph_mat3_norm1(const double A[9]) {
  double best = 0.0;
  for (int j = 0; j < 3; ++j) {
    double s = fabs(A[j]) + fabs(A[3 + j]) + fabs(A[6 + j]);
    if (s > best)
      best = s;
  }
  return best;
}

/* Eigen-decomposition of a symmetric A = Q diag(w) Q^T by cyclic Jacobi
 * rotations (columns of Q are the eigenvectors, row-major storage). */
SPH_HD static inline void sph_mat3_sym_eigen(const double A[9], double w[3],
                                             double Q[9]) {
  double a[9];
  memcpy(a, A, sizeof a);
  sph_mat3_identity(Q);
  for (int sweep = 0; sweep < 32; ++sweep) {
    double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
    if (off <= 1e-30 * (a[0] * a[0] + a[4] * a[4] + a[8] * a[8]) || off == 0.0)
      break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        double apq = a[3 * p + q];
        if (apq == 0.0)
          continue;
        double theta = (a[3 * q + q] - a[3 * p + p]) / (2.0 * apq);
        double t = (theta >= 0 ? 1.0 : -1.0) /
                   (fabs(theta) + sqrt(theta * theta + 1.0));
        double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
        /* a <- R^T a R, Q <- Q R with R the (p, q) rotation */
        for (int k = 0; k < 3; ++k) {
          double akp = a[3 * k + p], akq = a[3 * k + q];
          a[3 * k + p] = c * akp - s * akq;
          a[3 * k + q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          double apk = a[3 * p + k], aqk = a[3 * q + k];
          a[3 * p + k] = c * apk - s * aqk;
          a[3 * q + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          double qkp = Q[3 * k + p], qkq = Q[3 * k + q];
          Q[3 * k + p] = c * qkp - s * qkq;
          Q[3 * k + q] = s * qkp + c * qkq;
        }
      }
  }
  w[0] = a[0];
  w[1] = a[4];
  w[2] = a[8];
}

/* Smallest and largest eigenvalue of a symmetric A (trigonometric method). */
SPH_HD static inline void sph_mat3_sym_extremes(const double A[9], double *lo,
                                                double *hi) {
  double p1 = A[1] * A[1] + A[2] * A[2] + A[5] * A[5];
  double q = (A[0] + A[4] + A[8]) / 3.0;
  double p2 = (A[0] - q) * (A[0] - q) + (A[4] - q) * (A[4] - q) +
              (A[8] - q) * (A[8] - q) + 2.0 * p1;
  if (p2 <= 1e-30 * q * q) {
    *lo = *hi = q;
    return;
  }
  double p = sqrt(p2 / 6.0), B[9];
  for (int k = 0; k < 9; ++k)
    B[k] = (A[k] - (k % 4 == 0) * q) / p;
  double r = 0.5 * sph_mat3_det(B);
  double phi = r <= -1.0 ? M_PI / 3.0 : (r >= 1.0 ? 0.0 : acos(r) / 3.0);
  *hi = q + 2.0 * p * cos(phi);
  *lo = q + 2.0 * p * cos(phi + 2.0 * M_PI / 3.0);
}

#endif
