/* Nearly incompressible neo-Hookean material, seed 003 eq. 6-7:
 * psi = mu/2 (J^-2/3 F:F - 3) + kappa/2 (J - 1)^2,
 * P = mu J^-2/3 (F - 1/3 (F:F) F^-T) + p H, p = kappa (J - 1),
 * with F^-T = H / J so that mixed methods pass independent H and J. This is
 * seed 000 eq. 8-12 with xi = 0 and 2 varsigma = mu. */
#include <math.h>

#include "materials/material_impl.h"
#include "sph/tensor.h"

static void neo_hookean_stress(const sph_material *m, const double F[9],
                               const double H[9], double J, double P[9]) {
  double j23 = pow(J, -2.0 / 3.0);
  double ff = sph_mat3_ddot(F, F);
  double p = m->kappa * (J - 1.0);
  for (int k = 0; k < 9; ++k)
    P[k] = m->mu * j23 * (F[k] - ff / (3.0 * J) * H[k]) + p * H[k];
}

static double neo_hookean_energy(const sph_material *m, const double F[9],
                                 const double H[9], double J) {
  double ff = sph_mat3_ddot(F, F);
  return 0.5 * m->mu * (pow(J, -2.0 / 3.0) * ff - 3.0) +
         0.5 * m->kappa * (J - 1.0) * (J - 1.0);
}

const sph_material_ops sph_neo_hookean_ops = {
    .name = "neo-hookean",
    .reference = "seed 003 eq. 6-7",
    .stress = neo_hookean_stress,
    .energy = neo_hookean_energy,
};
