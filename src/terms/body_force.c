/* Body force per unit reference volume, E_a = rho0 g (seed 000 eq. 27c);
 * with rho0 NULL the state is the velocity and the rate is g itself. */
#include <stdlib.h>

#include "terms/terms_impl.h"

typedef struct body_force {
  const double *rho0;
  double g[3];
} body_force;

static sph_status body_force_rates(sph_term *term, sph_sim *sim,
                                   sph_stage *stage, sph_error *err) {
  const body_force *f = term->data;
  long n = (long)sim->ps->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      stage->dp[3 * a + c] += (f->rho0 ? f->rho0[a] : 1.0) * f->g[c];
  return SPH_OK;
}

static void body_force_destroy(sph_term *term) { free(term->data); }

const sph_term_ops body_force_term_ops = {
    .name = "body_force",
    .reference = "seed 000 eq. 27c",
    .distributed = 1,
    .rates = body_force_rates,
    .destroy = body_force_destroy,
};

sph_status body_force_create(sph_sim *sim, const double *rho0, sph_error *err) {
  body_force *f = malloc(sizeof *f);
  if (!f)
    return sph_error_set(err, SPH_ERR_NOMEM, "body force");
  f->rho0 = rho0;
  for (int c = 0; c < 3; ++c)
    f->g[c] = sim->scene->body_force[c];
  sph_status st = sph_sim_add_term(sim, &body_force_term_ops, f, err);
  if (st != SPH_OK)
    free(f);
  return st;
}
