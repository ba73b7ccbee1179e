/* Discrete angular momentum projection, seed 000 sec. 6 eq. 45-48: the
 * internal forces are corrected in the least-squares sense so that their
 * sum and their moment about the stage positions X^chi vanish on each body.
 * With Y = X - Xc (Xc the volume centroid) the system of eq. 48 decouples:
 * lambda = -I_Y^-1 sum V Y x T, mu = -sum V T / sum V. Over MPI ranks the
 * body's sums are global (sph_domain_sum, in rank order). */
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "terms/momentum_projection.h"
#include "terms/terms_impl.h"

/* The sums run over SPH_PROJ_BLOCKS blocks of consecutive particles, added
 * in block order (momentum_projection.h): the same bits on any thread count,
 * and no work array (the partial sums live on the stack). Small sets stay
 * on one thread. */
enum { PROJ_PARALLEL_MIN = 32768 };

/* the block sums of sph_proj_block_sums (count 7 or 12) added in block
 * order */
static void body_sums(size_t n, const double *V, const double *X,
                      const int32_t *body, int b, const double *w,
                      const double *xc, int count, double *out) {
  double part[SPH_PROJ_BLOCKS * 12];
  memset(part, 0, sizeof part);
#pragma omp parallel for schedule(static) if (n >= PROJ_PARALLEL_MIN)
  for (int k = 0; k < SPH_PROJ_BLOCKS; ++k) {
    size_t lo, hi;
    sph_proj_block_range(n, k, &lo, &hi);
    if (lo < hi)
      sph_proj_block_sums(lo, hi, V, X, body, b, w, xc, part + 12 * k);
  }
  sph_proj_add_blocks(part, count, out);
}

void sph_momentum_projection(sph_domain *d, size_t n, const double *V,
                             const double *X, const int32_t *body, int nbodies,
                             double *w) {
  for (int b = 0; b < nbodies; ++b) {
    /* centroid, total force and volume of the body */
    double s[7]; /* volume, V X, V w */
    body_sums(n, V, X, body, b, w, NULL, 7, s);
    sph_domain_sum(d, s, 7);
    if (!sph_proj_centroid(s))
      continue;
    const double *xc = s + 1;
    /* inertia about the centroid and moment of w */
    double Im[12];
    body_sums(n, V, X, body, b, w, xc, 12, Im);
    sph_domain_sum(d, Im, 12);
    /* planar bodies have no inertia about in-plane axes: keep the z part */
    double lambda[3], mu[3];
    sph_proj_coefficients(s, Im, lambda, mu);
    long nl = (long)n;
#pragma omp parallel for schedule(static) if (n >= PROJ_PARALLEL_MIN)
    for (long a = 0; a < nl; ++a)
      if (body[a] == b)
        sph_proj_apply_one((size_t)a, X, xc, lambda, mu, w);
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
    .gpu = 1,
    .rates = projection_rates,
};

sph_status angular_momentum_projection_create(sph_sim *sim, sph_error *err) {
  return sph_sim_add_term(sim, &angular_momentum_projection_term_ops, NULL,
                          err);
}
