/* Nearly incompressible neo-Hookean material, seed 003 eq. 6-7:
 * psi = mu/2 (J^-2/3 F:F - 3) + kappa/2 (J - 1)^2,
 * P = mu J^-2/3 (F - 1/3 (F:F) F^-T) + p H, p = kappa (J - 1),
 * with F^-T = H / J so that mixed methods pass independent H and J. This is
 * seed 000 eq. 8-12 with xi = 0 and 2 varsigma = mu.
 * Acoustic tensor for direction e_d, with s = F:F, H = cof F, J = det F and
 * dJ/dF = H, dH_iJ/dF_kL = (H_iJ H_kL - H_iL H_kJ)/J (zero for J = L = d):
 * Q_ik = mu J^-2/3 d_ik - 2/3 mu J^-5/3 (F_id H_kd + H_id F_kd)
 *        + (5/9 mu s J^-8/3 + kappa) H_id H_kd. */
#include <math.h>

#include "core/tensor.h"
#include "materials/material_impl.h"
#include "materials/neo_hookean_law.h"

static void neo_hookean_stress(const sph_material *m, const double F[9],
                               const double H[9], double J, double P[9]) {
  sph_neo_hookean_law(m->mu, m->kappa, F, H, J, P);
}

static double neo_hookean_energy(const sph_material *m, const double F[9],
                                 const double H[9], double J) {
  double ff = sph_mat3_ddot(F, F);
  return 0.5 * m->mu * (pow(J, -2.0 / 3.0) * ff - 3.0) +
         0.5 * m->kappa * (J - 1.0) * (J - 1.0);
}

static void neo_hookean_acoustic(const sph_material *m, const double F[9],
                                 double Q[27]) {
  double H[9];
  sph_mat3_cofactor(F, H);
  double J = sph_mat3_det(F), s = sph_mat3_ddot(F, F);
  double j23 = pow(J, -2.0 / 3.0), j53 = j23 / J, j83 = j53 / J;
  double a = m->mu * j23, b = 2.0 / 3.0 * m->mu * j53;
  double c = 5.0 / 9.0 * m->mu * s * j83 + m->kappa;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) {
        double Fi = F[3 * i + d], Fk = F[3 * k + d];
        double Hi = H[3 * i + d], Hk = H[3 * k + d];
        Q[9 * d + 3 * i + k] =
            (i == k) * a - b * (Fi * Hk + Hi * Fk) + c * Hi * Hk;
      }
}

const sph_material_ops sph_neo_hookean_ops = {
    .name = "neo-hookean",
    .reference = "seed 003 eq. 6-7",
    .stress = neo_hookean_stress,
    .energy = neo_hookean_energy,
    .acoustic = neo_hookean_acoustic,
};
