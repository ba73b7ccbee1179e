/* Material parameters: (E, nu) or (mu, kappa) to the Lame parameters, the
 * model's own parameters checked by the model; p-wave speed
 * sqrt((lambda + 2 mu) / rho0) and acoustic tensors. The registry is in
 * registry.c. */
#include <math.h>
#include <string.h>

#include "core/tensor.h"
#include "materials/material_impl.h"

sph_status sph_material_create(sph_material *m, const sph_material_params *p,
                               sph_error *err) {
  memset(m, 0, sizeof *m);
  m->ops = sph_material_find(p->model);
  if (!m->ops)
    return sph_error_set(err, SPH_ERR_ARG,
                         "unknown material model '%s' (known: %s)",
                         p->model ? p->model : "", sph_material_known());
  SPH_TRY(sph_material_elastic(m, p, err));
  return sph_material_own(m, p, err);
}

sph_status sph_material_elastic(sph_material *m, const sph_material_params *p,
                                sph_error *err) {
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
      return sph_error_at(err, SPH_ERR_RANGE, NULL, 0, 0, "poisson_ratio",
                          "must be in (-1, 0.5), got %g", nu);
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
  return SPH_OK;
}

sph_status sph_material_own(sph_material *m, const sph_material_params *p,
                            sph_error *err) {
  for (int i = 0; i < p->nown; ++i) {
    int mine = 0;
    for (const char *const *k = m->ops->keys; k && *k && !mine; ++k)
      mine = !strcmp(*k, p->own_key[i]);
    if (mine)
      continue;
    char owners[256];
    sph_material_owners(p->own_key[i], owners, sizeof owners);
    return sph_error_at(err, SPH_ERR_ARG, NULL, 0, 0, p->own_key[i],
                        "%s applies to %s only, not %s", p->own_key[i],
                        owners[0] ? owners : "no model", m->ops->name);
  }
  return m->ops->init ? m->ops->init(m, p, err) : SPH_OK;
}

double sph_material_param(const sph_material_params *p, const char *key,
                          double def) {
  for (int i = 0; i < p->nown; ++i)
    if (!strcmp(p->own_key[i], key))
      return p->own_value[i];
  return def;
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
