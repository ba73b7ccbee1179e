/* The pieces of the momentum projection of seed 000 eq. 46-48
 * (angular_momentum_projection.c), shared by the CPU term and the device
 * step (src/gpu): per-body sums over a fixed number of blocks of consecutive
 * particles, added in block order (the same bits on any thread count, on
 * the CPU and on the device), the coefficients lambda and mu, and the
 * correction of one particle. */
#ifndef SPH_MOMENTUM_PROJECTION_H
#define SPH_MOMENTUM_PROJECTION_H

#include <stddef.h>
#include <stdint.h>

#include "core/hd.h"
#include "core/tensor.h"

enum { SPH_PROJ_BLOCKS = 64 };

/* the volume, V X and V w of body b (7 sums), or with xc given the inertia
 * about xc and the moment of w (12 sums), over particles [lo, hi) */
SPH_HD static inline void sph_proj_block_sums(size_t lo, size_t hi,
                                              const double *V, const double *X,
                                              const int32_t *body, int b,
                                              const double *w, const double *xc,
                                              double *s) {
  if (!xc) {
    for (size_t a = lo; a < hi; ++a) {
      if (body[a] != b)
        continue;
      s[0] += V[a];
      for (int c = 0; c < 3; ++c) {
        s[1 + c] += V[a] * X[3 * a + c];
        s[4 + c] += V[a] * w[3 * a + c];
      }
    }
    return;
  }
  double *I = s, *m = s + 9;
  for (size_t a = lo; a < hi; ++a) {
    if (body[a] != b)
      continue;
    double y[3] = {X[3 * a] - xc[0], X[3 * a + 1] - xc[1],
                   X[3 * a + 2] - xc[2]};
    double yy = sph_vec3_dot(y, y), t[3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        I[3 * i + j] += V[a] * ((i == j) * yy - y[i] * y[j]);
    sph_vec3_cross(y, w + 3 * a, t);
    for (int c = 0; c < 3; ++c)
      m[c] += V[a] * t[c];
  }
}

/* block k's range of n particles */
SPH_HD static inline void sph_proj_block_range(size_t n, int k, size_t *lo,
                                               size_t *hi) {
  size_t len = (n + SPH_PROJ_BLOCKS - 1) / SPH_PROJ_BLOCKS;
  *lo = (size_t)k * len;
  *hi = *lo + len < n ? *lo + len : n;
}

/* out[c] = the blocks' part[12 k + c] added in block order */
SPH_HD static inline void sph_proj_add_blocks(const double *part, int count,
                                              double *out) {
  for (int c = 0; c < count; ++c)
    out[c] = 0.0;
  for (int k = 0; k < SPH_PROJ_BLOCKS; ++k)
    for (int c = 0; c < count; ++c)
      out[c] += part[12 * k + c];
}

/* From the 7 sums s (volume, V X, V w): the centroid into s + 1; 0 when
 * the body has no volume (nothing to project) */
SPH_HD static inline int sph_proj_centroid(double *s) {
  double vol = s[0];
  if (!(vol > 0.0))
    return 0;
  for (int c = 0; c < 3; ++c)
    s[1 + c] /= vol;
  return 1;
}

/* lambda = -I^-1 m (planar bodies: the z part) and mu = -sum V w / vol
 * from the 7 sums s (centroid set) and the 12 sums Im */
SPH_HD static inline void sph_proj_coefficients(const double *s,
                                                const double *Im,
                                                double lambda[3],
                                                double mu[3]) {
  const double *I = Im, *m = Im + 9, *sum = s + 4;
  double vol = s[0], Iinv[9];
  lambda[0] = lambda[1] = lambda[2] = 0.0;
  if (sph_mat3_inverse(I, Iinv) != 0.0) {
    sph_mat3_vec(Iinv, m, lambda);
  } else if (I[8] > 0.0) {
    lambda[2] = m[2] / I[8];
  }
  for (int c = 0; c < 3; ++c)
    lambda[c] = -lambda[c];
  mu[0] = -sum[0] / vol;
  mu[1] = -sum[1] / vol;
  mu[2] = -sum[2] / vol;
}

/* w_a += lambda x (X_a - xc) + mu for a particle of the body */
SPH_HD static inline void sph_proj_apply_one(size_t a, const double *X,
                                             const double xc[3],
                                             const double lambda[3],
                                             const double mu[3], double *w) {
  double y[3] = {X[3 * a] - xc[0], X[3 * a + 1] - xc[1], X[3 * a + 2] - xc[2]};
  double t[3];
  sph_vec3_cross(lambda, y, t);
  for (int c = 0; c < 3; ++c)
    w[3 * a + c] += t[c] + mu[c];
}

#endif
