/* Linear elastic material, small strain (the cable of seed 000 sec. 8.1):
 * eps = sym(F) - I, P = lambda tr(eps) I + 2 mu eps,
 * W = lambda/2 tr(eps)^2 + mu eps:eps. Not objective, by design.
 * Acoustic tensor for direction e_d: Q_ik = mu d_ik + (lambda + mu) d_id d_kd,
 * whatever F. */
#include "core/tensor.h"
#include "materials/material_impl.h"

static void small_strain(const double F[9], double eps[9]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      eps[3 * i + j] = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j);
}

static void linear_elastic_stress(const sph_material *m, const double F[9],
                                  const double H[9], double J, double P[9]) {
  double eps[9];
  small_strain(F, eps);
  double tr = sph_mat3_trace(eps);
  for (int k = 0; k < 9; ++k)
    P[k] = 2.0 * m->mu * eps[k];
  P[0] += m->lambda * tr;
  P[4] += m->lambda * tr;
  P[8] += m->lambda * tr;
}

static double linear_elastic_energy(const sph_material *m, const double F[9],
                                    const double H[9], double J) {
  double eps[9];
  small_strain(F, eps);
  double tr = sph_mat3_trace(eps);
  return 0.5 * m->lambda * tr * tr + m->mu * sph_mat3_ddot(eps, eps);
}

static void linear_elastic_acoustic(const sph_material *m, const double F[9],
                                    double Q[27]) {
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        Q[9 * d + 3 * i + k] =
            (i == k) * m->mu + (i == d && k == d) * (m->lambda + m->mu);
}

const sph_material_ops sph_linear_elastic_ops = {
    .name = "linear-elastic",
    .reference = "small-strain Hooke law (seed 000 sec. 8.1 cable)",
    .stress = linear_elastic_stress,
    .energy = linear_elastic_energy,
    .acoustic = linear_elastic_acoustic,
};
