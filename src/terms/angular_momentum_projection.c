/* Discrete angular momentum projection, seed 000 sec. 6 eq. 45-48: the
 * internal forces are corrected in the least-squares sense so that their
 * sum and their moment about the stage positions X^chi vanish on each body.
 * With Y = X - Xc (Xc the volume centroid) the system of eq. 48 decouples:
 * lambda = -I_Y^-1 sum V Y x T, mu = -sum V T / sum V. Over MPI ranks the
 * body's sums are global (sph_domain_sum, in rank order). */
#include <stdlib.h>
#include <string.h>

#include "sph/tensor.h"
#include "terms/terms_impl.h"

void sph_momentum_projection(sph_domain *d, size_t n, const double *V,
                             const double *X, const int32_t *body, int nbodies,
                             double *w) {
  for (int b = 0; b < nbodies; ++b) {
    /* centroid, total force and volume of the body (serial: repeatable) */
    double s[7] = {0, 0, 0, 0, 0, 0, 0}; /* volume, V X, V w */
    double *xc = s + 1, *sum = s + 4;
    for (size_t a = 0; a < n; ++a) {
      if (body[a] != b)
        continue;
      s[0] += V[a];
      for (int c = 0; c < 3; ++c) {
        xc[c] += V[a] * X[3 * a + c];
        sum[c] += V[a] * w[3 * a + c];
      }
    }
    sph_domain_sum(d, s, 7);
    double vol = s[0];
    if (!(vol > 0.0))
      continue;
    for (int c = 0; c < 3; ++c)
      xc[c] /= vol;
    /* inertia about the centroid and moment of w */
    double Im[12] = {0}, *I = Im, *m = Im + 9;
    for (size_t a = 0; a < n; ++a) {
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
    for (size_t a = 0; a < n; ++a) {
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

static const sph_term_ops projection_ops = {
    .name = "angular_momentum_projection",
    .reference = "seed 000 sec. 6 eq. 45-48",
    .distributed = 1,
    .rates = projection_rates,
};

sph_status angular_momentum_projection_create(sph_sim *sim, sph_error *err) {
  return sph_sim_add_term(sim, &projection_ops, NULL, err);
}
