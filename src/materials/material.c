/* Material registry and parameter checks: (E, nu) or (mu, kappa) to the
 * Lame parameters; p-wave speed sqrt((lambda + 2 mu) / rho0). */
#include <math.h>
#include <string.h>

#include "core/tensor.h"
#include "materials/material_impl.h"

static const sph_material_ops *const models[] = {
    &sph_linear_elastic_ops,
    &sph_neo_hookean_ops,
    &sph_mooney_rivlin_ops,
    NULL,
};

static const char *const model_names[] = {"linear-elastic", "neo-hookean",
                                          "mooney-rivlin", NULL};

const char *const *sph_material_models(void) { return model_names; }

sph_status sph_material_create(sph_material *m, const sph_material_params *p,
                               sph_error *err) {
  memset(m, 0, sizeof *m);
  for (const sph_material_ops *const *o = models; *o; ++o)
    if (p->model && strcmp((*o)->name, p->model) == 0)
      m->ops = *o;
  if (!m->ops)
    return sph_error_set(err, SPH_ERR_ARG,
                         "unknown material model '%s' (known: linear-elastic, "
                         "neo-hookean, mooney-rivlin)",
                         p->model ? p->model : "");
  if (!(p->density > 0.0))
    return sph_error_set(err, SPH_ERR_RANGE, "density must be positive, got %g",
                         p->density);
  if (p->has_youngs == p->has_moduli)
    return sph_error_set(err, SPH_ERR_ARG,
                         "give either youngs_modulus and poisson_ratio or "
                         "shear_modulus and bulk_modulus");
  double mu, kappa, E, nu;
  if (p->has_youngs) {
    E = p->youngs_modulus;
    nu = p->poisson_ratio;
    if (!(E > 0.0))
      return sph_error_set(err, SPH_ERR_RANGE,
                           "Young's modulus must be positive, got %g", E);
    if (!(nu > -1.0 && nu < 0.5))
      return sph_error_set(err, SPH_ERR_RANGE,
                           "Poisson's ratio must be in (-1, 0.5), got %g", nu);
    mu = E / (2.0 * (1.0 + nu));
    kappa = E / (3.0 * (1.0 - 2.0 * nu));
  } else {
    mu = p->shear_modulus;
    kappa = p->bulk_modulus;
    if (!(mu > 0.0))
      return sph_error_set(err, SPH_ERR_RANGE,
                           "shear modulus must be positive, got %g", mu);
    if (!(kappa > 0.0))
      return sph_error_set(err, SPH_ERR_RANGE,
                           "bulk modulus must be positive, got %g", kappa);
    E = 9.0 * kappa * mu / (3.0 * kappa + mu);
    nu = (3.0 * kappa - 2.0 * mu) / (2.0 * (3.0 * kappa + mu));
  }
  m->density = p->density;
  m->youngs_modulus = E;
  m->poisson_ratio = nu;
  m->mu = mu;
  m->kappa = kappa;
  m->lambda = kappa - 2.0 * mu / 3.0;
  /* seed 000 eq. 8: 2 varsigma + 3 sqrt(3) xi = mu */
  double xi = p->has_xi ? p->xi : 0.0;
  double xi_max = mu / (3.0 * sqrt(3.0));
  if (p->has_xi && m->ops != &sph_mooney_rivlin_ops)
    return sph_error_set(err, SPH_ERR_ARG,
                         "xi applies to mooney-rivlin only, not %s",
                         m->ops->name);
  if (!(xi >= 0.0 && xi <= xi_max))
    return sph_error_set(err, SPH_ERR_RANGE,
                         "xi must be in [0, mu/(3 sqrt 3)] = [0, %g], got %g",
                         xi_max, xi);
  m->xi = xi;
  m->varsigma = 0.5 * (mu - 3.0 * sqrt(3.0) * xi);
  return SPH_OK;
}

double sph_material_wave_speed(const sph_material *m) {
  return sqrt((m->lambda + 2.0 * m->mu) / m->density);
}

void sph_material_acoustic_tensors(const sph_material *m, const double F[9],
                                   double Q[27]) {
  if (m->ops->acoustic) {
    m->ops->acoustic(m, F, Q);
    return;
  }
  /* forward differences of P_id in F_kd, step 1e-7 of |F| */
  double H[9], P0[9];
  sph_mat3_cofactor(F, H);
  sph_material_stress(m, F, H, sph_mat3_det(F), P0);
  double e = 1e-7 * sqrt(sph_mat3_ddot(F, F) / 3.0);
  for (int d = 0; d < 3; ++d) {
    double *Qd = Q + 9 * d;
    for (int k = 0; k < 3; ++k) {
      double Fp[9], Hp[9], Pp[9];
      memcpy(Fp, F, sizeof Fp);
      Fp[3 * k + d] += e;
      sph_mat3_cofactor(Fp, Hp);
      sph_material_stress(m, Fp, Hp, sph_mat3_det(Fp), Pp);
      for (int i = 0; i < 3; ++i)
        Qd[3 * i + k] = (Pp[3 * i + d] - P0[3 * i + d]) / e;
    }
    for (int i = 0; i < 3; ++i) /* symmetric part */
      for (int k = i + 1; k < 3; ++k)
        Qd[3 * i + k] = Qd[3 * k + i] = 0.5 * (Qd[3 * i + k] + Qd[3 * k + i]);
  }
}
