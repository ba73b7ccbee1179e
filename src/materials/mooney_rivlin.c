/* Polyconvex nearly incompressible Mooney-Rivlin material, seed 000
 * eq. 8-12: W = varsigma J^-2/3 (F:F) + xi J^-2 (H:H)^3/2 + kappa/2 (J-1)^2,
 * P = Sigma_F + Sigma_H x F + Sigma_J H with the conjugate stresses of
 * eq. 9-10 and p = kappa (J - 1) (eq. 11). W is shifted so W(I) = 0. */
#include <math.h>

#include "core/tensor.h"
#include "materials/material_impl.h"

static void mooney_rivlin_stress(const sph_material *m, const double F[9],
                                 const double H[9], double J, double P[9]) {
  double ff = sph_mat3_ddot(F, F), hh = sph_mat3_ddot(H, H);
  double j23 = pow(J, -2.0 / 3.0), hn = sqrt(hh);
  double sigma_j = -2.0 * m->varsigma / 3.0 * j23 / J * ff -
                   2.0 * m->xi / (J * J * J) * hh * hn + m->kappa * (J - 1.0);
  double sigma_h[9], cross[9];
  for (int k = 0; k < 9; ++k)
    sigma_h[k] = 3.0 * m->xi / (J * J) * hn * H[k];
  sph_mat3_tensor_cross(sigma_h, F, cross);
  for (int k = 0; k < 9; ++k)
    P[k] = 2.0 * m->varsigma * j23 * F[k] + cross[k] + sigma_j * H[k];
}

static double mooney_rivlin_energy(const sph_material *m, const double F[9],
                                   const double H[9], double J) {
  double ff = sph_mat3_ddot(F, F), hh = sph_mat3_ddot(H, H);
  double w = m->varsigma * pow(J, -2.0 / 3.0) * ff +
             m->xi / (J * J) * hh * sqrt(hh) +
             0.5 * m->kappa * (J - 1.0) * (J - 1.0);
  /* value at F = H = I, J = 1 */
  return w - 3.0 * m->varsigma - 3.0 * sqrt(3.0) * m->xi;
}

const sph_material_ops sph_mooney_rivlin_ops = {
    .name = "mooney-rivlin",
    .reference = "seed 000 eq. 8-12",
    .stress = mooney_rivlin_stress,
    .energy = mooney_rivlin_energy,
};
