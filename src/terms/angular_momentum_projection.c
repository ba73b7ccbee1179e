/* Discrete angular momentum projection, seed 000 sec. 6 eq. 45-48: the
 * internal forces are corrected in the least-squares sense so that their
 * sum and their moment about the stage positions X^chi vanish on each body.
 * With Y = X - Xc (Xc the volume centroid) the system of eq. 48 decouples:
 * lambda = -I_Y^-1 sum V Y x T, mu = -sum V T / sum V. Over MPI ranks the
 * body's sums are global (sph_domain_sum, in rank order). */
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "terms/terms_impl.h"

/* The sums run over a fixed number of blocks of consecutive particles,
 * added in block order: the same bits on any thread count, and no work
 * array (the partial sums live on the stack). Small sets stay on one
 * thread. */
enum { PROJ_BLOCKS = 64, PROJ_PARALLEL_MIN = 32768 };

/* the volume, V X and V w of body b (7 sums), or with xc given the inertia
 * about xc and the moment of w (12 sums), over particles [lo, hi) */
static void body_block_sums(size_t lo, size_t hi, const double *V,
                            const double *X, const int32_t *body, int b,
                            const double *w, const double *xc, double *s) {
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

/* the block sums of body_block_sums (count 7 or 12) added in block order */
static void body_sums(size_t n, const double *V, const double *X,
                      const int32_t *body, int b, const double *w,
                      const double *xc, int count, double *out) {
  double part[PROJ_BLOCKS][12];
  memset(part, 0, sizeof part);
  size_t len = (n + PROJ_BLOCKS - 1) / PROJ_BLOCKS;
#pragma omp parallel for schedule(static) if (n >= PROJ_PARALLEL_MIN)
  for (int k = 0; k < PROJ_BLOCKS; ++k) {
    size_t lo = (size_t)k * len, hi = lo + len < n ? lo + len : n;
    if (lo < hi)
      body_block_sums(lo, hi, V, X, body, b, w, xc, part[k]);
  }
  memset(out, 0, (size_t)count * sizeof *out);
  for (int k = 0; k < PROJ_BLOCKS; ++k)
    for (int c = 0; c < count; ++c)
      out[c] += part[k][c];
}

void sph_momentum_projection(sph_domain *d, size_t n, const double *V,
                             const double *X, const int32_t *body, int nbodies,
                             double *w) {
  for (int b = 0; b < nbodies; ++b) {
    /* centroid, total force and volume of the body */
    double s[7]; /* volume, V X, V w */
    double *xc = s + 1, *sum = s + 4;
    body_sums(n, V, X, body, b, w, NULL, 7, s);
    sph_domain_sum(d, s, 7);
    double vol = s[0];
    if (!(vol > 0.0))
      continue;
    for (int c = 0; c < 3; ++c)
      xc[c] /= vol;
    /* inertia about the centroid and moment of w */
    double Im[12], *I = Im, *m = Im + 9;
    body_sums(n, V, X, body, b, w, xc, 12, Im);
    sph_domain_sum(d, Im, 12);
    /* planar bodies have no inertia about in-plane axes: keep the z part */
    double Iinv[9], lambda[3] = {0, 0, 0};
    if (sph_mat3_inverse(I, Iinv) != 0.0) {
      sph_mat3_vec(Iinv, m, lambda);
    } else if (I[8] > 0.0) {
      lambda[2] = m[2] / I[8];
    }
    for (int c = 0; c < 3; ++c)
      lambda[c] = -lambda[c];
    double mu[3] = {-sum[0] / vol, -sum[1] / vol, -sum[2] / vol};
    long nl = (long)n;
#pragma omp parallel for schedule(static) if (n >= PROJ_PARALLEL_MIN)
    for (long a = 0; a < nl; ++a) {
      if (body[a] != b)
        continue;
      double y[3] = {X[3 * a] - xc[0], X[3 * a + 1] - xc[1],
                     X[3 * a + 2] - xc[2]};
      double t[3];
      sph_vec3_cross(lambda, y, t);
      for (int c = 0; c < 3; ++c)
        w[3 * a + c] += t[c] + mu[c];
    }
  }
}

static sph_status projection_rates(sph_term *term, sph_sim *sim,
                                   sph_stage *stage, sph_error *err) {
  const sph_particles *ps = sim->ps;
  sph_momentum_projection(sim->domain, ps->n, ps->field[SPH_FIELD_VOLUME0],
                          stage->x_moment, ps->body, (int)sim->scene->nbodies,
                          stage->dp);
  return SPH_OK;
}

const sph_term_ops angular_momentum_projection_term_ops = {
    .name = "angular_momentum_projection",
    .reference = "seed 000 sec. 6 eq. 45-48",
    .distributed = 1,
    .rates = projection_rates,
};

sph_status angular_momentum_projection_create(sph_sim *sim, sph_error *err) {
  return sph_sim_add_term(sim, &angular_momentum_projection_term_ops, NULL,
                          err);
}
