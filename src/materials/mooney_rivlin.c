/* Polyconvex nearly incompressible Mooney-Rivlin material, seed 000
 * eq. 8-12: W = varsigma J^-2/3 (F:F) + xi J^-2 (H:H)^3/2 + kappa/2 (J-1)^2,
 * P = Sigma_F + Sigma_H x F + Sigma_J H with the conjugate stresses of
 * eq. 9-10 and p = kappa (J - 1) (eq. 11). W is shifted so W(I) = 0. */
#include <math.h>

#include "core/tensor.h"
#include "materials/material_impl.h"

/* its own parameters in sph_material.own */
enum { VARSIGMA, XI };

static const char *const mooney_rivlin_keys[] = {"xi", NULL};

/* seed 000 eq. 8: 2 varsigma + 3 sqrt(3) xi = mu, xi in [0, mu/(3 sqrt 3)]
 * (default 0: neo-hookean) */
static sph_status mooney_rivlin_init(sph_material *m,
                                     const sph_material_params *p,
                                     sph_error *err) {
  double xi = sph_material_param(p, "xi", 0.0);
  double xi_max = m->mu / (3.0 * sqrt(3.0));
  if (!(xi >= 0.0 && xi <= xi_max))
    return sph_error_at(err, SPH_ERR_RANGE, NULL, 0, 0, "xi",
                        "xi must be in [0, mu/(3 sqrt 3)] = [0, %g], got %g",
                        xi_max, xi);
  m->own[XI] = xi;
  m->own[VARSIGMA] = 0.5 * (m->mu - 3.0 * sqrt(3.0) * xi);
  return SPH_OK;
}

static void mooney_rivlin_stress(const sph_material *m, const double F[9],
                                 const double H[9], double J, double P[9]) {
  double ff = sph_mat3_ddot(F, F), hh = sph_mat3_ddot(H, H);
  double j23 = pow(J, -2.0 / 3.0), hn = sqrt(hh);
  double sigma_j = -2.0 * m->own[VARSIGMA] / 3.0 * j23 / J * ff -
                   2.0 * m->own[XI] / (J * J * J) * hh * hn +
                   m->kappa * (J - 1.0);
  double sigma_h[9], cross[9];
  for (int k = 0; k < 9; ++k)
    sigma_h[k] = 3.0 * m->own[XI] / (J * J) * hn * H[k];
  sph_mat3_tensor_cross(sigma_h, F, cross);
  for (int k = 0; k < 9; ++k)
    P[k] = 2.0 * m->own[VARSIGMA] * j23 * F[k] + cross[k] + sigma_j * H[k];
}

static double mooney_rivlin_energy(const sph_material *m, const double F[9],
                                   const double H[9], double J) {
  double ff = sph_mat3_ddot(F, F), hh = sph_mat3_ddot(H, H);
  double w = m->own[VARSIGMA] * pow(J, -2.0 / 3.0) * ff +
             m->own[XI] / (J * J) * hh * sqrt(hh) +
             0.5 * m->kappa * (J - 1.0) * (J - 1.0);
  /* value at F = H = I, J = 1 */
  return w - 3.0 * m->own[VARSIGMA] - 3.0 * sqrt(3.0) * m->own[XI];
}

const sph_material_ops sph_mooney_rivlin_ops = {
    .name = "mooney-rivlin",
    .reference = "seed 000 eq. 8-12",
    .keys = mooney_rivlin_keys,
    .init = mooney_rivlin_init,
    .stress = mooney_rivlin_stress,
    .energy = mooney_rivlin_energy,
};
